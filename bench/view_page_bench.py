#!/usr/bin/env python3
"""The page of `octray view` as a user sees it: its frame rate in a real browser.

    view_page_bench.py OCTRAY [SCENE] [--width W] [--height H] [--threads T]
                       [--moves N] [--move-ms MS | --script-ms MS] [--preview-divisor D]

`octray view --bench` times the renderer and the PNG encoding without a browser. This
opens the page in headless Chromium (chromedriver, python3-selenium: tools/setup.sh
installs them), as `octray view SCENE` serves it on a free port, and reports:

  first picture   ms from the start of the page's navigation to its first picture drawn
                  on the canvas (the page's own clock, performance.now()),
  orbit           pictures drawn per second while a pointer drags across the canvas in
                  N moves of MS ms each (chromedriver plays them, and the drag takes as
                  long as it takes: that time is measured, and the moves a second are
                  printed beside the pictures a second, since the page cannot draw more
                  pictures than the camera makes; the camera orbits the look-at point and
                  the server renders reduced-size previews while it moves), with the
                  page's Mrays/s of the last picture; with --script-ms the page's own
                  script makes the same camera moves every MS ms instead (a mouse, and
                  chromedriver's pointer, give about 60 a second at most),
  refined         ms from the end of the drag to the refined picture (target spp) drawn.

Each picture is a message of the picture stream, its decode and the draw: the loopback
transfer and the browser's work are in these figures. A bench, not a test: it asserts
nothing about speed; exit 1 if the page never draws, 77 if Chromium, chromedriver or
selenium is missing.
"""

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile

WAIT = 60  # seconds, for a loaded machine


def start_view(args):
    command = [args.octray, "view", args.scene, "--port", "0", "--width", str(args.width),
               "--height", str(args.height), "--threads", str(args.threads)]
    if args.preview_divisor:
        command += ["--preview-divisor", str(args.preview_divisor)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)
    for line in process.stdout:
        if line.strip().startswith("http://"):
            return process, line.strip()
    process.wait()
    sys.exit("octray view printed no URL: " + process.stderr.read())


