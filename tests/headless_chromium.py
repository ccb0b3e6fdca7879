"""Headless Chromium for the browser tests (tests/view/browser_test.py, tests/docs/
figures_test.py): Debian's chromium driven by chromedriver through python3-selenium, all
three installed by tools/setup.sh.

    browser, reason = headless_chromium.start(profile_dir, "640,400")
    if browser is None: skip(reason)
"""

import os
import shutil


def start(profile, window_size, extra_arguments=()):
    """A headless Chromium with its profile in `profile` and a window of `window_size`
    ("W,H"), or (None, why) when selenium, chromium or chromedriver is missing."""
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        return None, "python3-selenium is not installed"
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver") or (
        "/usr/bin/chromedriver" if os.path.exists("/usr/bin/chromedriver") else None)
    if not chromium or not driver:
        return None, "chromium or chromedriver is not installed"
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu",
                     "--disable-dev-shm-usage", f"--window-size={window_size}",
                     f"--user-data-dir={profile}", *extra_arguments):
        options.add_argument(argument)
    return webdriver.Chrome(service=Service(driver), options=options), None
