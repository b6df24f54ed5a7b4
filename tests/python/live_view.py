"""Drives Shoal's web view in a real headless Chromium (Debian's), over the Chrome DevTools
Protocol with the `websockets` package (pinned in requirements.txt): loads the page, waits for what a person would
look for, reads back what the page drew (`window.shoalView.summary()`), and takes screenshots.

    python live_view.py CHROMIUM URL OUTDIR live     # a running mission
    python live_view.py CHROMIUM URL OUTDIR replay   # a replayed log
    python live_view.py CHROMIUM URL OUTDIR conflict # a replayed log ending in a conflict

Prints one JSON object per step on stdout ({"step", "before_us", "after_us", "summary"}); the
Rust test compares them with the run's mission log. Screenshots go to OUTDIR/<step>.png.
Exits non-zero, saying which wait failed, when the page never shows what was waited for.
"""

import base64
import json
import os
import shutil
import subprocess
import sys
import time
import urllib.request

from websockets.sync.client import connect

WAIT_S = 120


class Page:
    """One page target of the browser, spoken to over CDP."""

    def __init__(self, ws_url):
        self.ws = connect(ws_url, max_size=None, open_timeout=30)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        mine = self.next_id
        self.ws.send(json.dumps({"id": mine, "method": method, "params": params}))
        while True:
            reply = json.loads(self.ws.recv(timeout=60))
            if reply.get("id") == mine:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def evaluate(self, expression):
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        if "exceptionDetails" in r:
            return None
        return r.get("result", {}).get("value")

    def summary(self):
        text = self.evaluate(
            "window.shoalView && window.shoalView.summary ? "
            "(window.shoalView.draw(), JSON.stringify(window.shoalView.summary())) : null"
        )
        return json.loads(text) if text else None

    def screenshot(self, path):
        r = self.call("Page.captureScreenshot", format="png")
        with open(path, "wb") as f:
            f.write(base64.b64decode(r["data"]))


def launch(chromium, outdir):
    profile = os.path.join(outdir, "profile")
    shutil.rmtree(profile, ignore_errors=True)
    os.makedirs(profile)
    log = open(os.path.join(outdir, "chromium.log"), "wb")
    proc = subprocess.Popen(
        [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--remote-debugging-port=0", f"--user-data-dir={profile}",
         "--window-size=1500,1100", "about:blank"],
        stdout=log, stderr=log, stdin=subprocess.DEVNULL)
    port_file = os.path.join(profile, "DevToolsActivePort")
    end = time.time() + 60
    while not os.path.exists(port_file) or not open(port_file).read().strip():
        if time.time() > end or proc.poll() is not None:
            raise SystemExit(f"chromium did not start (see {outdir}/chromium.log)")
        time.sleep(0.1)
    port = open(port_file).read().split()[0]
    targets = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10))
    page = next(t for t in targets if t.get("type") == "page")
    return proc, Page(page["webSocketDebuggerUrl"])


def wait_for(page, what, test):
    end = time.time() + WAIT_S
    last = None
    while time.time() < end:
        last = page.summary()
        if last and test(last):
            return last
        time.sleep(0.2)
    raise SystemExit(f"the page never showed {what}; last summary: {json.dumps(last)}")


def step(page, outdir, name, summary=None):
    before = time.time_ns() // 1000
    s = summary or page.summary()
    after = time.time_ns() // 1000
    page.screenshot(os.path.join(outdir, f"{name}.png"))
    print(json.dumps({"step": name, "before_us": before, "after_us": after, "summary": s}), flush=True)
    return s


def complete(s):
    """Caught up, every vehicle of the table drawn."""
    return s["caughtUp"] and s["rows"] > 0 and len(s["vehicles"]) == s["rows"]


def published(s):
    return any(o["published"] for o in s["obstacles"])


def live(page, url, outdir):
    page.call("Page.navigate", url=url)
    wait_for(page, "every vehicle", lambda s: complete(s) and s["t_s"] is not None and s["t_s"] > 0)
    step(page, outdir, "vehicles")
    wait_for(page, "a predicted closest approach", lambda s: s["predicted"] is not None)
    step(page, outdir, "predicted")
    wait_for(page, "a published obstacle", lambda s: complete(s) and published(s))
    step(page, outdir, "obstacle")
    # The socket drops: the page reconnects and catches up.
    page.evaluate("window.shoalView.socket.close()")
    s = wait_for(page, "the state back after a reconnect",
                 lambda s: s["connections"] >= 2 and s["connected"] and complete(s) and published(s))
    step(page, outdir, "reconnected", s)
    # A reload: a new page, caught up from scratch.
    page.call("Page.reload")
    s = wait_for(page, "the state back after a reload",
                 lambda s: s["connections"] == 1 and complete(s) and published(s))
    step(page, outdir, "reloaded", s)


def replay(page, url, outdir):
    page.call("Page.navigate", url=url)
    s = wait_for(page, "the replayed log", lambda s: s["mode"] == "replay" and complete(s))
    step(page, outdir, "replay-end", s)
    # Halfway through with the slider, as a person would drag it.
    page.evaluate(
        "(() => { const r = document.getElementById('slider');"
        " r.value = (Number(r.min) + Number(r.max)) / 2;"
        " r.dispatchEvent(new Event('input')); })()")
    s = wait_for(page, "the slider's time", lambda s: s["mode"] == "replay" and len(s["vehicles"]) > 0)
    step(page, outdir, "replay-middle", s)


def conflict(page, url, outdir):
    """A replayed log that ends with a predicted conflict: the line is drawn red."""
    page.call("Page.navigate", url=url)
    s = wait_for(page, "a predicted conflict",
                 lambda s: s["mode"] == "replay" and s["caughtUp"] and s["ended"]
                 and s["predicted"] is not None and s["predicted"]["conflict"])
    # What the browser paints, not what the page says it drew.
    s["predicted_stroke"] = page.evaluate(
        "getComputedStyle(document.querySelector('#top [data-predicted]')).stroke")
    step(page, outdir, "conflict", s)


def main():
    chromium, url, outdir, mode = sys.argv[1:5]
    os.makedirs(outdir, exist_ok=True)
    proc, page = launch(chromium, outdir)
    try:
        page.call("Page.enable")
        page.call("Runtime.enable")
        {"live": live, "replay": replay, "conflict": conflict}[mode](page, url, outdir)
    finally:
        try:
            page.call("Browser.close")
        except Exception:
            pass
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
        # Only the screenshots are kept.
        shutil.rmtree(os.path.join(outdir, "profile"), ignore_errors=True)


if __name__ == "__main__":
    main()