def measure(browser, url, moves, move_ms, script_ms, ActionChains, WebDriverWait):
    browser.set_page_load_timeout(WAIT)
    browser.set_script_timeout(WAIT + moves * (script_ms or 0) / 1000)
    browser.get(url)
    WebDriverWait(browser, WAIT).until(
        lambda b: b.execute_script("return window.octrayDrawTimes.length > 0"))
    first_ms = browser.execute_script("return window.octrayDrawTimes[0]")
    loaded_ms = browser.execute_script(
        "const n = performance.getEntriesByType('navigation')[0];"
        "return n ? n.domContentLoadedEventEnd : null;")
    # Let the first picture refine before moving the camera.
    WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
        "return document.body.dataset.preview === 'false' && "
        "document.body.dataset.spp === document.getElementById('target-spp').textContent"))

    canvas = browser.find_element("id", "view")
    if script_ms is None:
        # One W3C action sequence: chromedriver plays the moves, each lasting move_ms.
        chain = ActionChains(browser, duration=move_ms).move_to_element(canvas).click_and_hold()
        for k in range(moves):
            chain.move_by_offset(1 if (k // 120) % 2 == 0 else -1, 0)
        start = browser.execute_script("return performance.now()")
        chain.release().perform()
        end = browser.execute_script("return performance.now()")
    else:
        # The page's own camera calls, as a drag makes them (orbit by one pixel's angle,
        # sendCamera moving), every script_ms ms from a timer: camera changes faster
        # than the ~60 a second chromedriver's pointer moves reach.
        start, end = browser.execute_async_script("""
            const [moves, everyMs, done] = arguments;
            const from = camera, step = Math.PI / canvas.clientWidth;
            const start = performance.now();
            let k = 0, x = 0;
            const timer = setInterval(() => {
              x += (Math.floor(k / 120) % 2 === 0) ? 1 : -1;
              sendCamera(orbit(from, -x * step, 0), true);
              if (++k < moves) return;
              clearInterval(timer);
              sendCamera(camera, false);
              done([start, performance.now()]);
            }, everyMs);""", moves, script_ms)
    draws = browser.execute_script(
        "return window.octrayDrawTimes.filter(t => t >= arguments[0] && t <= arguments[1])"
        ".length", start, end)
    mrays = browser.find_element("id", "mrays").text
    WebDriverWait(browser, WAIT).until(lambda b: b.execute_script(
        "return document.body.dataset.preview === 'false' && "
        "document.body.dataset.spp === document.getElementById('target-spp').textContent && "
        "Number(document.getElementById('view').dataset.spp) === Number(document.body.dataset.spp)"))
    refined_ms = browser.execute_script(
        "return window.octrayDrawTimes[window.octrayDrawTimes.length - 1]") - end
    # How the pictures came: the picture stream (issue 44), or an event and a PNG request
    # each (the page before it).
    transport = browser.execute_script(
        "return document.getElementById('view').dataset.transport || 'event + PNG request'")
    return first_ms, loaded_ms, draws, (end - start) / 1000.0, mrays, refined_ms, transport


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("octray")
    parser.add_argument("scene", nargs="?", default="whitted")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--moves", type=int, default=180,
                        help="pointer moves of the drag (default 180)")
    parser.add_argument("--move-ms", type=int, default=16,
                        help="each move's duration in ms (default 16, a 60 Hz mouse; 0: as "
                             "fast as chromedriver plays them)")
    parser.add_argument("--preview-divisor", type=int, default=0,
                        help="passed to octray view (default: its own)")
    parser.add_argument("--script-ms", type=int, default=None,
                        help="move the camera from the page's own script every MS ms "
                             "instead of by a pointer drag (which chromedriver plays at "
                             "~60 moves a second at most)")
    args = parser.parse_args()
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.support.ui import WebDriverWait
    except ImportError:
        print("SKIP: python3-selenium is not installed")
        return 77
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver") or (
        "/usr/bin/chromedriver" if os.path.exists("/usr/bin/chromedriver") else None)
    if not chromium or not driver:
        print("SKIP: chromium or chromedriver is not installed")
        return 77

    process, url = start_view(args)
    try:
        with tempfile.TemporaryDirectory() as profile:
            options = webdriver.ChromeOptions()
            options.binary_location = chromium
            for argument in ("--headless=new", "--no-sandbox", "--disable-gpu",
                             "--disable-dev-shm-usage", "--window-size=1000,700",
                             f"--user-data-dir={profile}"):
                options.add_argument(argument)
            browser = webdriver.Chrome(service=Service(driver), options=options)
            try:
                first_ms, loaded_ms, draws, seconds, mrays, refined_ms, transport = measure(
                    browser, url, max(1, args.moves), max(0, args.move_ms), args.script_ms,
                    ActionChains, WebDriverWait)
            finally:
                browser.quit()
    finally:
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=60)
    loaded = f" (DOMContentLoaded at {loaded_ms:.0f} ms)" if loaded_ms else ""
    print(f"scene {args.scene} {args.width}x{args.height}, {args.threads} threads, "
          f"pictures by {transport}")
    print(f"first picture: drawn {first_ms:.0f} ms after navigation began{loaded}")
    motion = "dragging" if args.script_ms is None else f"camera moves every {args.script_ms} ms"
    print(f"orbit: {draws} pictures drawn in {seconds:.2f} s of {motion} ({args.moves} moves, "
          f"{args.moves / seconds:.1f} a second): {draws / seconds:.1f} pictures/s; "
          f"last picture {mrays} Mrays/s")
    if refined_ms >= 0:
        print(f"refined: drawn {refined_ms:.0f} ms after the drag ended")
    else:  # the last move's picture refined before chromedriver answered the action
        print("refined: drawn before the drag's end was read")
    if draws == 0:
        print("FAIL: the page drew no picture while the camera moved")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
