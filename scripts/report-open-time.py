#!/usr/bin/env python3
"""Opens report.html files in headless Chromium (software WebGL, through
chromedriver) and prints, per file: its size, the 3D view's share of it,
the load event and the view's first frame (milliseconds after navigation
start), and the time to draw one frame (the mean of 20) at rest and while
the view turns (a subsample of at most about 30 000 points), each the
median of three loads.

    python3 scripts/report-open-time.py fits/alu-ggx/report.html other/report.html

The figures of docs/plots.md ("The 3D view") come from this script."""

import json
import os
import socket
import statistics
import subprocess
import sys
import time
import urllib.request


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main(paths):
    port = free_port()
    driver = subprocess.Popen(["chromedriver", f"--port={port}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def call(method, path, body=None):
        data = json.dumps(body).encode() if body is not None else None
        req = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data, method=method,
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=120) as r:
            return json.loads(r.read())["value"]

    try:
        for _ in range(100):
            try:
                call("GET", "/status")
                break
            except OSError:
                time.sleep(0.1)
        args = ["--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--window-size=1280,1000"]
        session = call("POST", "/session", {"capabilities": {"alwaysMatch": {
            "browserName": "chrome", "goog:chromeOptions": {"args": args}}}})["sessionId"]
        at = lambda p: f"/session/{session}{p}"
        wait = """const done = arguments[arguments.length - 1];
            const t0 = performance.now();
            (function poll() {
                const v = document.querySelector('.brtf-view');
                if (v && v.brtfView && v.brtfView.ready) {
                    const time = (turning) => {
                        const t = performance.now();
                        for (let k = 0; k < 20; k++) v.brtfView.frame(turning);
                        return (performance.now() - t) / 20;
                    };
                    done({load: performance.getEntriesByType('navigation')[0].loadEventEnd,
                          first: v.brtfView.firstDraw ?? null, view: v.outerHTML.length,
                          frame: time(false), turning: time(true)});
                } else if (performance.now() - t0 > 20000) { done(null); } else { setTimeout(poll, 20); }
            })();"""
        print(f"{'file':<50} {'MB':>6} {'view MB':>8} {'load ms':>8} {'3D ms':>7} {'frame ms':>9} {'turning ms':>11}")
        for path in paths:
            url = "file://" + os.path.abspath(path)
            runs = []
            for _ in range(3):
                call("POST", at("/url"), {"url": "about:blank"})
                call("POST", at("/url"), {"url": url})
                runs.append(call("POST", at("/execute/async"), {"script": wait, "args": []}))
            if any(r is None for r in runs):
                print(f"{path}: the 3D view did not draw within 20 s")
                continue
            size = os.path.getsize(path) / 1e6
            load = statistics.median(r["load"] for r in runs)
            first = statistics.median(r["first"] for r in runs)
            frame = statistics.median(r["frame"] for r in runs)
            turning = statistics.median(r["turning"] for r in runs)
            print(f"{path:<50} {size:6.2f} {runs[0]['view'] / 1e6:8.2f} {load:8.0f} {first:7.0f} {frame:9.1f} {turning:11.1f}")
        call("DELETE", at(""))
    finally:
        driver.kill()


if __name__ == "__main__":
    main(sys.argv[1:])
