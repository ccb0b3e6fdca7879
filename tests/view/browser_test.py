#!/usr/bin/env python3
"""The page of `octray view` in a real browser (headless Chromium through chromedriver).

    browser_test.py OCTRAY ARTIFACTS_DIR

Starts `octray view` on a free port, opens the URL it prints, and checks that the page
shows the refined picture (the canvas has non-black pixels and says spp 4), that a drag
across the canvas orbits the camera (the server reports a new camera at the same distance
from the same look-at point, and the canvas changes), that the wheel dollies, that the
switches reach the server (spp, path; the ISA selector offers the server's list), that an
animated scene's frame slider renders and saves another frame, that
the frameless order converges to the same picture as the tiled one, that
`octray view A.exr B.exr` shows compare's verdict, the heatmap and the value under the
cursor, that the server refuses the page
without the token, and that SIGINT stops the command with status 0. Screenshots go to
ARTIFACTS_DIR. Exits 77 (ctest's SKIP_RETURN_CODE) when Chromium, chromedriver or
python3-selenium is missing.
"""

import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import urllib.error
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import headless_chromium  # noqa: E402  (tests/headless_chromium.py)

SKIP = 77
WAIT = 90  # seconds: generous, for a loaded two-core machine


def skip(why):
    print(f"SKIP: {why} (tools/setup.sh installs chromium, chromium-driver and "
          "python3-selenium)")
    return SKIP


def fail(why):
    print(f"FAIL: {why}")
    return 1


def start_view(octray, *extra, cwd=None):
    return start_command([octray, "view", "whitted", "--port", "0", "--width", "160",
                          "--height", "90", "--spp", "4", "--threads", "2", *extra], cwd)


def start_command(command, cwd=None):
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, cwd=cwd)
    for line in process.stdout:
        line = line.strip()
        if line.startswith("http://"):
            return process, line
    process.wait()
    raise RuntimeError("octray view printed no URL: " + process.stderr.read())


def fetch_status(url):
    base, token = url.split("/?token=")
    with urllib.request.urlopen(f"{base}/api/status?token={token}", timeout=30) as response:
        return json.load(response)


def canvas_digest(browser):
    """(non-black pixel count, a checksum of the canvas's pixels)."""
    return browser.execute_script("""
        const canvas = document.getElementById('view');
        const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
        let lit = 0, sum = 0;
        for (let i = 0; i < data.length; i += 4) {
          if (data[i] + data[i + 1] + data[i + 2] > 24) lit++;
          sum = (sum * 31 + data[i] + 7 * data[i + 1] + 13 * data[i + 2]) % 1000000007;
        }
        return [lit, sum];""")


def run(octray, artifacts):
    try:
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.actions.wheel_input import ScrollOrigin
        from selenium.webdriver.support.ui import WebDriverWait
    except ImportError:
        return skip("python3-selenium is not installed")
    os.makedirs(artifacts, exist_ok=True)

    process, url = start_view(octray)
    status = 0
    try:
        base = url.split("/?token=")[0]
        try:
            urllib.request.urlopen(base + "/", timeout=30)
            return fail("the page was served without the token")
        except urllib.error.HTTPError as e:
            if e.code != 403:
                return fail(f"without the token: HTTP {e.code}, expected 403")

        with tempfile.TemporaryDirectory() as profile:
            browser, missing = headless_chromium.start(profile, "640,400")
            if browser is None:
                return skip(missing)
            try:
                status = check_page(browser, url, artifacts, ActionChains, ScrollOrigin,
                                    WebDriverWait)
                if status == 0:
                    status = check_zoom(browser, WebDriverWait)
                if status == 0:
                    status = check_frameless(browser, octray, artifacts, WebDriverWait)
                if status == 0:
                    status = check_save(browser, octray, WebDriverWait)
                if status == 0:
                    status = check_frame(browser, octray, WebDriverWait)
                if status == 0:
                    status = check_compare(browser, octray, artifacts, ActionChains,
                                           WebDriverWait)
            finally:
                browser.quit()
    finally:
        process.send_signal(signal.SIGINT)
        try:
            out, err = process.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            process.kill()
            return fail("octray view did not stop within 60 s of SIGINT")
    if status == 0 and process.returncode != 0:
        return fail(f"octray view exited {process.returncode} after SIGINT: {err}")
    if status == 0 and "stopped" not in out:
        return fail(f"octray view did not say it stopped: {out!r}")
    return status


