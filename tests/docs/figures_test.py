#!/usr/bin/env python3
"""The documentation's SVG figures as a browser draws them (headless Chromium).

    figures_test.py FIGURES_DIR [ARTIFACTS_DIR]

Loads every .svg in FIGURES_DIR (docs/figures) from its file:// URL and, for every <text>
element, takes the box the browser laid its text out in (getBBox()) and carries it into the
root <svg>'s user space, the coordinates of its viewBox (the element's screen transform
followed by the inverse of the root's, so the element's own transform and its groups'
count). Checks that each box lies inside the viewBox (a caption cut at an edge, or not
drawn at all) and that no two boxes intersect (captions drawn over each other). The
failure message names the file, the texts and their boxes. With ARTIFACTS_DIR, saves each
figure's screenshot there as NAME.png, to look at. Exits 77 (ctest's SKIP_RETURN_CODE)
when Chromium, chromedriver or python3-selenium is missing.
"""

import os
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import headless_chromium  # noqa: E402  (tests/headless_chromium.py)

SKIP = 77
WAIT = 90  # seconds: generous, for a loaded two-core machine
TOLERANCE = 0.5  # user units (px at the figures' scale): rounding in the layout

# Each <text>'s box in the root's user space: [text, x0, y0, x1, y1], and the viewBox.
BOXES_SCRIPT = """
const root = document.documentElement;
const vb = root.viewBox && root.viewBox.baseVal && root.viewBox.baseVal.width > 0
    ? root.viewBox.baseVal
    : {x: 0, y: 0, width: root.width.baseVal.value, height: root.height.baseVal.value};
const toRoot = root.getScreenCTM().inverse();
const boxes = [];
for (const text of root.querySelectorAll('text')) {
  const box = text.getBBox();
  const m = toRoot.multiply(text.getScreenCTM());
  const xs = [], ys = [];
  for (const [x, y] of [[box.x, box.y], [box.x + box.width, box.y],
                        [box.x, box.y + box.height],
                        [box.x + box.width, box.y + box.height]]) {
    xs.push(m.a * x + m.c * y + m.e);
    ys.push(m.b * x + m.d * y + m.f);
  }
  boxes.push([text.textContent.trim(), Math.min(...xs), Math.min(...ys),
              Math.max(...xs), Math.max(...ys)]);
}
return {viewBox: [vb.x, vb.y, vb.x + vb.width, vb.y + vb.height], boxes: boxes};
"""


def skip(why):
    print(f"SKIP: {why} (tools/setup.sh installs chromium, chromium-driver and "
          "python3-selenium)")
    return SKIP


def show(box):
    text, x0, y0, x1, y1 = box
    return f"{text!r} at ({x0:.1f}, {y0:.1f})-({x1:.1f}, {y1:.1f})"


def problems(name, view_box, boxes):
    """The figure's faults, one line each: captions outside the viewBox, captions overlapping."""
    vx0, vy0, vx1, vy1 = view_box
    found = []
    for box in boxes:
        _, x0, y0, x1, y1 = box
        if (x0 < vx0 - TOLERANCE or y0 < vy0 - TOLERANCE or x1 > vx1 + TOLERANCE
                or y1 > vy1 + TOLERANCE):
            found.append(f"{name}: {show(box)} lies outside the viewBox "
                         f"({vx0:g}, {vy0:g})-({vx1:g}, {vy1:g})")
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            overlap_x = min(a[3], b[3]) - max(a[1], b[1])
            overlap_y = min(a[4], b[4]) - max(a[2], b[2])
            if overlap_x > TOLERANCE and overlap_y > TOLERANCE:
                found.append(f"{name}: {show(a)} and {show(b)} overlap "
                             f"({overlap_x:.1f} x {overlap_y:.1f})")
    return found


def run(figures, artifacts):
    svgs = sorted(f for f in os.listdir(figures) if f.endswith(".svg"))
    if not svgs:
        print(f"FAIL: no .svg in {figures}")
        return 1
    if artifacts:
        os.makedirs(artifacts, exist_ok=True)

    found = []
    with tempfile.TemporaryDirectory() as profile:
        browser, missing = headless_chromium.start(profile, "1200,800", ("--hide-scrollbars",))
        if browser is None:
            return skip(missing)
        try:
            browser.set_page_load_timeout(WAIT)
            for name in svgs:
                path = os.path.abspath(os.path.join(figures, name))
                browser.get("file://" + path)
                if browser.execute_script(
                        "return document.documentElement.localName") != "svg":
                    found.append(f"{name}: the browser did not load it as SVG")
                    continue
                laid_out = browser.execute_script(BOXES_SCRIPT)
                boxes = laid_out["boxes"]
                print(f"{name}: {len(boxes)} texts in viewBox {laid_out['viewBox']}")
                for box in boxes:
                    print("  " + show(box))
                found += problems(name, laid_out["viewBox"], boxes)
                if artifacts:
                    browser.save_screenshot(
                        os.path.join(artifacts, os.path.splitext(name)[0] + ".png"))
        finally:
            browser.quit()
    for line in found:
        print("FAIL: " + line)
    if found:
        return 1
    print(f"ok: {len(svgs)} figures, every caption inside its picture, none overlapping")
    return 0


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    sys.exit(run(sys.argv[1], sys.argv[2] if len(sys.argv) == 3 else None))
