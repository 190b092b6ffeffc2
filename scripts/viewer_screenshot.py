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
import os
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ left in scripts/ by the import below
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from devtools import Browser, DevToolsError  # noqa: E402

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
    flags = [
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--ignore-gpu-blocklist",
        f"--window-size={width},{height}",
    ]
    try:
        with Browser(args.port, flags) as page:
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
    except DevToolsError as e:
        fail(str(e))
    with open(args.out, "wb") as f:
        f.write(base64.b64decode(shot["data"]))

if __name__ == "__main__":
    main()