def check_page(browser, url, artifacts, ActionChains, ScrollOrigin, WebDriverWait):
    browser.set_page_load_timeout(WAIT)
    browser.get(url)
    # The refined first picture: the last pass's event, and its PNG drawn on the canvas.
    WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
        "return document.body.dataset.spp === '4' && "
        "document.getElementById('view').dataset.spp === '4'"))
    lit, before = canvas_digest(browser)
    browser.save_screenshot(os.path.join(artifacts, "view_loaded.png"))
    if lit < 160 * 90 // 2:
        return fail(f"the canvas shows {lit} lit pixels of {160 * 90}: no picture")
    for element, text in (("spp", "4"), ("target-spp", "4")):
        shown = browser.find_element("id", element).text
        if shown != text:
            return fail(f"#{element} shows {shown!r}, expected {text!r}")
    mrays = browser.find_element("id", "mrays").text
    if not mrays or float(mrays) <= 0:
        return fail(f"#mrays shows {mrays!r}")
    first = fetch_status(url)["frame"]

    # A drag to the right orbits the eye about the look-at point.
    canvas = browser.find_element("id", "view")
    ActionChains(browser).move_to_element(canvas).click_and_hold().move_by_offset(
        40, 0).move_by_offset(40, 10).release().perform()

    def refined_after_drag(b):
        frame = fetch_status(url)["frame"]
        if frame["camera_version"] <= 1 or frame["preview"] or frame["spp"] != 4:
            return False
        shown = b.execute_script(
            "const c = document.getElementById('view');"
            "return [Number(c.dataset.generation), c.dataset.spp];")
        ok = shown[0] is not None and shown[0] >= frame["generation"] and shown[1] == "4"
        return frame if ok else False

    moved = WebDriverWait(browser, WAIT).until(refined_after_drag)
    browser.save_screenshot(os.path.join(artifacts, "view_orbited.png"))
    eye0, eye1 = first["camera"]["eye"], moved["camera"]["eye"]
    lookat = first["camera"]["lookat"]
    if moved["camera"]["lookat"] != lookat:
        return fail(f"the look-at point moved: {lookat} -> {moved['camera']['lookat']}")
    if eye1 == eye0:
        return fail(f"the drag left the eye at {eye0}")
    r0, r1 = math.dist(eye0, lookat), math.dist(eye1, lookat)
    if abs(r1 - r0) > 1e-3 * r0:
        return fail(f"an orbit changed the distance to the look-at point: {r0} -> {r1}")
    _, after = canvas_digest(browser)
    if after == before:
        return fail("the canvas did not change after the drag")
    # The pictures came over the picture stream (/api/pictures, one long-lived response),
    # not a request each: no PNG fetched, no event stream opened; the refined one is PNG.
    stream = browser.execute_script(
        "const c = document.getElementById('view');"
        "const asked = performance.getEntriesByType('resource').map((e) => e.name);"
        "return {transport: c.dataset.transport, format: c.dataset.format,"
        " drawn: window.octrayStreamPictures,"
        " per_picture: asked.filter((n) => n.includes('/api/image.png') ||"
        "                                  n.includes('/api/events')).length};")
    if stream["transport"] != "stream" or not stream["drawn"]:
        return fail(f"the pictures did not come over the picture stream: {stream}")
    if stream["per_picture"]:
        return fail(f"the page asked for pictures one by one: {stream}")
    if stream["format"] != "png":
        return fail(f"the refined picture was not sent lossless (PNG): {stream}")
    # The exposure is applied by the server: the stream reopens with it and the picture
    # drawn next is brighter.
    _, unexposed = canvas_digest(browser)
    browser.execute_script(
        "const e = document.getElementById('exposure'); e.value = '2';"
        "e.dispatchEvent(new Event('input'));")
    WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
        "return document.getElementById('view').dataset.exposure === '2';"))
    _, exposed = canvas_digest(browser)
    if exposed == unexposed:
        return fail("the canvas did not change with the exposure")
    browser.execute_script(
        "const e = document.getElementById('exposure'); e.value = '0';"
        "e.dispatchEvent(new Event('input'));")
    WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
        "return document.getElementById('view').dataset.exposure === '0';"))

    # The wheel dollies: scrolling down moves the eye away along the view.
    ActionChains(browser).scroll_from_origin(ScrollOrigin.from_element(canvas), 0,
                                             200).perform()

    def refined_after_wheel(b):
        frame = fetch_status(url)["frame"]
        if (frame["camera_version"] <= moved["camera_version"] or frame["preview"]
                or frame["spp"] != 4):
            return False
        return frame

    dollied = WebDriverWait(browser, WAIT).until(refined_after_wheel)
    r2 = math.dist(dollied["camera"]["eye"], lookat)
    if not r2 > 1.01 * r1:
        return fail(f"the wheel did not dolly out: distance {r1} -> {r2}")
    print(f"PASS: {stream['drawn']} pictures drawn from the picture stream; "
          f"first picture {lit} lit pixels; drag moved the eye {eye0} -> {eye1} "
          f"(camera version {moved['camera_version']}); the wheel dollied from {r1:.3f} "
          f"to {r2:.3f}; screenshots in {artifacts}")
    return 0


