"""Screenshots of a page in headless Chromium once it has had time to draw, through the
DevTools protocol (Chromium's --screenshot takes its picture before a WebAssembly app
such as rerun's web viewer has loaded).

    python scripts/viewer_screenshot.py URL OUT.png [--wait SECONDS] [--size WxH]
        [--key KEY]...

Each --key is pressed after the wait (e.g. `Home` or `ArrowLeft` to move along the
viewer's timeline), a second apart, before the picture is taken. Exit status 1 with the
reason when Chromium does not start or the picture cannot be taken.
"""

import argparse
import base64
import json
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

import websocket

KEYS = {
    "Home": ("Home", 36),
    "End": ("End", 35),
    "ArrowLeft": ("ArrowLeft", 37),
    "ArrowRight": ("ArrowRight", 39),
    "Space": (" ", 32),
}


def fail(message):
    print(f"viewer_screenshot: {message}", file=sys.stderr)
    sys.exit(1)


def devtools_page(port, deadline):
    while time.time() < deadline:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=2) as r:
                pages = [t for t in json.load(r) if t.get("type") == "page"]
            if pages:
                return pages[0]["webSocketDebuggerUrl"]
        except OSError:
            pass
        time.sleep(0.3)
    fail("Chromium's DevTools endpoint did not answer")


class Page:
    def __init__(self, url):
        self.ws = websocket.create_connection(url, timeout=60)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            reply = json.loads(self.ws.recv())
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    fail(f"{method}: {reply['error']}")
                return reply.get("result", {})


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("url")
    parser.add_argument("out")
    parser.add_argument("--wait", type=float, default=25.0)
    parser.add_argument("--size", default="1600x1000")
    parser.add_argument("--key", action="append", default=[])
    parser.add_argument("--port", type=int, default=9333)
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        fail("chromium is not installed (Debian: apt-get install chromium)")
    profile = tempfile.mkdtemp(prefix="betr-chromium-")
    browser = subprocess.Popen(
        [
            chromium,
            "--headless=new",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--ignore-gpu-blocklist",
            f"--remote-debugging-port={args.port}",
            f"--user-data-dir={profile}",
            f"--window-size={width},{height}",
            "about:blank",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        page = Page(devtools_page(args.port, time.time() + 30))
        page.call("Emulation.setDeviceMetricsOverride", width=width, height=height,
                  deviceScaleFactor=1, mobile=False)
        page.call("Page.enable")
        page.call("Page.navigate", url=args.url)
        time.sleep(args.wait)
        for key in args.key:
            name, code = KEYS.get(key, (key, 0))
            for kind in ("keyDown", "keyUp"):
                page.call("Input.dispatchKeyEvent", type=kind, key=name, code=key,
                          windowsVirtualKeyCode=code)
            time.sleep(1.0)
        shot = page.call("Page.captureScreenshot", format="png")
        with open(args.out, "wb") as f:
            f.write(base64.b64decode(shot["data"]))
    finally:
        browser.terminate()
        try:
            browser.wait(timeout=10)
        except subprocess.TimeoutExpired:
            browser.kill()
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    main()
