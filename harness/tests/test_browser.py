"""The HTML report in a real browser (issue 23): Debian's chromium, headless, driven through its
WebDriver (chromedriver, plain HTTP + JSON: no Python package beyond the standard library).

A page passes when every image has decoded (naturalWidth > 0), every link resolves (an anchor
to an element of the page, a relative link to a file that exists), the browser's console has no
error (a script error, a resource that failed to load), and the file is at most PAGE_MAX bytes.
A screenshot of the top of the page is saved beside it (browser.png).

test_report_of_a_fake_project: a validate of the fake project (tests/fakes.py) in make test.
test_report_of_the_catalogue: reports/index.html of this work tree when there is one (.ci/run
runs it after `make validate`: `make test-browser`).  Both are skipped, with the reason, where
chromium or chromedriver is absent (.ci/install-browser-deps installs them).
"""
import base64
import json
import os
import shutil
import socket
import subprocess
import time
import urllib.error
import urllib.request
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest

from harness.__main__ import main

REPO = Path(__file__).resolve().parents[2]
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
DRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
PAGE_MAX = 16 * 1024 * 1024     # an index.html a browser opens at once and a mail can carry
needs_browser = pytest.mark.skipif(not (os.path.exists(CHROMIUM) and os.path.exists(DRIVER)),
                                   reason="Debian's chromium and chromium-driver are not installed "
                                          "(.ci/install-browser-deps)")

# Run in the page after it has loaded: what is broken, as JSON-able lists.
INSPECT = """
const images = Array.from(document.images).map(i => ({alt: i.alt, ok: i.complete && i.naturalWidth > 0}));
const links = Array.from(document.querySelectorAll('a[href]')).map(a => a.getAttribute('href'));
const anchors = links.filter(h => h.startsWith('#')).filter(h => !document.getElementById(decodeURIComponent(h.slice(1))));
return {images: images, links: links, missing_anchors: anchors, title: document.title,
        height: document.body.scrollHeight};
"""


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Driver:
    """A chromedriver process and one headless chromium session."""

    def __init__(self):
        self.port = free_port()
        self.proc = subprocess.Popen([DRIVER, f"--port={self.port}"], stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 30
        while True:
            try:
                if self.call("GET", "/status")["value"].get("ready"):
                    break
            except (urllib.error.URLError, ConnectionError, OSError):
                pass
            if time.monotonic() > deadline:
                self.proc.kill()
                raise RuntimeError("chromedriver did not become ready in 30 s")
            time.sleep(0.1)
        options = {"binary": CHROMIUM, "args": ["--headless=new", "--no-sandbox", "--disable-gpu",
                                                 "--disable-dev-shm-usage", "--window-size=1280,900",
                                                 "--allow-file-access-from-files"]}
        caps = {"capabilities": {"alwaysMatch": {"browserName": "chrome", "goog:chromeOptions": options,
                                                 "goog:loggingPrefs": {"browser": "ALL"}}}}
        self.session = self.call("POST", "/session", caps)["value"]["sessionId"]

    def call(self, method, path, body=None):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(f"http://127.0.0.1:{self.port}{path}", data=data, method=method,
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=120) as r:
            return json.loads(r.read().decode())

    def do(self, method, path, body=None):
        return self.call(method, f"/session/{self.session}{path}", body)["value"]

    def close(self):
        try:
            self.call("DELETE", f"/session/{self.session}")
        finally:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()


def inspect_page(index):
    """What the browser found on the page: images, links, console errors; saves browser.png."""
    driver = Driver()
    try:
        driver.do("POST", "/url", {"url": index.resolve().as_uri()})
        found = driver.do("POST", "/execute/sync", {"script": INSPECT, "args": []})
        found["console"] = [e for e in driver.do("POST", "/se/log", {"type": "browser"})
                            if e.get("level") == "SEVERE"]
        shot = driver.do("GET", "/screenshot")
        (index.parent / "browser.png").write_bytes(base64.b64decode(shot))
    finally:
        driver.close()
    return found


def assert_page_sound(index):
    size = index.stat().st_size
    assert size <= PAGE_MAX, f"{index} is {size / 1e6:.1f} MB, above the {PAGE_MAX / 1e6:.1f} MB a page may be"
    found = inspect_page(index)
    broken = [i["alt"] for i in found["images"] if not i["ok"]]
    assert not broken, f"images that did not decode: {broken}"
    assert not found["missing_anchors"], f"links to no element of the page: {found['missing_anchors']}"
    for href in found["links"]:
        if href.startswith("#"):
            continue
        url = urlparse(href)
        assert url.scheme in ("", "file"), f"a link out of the report: {href}"
        target = (index.parent / unquote(url.path)).resolve()
        assert target.exists(), f"a link to a file that does not exist: {href}"
    assert not found["console"], f"errors in the browser's console: {found['console']}"
    assert (index.parent / "browser.png").stat().st_size > 1000
    return found


@needs_browser
def test_report_of_a_fake_project(project):
    assert main(["validate", "--no-stability"]) == 0
    found = assert_page_sound(project / "reports" / "index.html")
    assert found["images"] and found["title"].startswith("ballast")


@needs_browser
@pytest.mark.skipif(not (REPO / "reports" / "index.html").exists(),
                    reason="no reports/index.html in this work tree (make validate writes it)")
def test_report_of_the_catalogue():
    found = assert_page_sound(REPO / "reports" / "index.html")
    assert len(found["images"]) >= 10