def check_zoom(browser, WebDriverWait):
    """The z key (no click first) zooms the 160 x 90 picture to 1, 2, 4 and 8 screen pixels a
    pixel and back to fitting the window, and the value under the cursor at 2x is that of
    the picture pixel under it."""
    def shown():
        return browser.execute_script(
            "const r = document.getElementById('view').getBoundingClientRect();"
            "return [r.width, r.height, document.getElementById('zoom').textContent];")

    body = browser.find_element("tag name", "body")
    for width, height, label in ((160, 90, "1x"), (320, 180, "2x"), (640, 360, "4x"),
                                 (1280, 720, "8x"), (160, 90, "fit")):
        body.send_keys("z")
        got = shown()
        if abs(got[0] - width) > 0.5 or abs(got[1] - height) > 0.5 or got[2] != label:
            return fail(f"zoom {label}: the canvas is {got[0]} x {got[1]} ({got[2]!r}), "
                        f"expected {width} x {height}")
        if label == "2x":
            # Picture pixel (10, 5) is CSS pixels 20-21, 10-11 from the canvas's corner.
            browser.execute_script(
                "const c = document.getElementById('view');"
                "const r = c.getBoundingClientRect();"
                "c.dispatchEvent(new MouseEvent('mousemove', {bubbles: true,"
                " clientX: r.left + 21, clientY: r.top + 11}));")
            try:
                WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
                    "return document.getElementById('pixel').textContent"
                    ".startsWith('(10, 5)');"))
            except Exception:
                text = browser.execute_script(
                    "return document.getElementById('pixel').textContent;")
                return fail(f"at 2x the cursor over pixel (10, 5) reads {text!r}")
    # Fit: a picture larger than the window is shown whole, its shape kept.
    fits = browser.execute_script(
        "const c = document.getElementById('view'); const s = getComputedStyle(c);"
        "return [s.maxWidth, parseFloat(s.maxHeight), window.innerHeight];")
    if fits[0] != "100%" or abs(fits[1] - (fits[2] - 130)) > 1:
        return fail(f"fit: the canvas's max width and height are {fits[:2]}, expected 100% "
                    f"and the window's height ({fits[2]}) less the header and help")
    return 0


