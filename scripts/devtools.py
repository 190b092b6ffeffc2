"""Headless Chromium driven through its DevTools protocol, for the scripts that take
pictures in a browser (viewer_screenshot.py, picture_check.py).

    with Browser(port, flags) as page:
        page.call("Page.navigate", url=...)
        page.evaluate("document.readyState")

Every failure to start or drive Chromium is a DevToolsError with the reason.
"""

import json
import shutil
import subprocess
import tempfile
import time
import urllib.request

import websocket


class DevToolsError(Exception):
    """Chromium could not be started or driven."""


class Page:
    """One page of the browser, spoken to over its DevTools websocket."""

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
                    raise DevToolsError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def evaluate(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True,
                           awaitPromise=True)
        if "exceptionDetails" in result:
            raise DevToolsError(f"script failed in the page: {result['exceptionDetails']}")
        return result["result"].get("value")


def devtools_page(port, deadline):
    """The websocket address of the browser's first page, once it answers."""
    while time.time() < deadline:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=2) as r:
                pages = [t for t in json.load(r) if t.get("type") == "page"]
            if pages:
                return pages[0]["webSocketDebuggerUrl"]
        except OSError:
            pass
        time.sleep(0.3)
    raise DevToolsError(f"Chromium's DevTools endpoint on port {port} did not answer")


class Browser:
    """Headless Chromium on about:blank with its DevTools on `port` and `flags` added, in
    a profile of its own that is removed when it stops."""

    def __init__(self, port, flags=()):
        self.port = port
        self.flags = list(flags)
        self.process = None
        self.profile = None

    def __enter__(self):
        chromium = shutil.which("chromium") or shutil.which("chromium-browser")
        if not chromium:
            raise DevToolsError("chromium is not installed (Debian: apt-get install chromium)")
        self.profile = tempfile.mkdtemp(prefix="betr-chromium-")
        self.process = subprocess.Popen(
            [chromium, "--headless=new", "--no-sandbox", *self.flags,
             f"--remote-debugging-port={self.port}", f"--user-data-dir={self.profile}",
             "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            return Page(devtools_page(self.port, time.time() + 30))
        except BaseException:
            self.__exit__(None, None, None)
            raise

    def __exit__(self, *_):
        self.process.terminate()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
        shutil.rmtree(self.profile, ignore_errors=True)
        return False
