#!/usr/bin/env python3
"""The page in a real browser: headless Chromium (through Selenium and
chromedriver) opens --live's page while ptr renders, sees the image change
as passes land and the progress advance, its exposure control brighten the
image and its denoised preview's box reach ptr (on, then off: the image
drawn last is as rendered), and at the end holds on its canvas
the PNG ptr wrote (the same view), within 1/255. Exits 77 (skipped) only
where Chromium, chromedriver or Selenium is missing, saying which.

Usage: test_browser.py PTR SOURCE_DIR [SANITIZED]
With $PTR_LIVE_SCREENSHOT set to a file name, it saves a screenshot of the
page at its second image of the render (docs/images/live.png)."""
import base64
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "support"))
from live_client import Page, Ptr, read_ppm, samples as samples_for, wait_for  # noqa: E402

SKIP = 77
ptr, src = sys.argv[1], sys.argv[2]
screenshot = os.environ.get("PTR_LIVE_SCREENSHOT")


def find_browser():
    try:
        from selenium import webdriver  # noqa: F401
    except ImportError:
        # Debian's python3-selenium is for Debian's python3, which may not
        # be the python3 first on the PATH.
        system = "/usr/bin/python3"
        if os.path.exists(system) and os.path.realpath(sys.executable) != os.path.realpath(system):
            os.execv(system, [system] + sys.argv)
        return None, None, "python3-selenium is not installed"
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver") or (
        "/usr/bin/chromedriver" if os.path.exists("/usr/bin/chromedriver") else None)
    if not browser:
        return None, None, "chromium is not installed"
    if not driver:
        return None, None, "chromium-driver (chromedriver) is not installed"
    return browser, driver, None


def start_browser(browser, driver):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = browser
    for arg in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=900,700", "--force-color-profile=srgb", "--no-first-run"]:
        options.add_argument(arg)
    return webdriver.Chrome(service=Service(driver), options=options)


CANVAS = """
const c = document.getElementById('image');
const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
let s = '';
for (let i = 0; i < d.length; i += 0x8000) s += String.fromCharCode.apply(null, d.subarray(i, i + 0x8000));
return [c.width, c.height, c.dataset.frame, document.body.dataset.state || '',
        Number(document.body.dataset.samples || 0), btoa(s)];
"""


def mean(pixels):
    data = base64.b64decode(pixels)
    return sum(data[i] for i in range(0, len(data), 4 * 7)) / max(1, len(data) // (4 * 7))


SET_STOPS = """
const s = document.getElementById('stops');
s.value = arguments[0];
s.dispatchEvent(new Event('input'));
"""


def try_exposure(web, p, before):
    """Two stops more on the page's control: an image comes that is brighter
    (the view applied by ptr); then back to 0."""
    web.execute_script(SET_STOPS, 2)
    end = time.time() + 10
    result = "no brighter image within 10 s"
    while time.time() < end and p.process.poll() is None:
        pixels = web.execute_script(CANVAS)[5]
        if mean(pixels) > before * 1.3:
            result = "brighter"
            break
        time.sleep(0.05)
    else:
        if p.process.poll() is not None:
            result = "render ended first"
    web.execute_script(SET_STOPS, 0)
    return result


def try_preview(web, p, url):
    """The denoised preview's toggle, on then off: ptr hears each (the state
    it sends says so), and the page's box follows the state."""
    listener = Page(url)
    result = "on and off"
    for on in (True, False):
        web.execute_script("document.getElementById('denoise').click()")
        heard = wait_for(lambda: any(s["preview"] == on for s in listener.states[-1:]), 10)
        if p.process.poll() is not None:
            result = "render ended first"
            break
        checked = web.execute_script("return document.getElementById('denoise').checked")
        if not heard or checked != on:
            result = "the toggle %s did not reach ptr or the page" % ("on" if on else "off")
            break
    listener.close()
    return result


def main():
    global screenshot
    total = samples_for(600)
    browser, driver, why = find_browser()
    if why:
        print("skipped: " + why + " (Debian: apt-get install chromium chromium-driver "
              "python3-selenium)")
        return SKIP
    failures = []

    def check(ok, message):
        if not ok:
            failures.append(message)
            print("FAIL: " + message, file=sys.stderr)

    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "live.png")
        web = start_browser(browser, driver)
        try:
            p = Ptr([ptr, os.path.join(src, "scenes", "seed.gltf"), "-o", out, "--width", "256",
                     "--height", "256", "--samples", str(total), "--threads", "2", "--live", "0"])
            url = p.url()
            if not url:
                p.process.kill()
                print("FAIL: ptr printed no address: " + p.stderr, file=sys.stderr)
                return 1
            web.get(url)
            seen, samples, exposure, preview = {}, [], "not tried", "not tried"
            while p.process.poll() is None:
                w, h, frame, state, done, pixels = web.execute_script(CANVAS)
                if w > 1:
                    seen.setdefault(hashlib.sha1(pixels.encode()).hexdigest(), frame)
                samples.append(done)
                if screenshot and len(seen) >= 2 and state == "rendering":
                    web.save_screenshot(screenshot)
                    screenshot = None
                if exposure == "not tried" and len(seen) >= 2:
                    exposure = try_exposure(web, p, mean(pixels))
                elif preview == "not tried" and exposure != "not tried":
                    preview = try_preview(web, p, url)
                time.sleep(0.2)
            check(exposure in ("brighter", "render ended first"),
                  "the exposure control: %s" % exposure)
            check(preview in ("on and off", "render ended first") or
                  (preview == "not tried" and exposure == "render ended first"),
                  "the preview's toggle: %s" % preview)
            code = p.wait()
            check(code == 0, "ptr: exit %d: %s" % (code, p.stderr))
            # The page keeps the last image: wait for it to be drawn.
            end = time.time() + 10
            while time.time() < end:
                w, h, frame, state, done, pixels = web.execute_script(CANVAS)
                if state == "done":
                    break
                time.sleep(0.1)
            time.sleep(0.5)
            w, h, frame, state, done, pixels = web.execute_script(CANVAS)
            check(state == "done" and done == total, "the page's last state: %s, %s samples"
                  % (state, done))
            check(len(seen) >= 3, "the canvas showed %d different images during the render, "
                  "not 3 or more" % len(seen))
            check(samples == sorted(samples) and len(set(samples)) >= 3,
                  "the samples shown did not advance: %s" % samples)
        finally:
            web.quit()
        ppm = os.path.join(d, "live.ppm")
        subprocess.run(["oiiotool", out, "-o", ppm], check=True)
        pw, ph, reference = read_ppm(ppm)
        rgba = base64.b64decode(pixels)
        check((w, h) == (pw, ph), "canvas %dx%d, PNG %dx%d" % (w, h, pw, ph))
        if (w, h) == (pw, ph):
            worst = max(abs(rgba[4 * i + c] - reference[3 * i + c])
                        for i in range(w * h) for c in range(3))
            check(worst <= 1, "the canvas differs from the PNG by %d/255" % worst)
            print("browser: %d images shown during the render; exposure +2: %s; the preview's "
                  "toggle: %s; the canvas is the PNG within %d/255"
                  % (len(seen), exposure, preview, worst))
    if failures:
        return 1
    print("browser: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