def check_frameless(browser, octray, artifacts, WebDriverWait):
    """The frameless order converges to the tiled order's picture: the same canvas pixels
    as a tiled viewer's refined first picture (the first URL's, before any drag)."""
    tiled, tiled_url = start_view(octray)
    frameless, frameless_url = start_view(octray, "--order", "frameless")
    try:
        digests = []
        for url, name, done in (
                (tiled_url, "view_tiled.png", lambda f: f["spp"] == 4 and not f["preview"]),
                (frameless_url, "view_frameless.png", lambda f: f["coverage"] == 1)):
            browser.get(url)

            def converged(b):
                frame = fetch_status(url)["frame"]
                if not done(frame):
                    return False
                generation = b.execute_script(
                    "return Number(document.getElementById('view').dataset.generation);")
                return generation is not None and generation >= frame["generation"]

            WebDriverWait(browser, WAIT).until(converged)
            digests.append(canvas_digest(browser))
            browser.save_screenshot(os.path.join(artifacts, name))
    finally:
        for process in (tiled, frameless):
            process.send_signal(signal.SIGINT)
            process.communicate(timeout=60)
    if digests[0] != digests[1]:
        return fail(f"frameless converged to another picture than tiled: {digests}")
    print(f"PASS: the frameless order converged to the tiled picture {digests[0]}")
    return 0


def check_save(browser, octray, WebDriverWait):
    """The save button writes the refined picture in the viewer's directory and shows the
    octray render command line that makes it again."""
    with tempfile.TemporaryDirectory() as folder:
        process, url = start_view(octray, cwd=folder)
        try:
            browser.get(url)
            WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
                "return document.body.dataset.spp === '4';"))
            name = browser.find_element("id", "save-name")
            name.clear()
            name.send_keys("saved.exr")
            browser.find_element("id", "save").click()
            command = WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
                "return document.getElementById('save-result').dataset.command;"))
            # The spp switch: the server re-renders up to the new spp.
            browser.execute_script(
                "const spp = document.getElementById('spp-switch'); spp.value = '2';"
                "spp.dispatchEvent(new Event('change'));")
            WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
                "return document.getElementById('target-spp').textContent === '2' && "
                "document.body.dataset.spp === '2';"))
            if fetch_status(url)["settings"]["spp"] != 2:
                return fail("the spp switch did not reach the server")
            # The ISA selector offers what the server says this CPU runs; the path switch
            # reaches the server.
            offered = browser.execute_script(
                "return [...document.getElementById('isa').options].map(o => o.value);")
            if offered != fetch_status(url)["isas"]:
                return fail(f"the page offers the ISAs {offered}, the server "
                            f"{fetch_status(url)['isas']}")
            browser.execute_script(
                "const path = document.getElementById('path'); path.value = 'scalar';"
                "path.dispatchEvent(new Event('change'));")
            WebDriverWait(browser, WAIT).until(
                lambda b: fetch_status(url)["settings"]["path"] == "scalar")
        finally:
            process.send_signal(signal.SIGINT)
            process.communicate(timeout=60)
        expected = "octray render whitted --width 160 --height 90 --spp 4 --max-depth "
        if not command.startswith(expected) or not command.endswith(" -o saved.exr"):
            return fail(f"save showed the command {command!r}")
        if not os.path.exists(os.path.join(folder, "saved.exr")):
            return fail("save did not write saved.exr in the viewer's directory")
    print(f"PASS: save wrote saved.exr and showed {command}; the spp switch re-rendered; "
          "the page offers the server's ISAs and switches the path")
    return 0


def check_frame(browser, octray, WebDriverWait):
    """An animated scene (scene/examples/bounce.json, 48 frames) shows the frame slider;
    moving it re-renders that frame, and save's command line names it (--frames N)."""
    scene = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scene",
                         "examples", "bounce.json")
    with tempfile.TemporaryDirectory() as folder:
        process, url = start_command(
            [octray, "view", scene, "--port", "0", "--width", "160", "--height", "90",
             "--spp", "2", "--threads", "2"], folder)
        try:
            browser.get(url)
            WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
                "return !document.getElementById('frame-controls').hidden && "
                "document.body.dataset.spp === '2';"))
            browser.execute_script(
                "const frame = document.getElementById('frame'); frame.value = '10';"
                "frame.dispatchEvent(new Event('input'));"
                "frame.dispatchEvent(new Event('change'));")
            WebDriverWait(browser, WAIT).until(
                lambda b: fetch_status(url).get("frame", {}).get("animation_frame") == 10
                and fetch_status(url)["frame"]["spp"] == 2)
            label = browser.execute_script(
                "return document.getElementById('frame-value').textContent;")
            if not label.startswith("10 / 47"):
                return fail(f"the frame slider's label says {label!r}")
            name = browser.find_element("id", "save-name")
            name.clear()
            name.send_keys("frame10.exr")
            browser.find_element("id", "save").click()
            command = WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
                "return document.getElementById('save-result').dataset.command;"))
        finally:
            process.send_signal(signal.SIGINT)
            process.communicate(timeout=60)
        if not command.endswith(" --frames 10 -o frame10.exr"):
            return fail(f"save showed the command {command!r} for frame 10")
    print(f"PASS: the frame slider rendered frame 10 ({label}); save showed {command}")
    return 0


def check_compare(browser, octray, artifacts, ActionChains, WebDriverWait):
    """`octray view A.exr B.exr`: the page shows compare's verdict, flips to the heatmap
    (drawn at the heatmap's size, not black), and shows the linear value under the cursor
    as the server reads it."""
    with tempfile.TemporaryDirectory() as folder:
        a, b = os.path.join(folder, "a.exr"), os.path.join(folder, "b.exr")
        for spp, path in ((1, a), (4, b)):
            subprocess.run([octray, "render", "whitted", "--width", "160", "--height", "90",
                            "--spp", str(spp), "--threads", "2", "-o", path], check=True,
                           capture_output=True, timeout=WAIT)
        process, url = start_command([octray, "view", a, b, "--port", "0"])
        try:
            status = fetch_status(url)
            browser.get(url)
            WebDriverWait(browser, WAIT).until(lambda br: br.execute_script(
                "return document.getElementById('view').dataset.picture === 'a';"))
            verdict = browser.execute_script(
                "return document.getElementById('figures').dataset.verdict;")
            if verdict != status["compare"]["verdict"]:
                return fail(f"the page shows verdict {verdict}, compare says "
                            f"{status['compare']['verdict']}")
            browser.save_screenshot(os.path.join(artifacts, "view_compare_a.png"))
            canvas = browser.find_element("id", "view")
            # The keys work on the page as loaded, before any click on the canvas.
            ActionChains(browser).send_keys("d").perform()
            WebDriverWait(browser, WAIT).until(lambda br: br.execute_script(
                "return document.getElementById('view').dataset.picture === 'diff';"))
            canvas.click()
            canvas.send_keys("h")
            WebDriverWait(browser, WAIT).until(lambda br: br.execute_script(
                "const c = document.getElementById('view');"
                f"return c.dataset.picture === 'heatmap' && c.width === {status['heatmap_width']};"))
            lit, _ = canvas_digest(browser)
            if lit == 0:
                return fail("the heatmap is black")
            browser.save_screenshot(os.path.join(artifacts, "view_compare_heatmap.png"))
            # The value under the cursor: the top-left pixel's |A - B| (the heatmap's).
            canvas.send_keys("a")
            WebDriverWait(browser, WAIT).until(lambda br: br.execute_script(
                "return document.getElementById('view').dataset.picture === 'a';"))
            ActionChains(browser).move_to_element_with_offset(canvas, 0, 0).perform()
            shown = WebDriverWait(browser, WAIT).until(lambda br: br.execute_script(
                "return document.getElementById('pixel').dataset.rgb;"))
            text = browser.execute_script("return document.getElementById('pixel').textContent;")
            x, y = [int(v) for v in text.split(")")[0].strip("(").split(",")]
            base, token = url.split("/?token=")
            with urllib.request.urlopen(f"{base}/api/pixel?token={token}&picture=a&x={x}&y={y}",
                                        timeout=30) as response:
                expected = json.load(response)["rgb"]
            if json.loads(shown) != expected:
                return fail(f"the page shows {shown} at ({x}, {y}), the server {expected}")
        finally:
            process.send_signal(signal.SIGINT)
            out, err = process.communicate(timeout=60)
        if process.returncode != 0:
            return fail(f"octray view A B exited {process.returncode}: {err}")
    print(f"PASS: the A/B page shows {verdict} and the heatmap; the cursor reads {text}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(run(sys.argv[1], sys.argv[2]))
