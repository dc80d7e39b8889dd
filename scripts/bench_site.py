"""Issue 40: time to the first simulated frame of each kit page, and the pages' weight.

    python scripts/bench_site.py rosie_1000 asimov --runs 3 [--site build/assets/sim]

Publishes the robots (without pictures) into a temporary site unless --site names one
already published, serves it with `python -m http.server` on 127.0.0.1, and opens each kit
page in headless Chromium (Debian's, through Playwright), a fresh browser context per run
(no HTTP cache). Reports per kit: the median over the runs of `simkitViewer.firstFrame`
(ms from navigation start to the first MuJoCo step drawn) and of `ready` (model compiled),
and the bytes the page fetched (its own HTML, the viewer and vendored libraries, the kit's
robot.json, MJCF and meshes). docs/performance.md records the figures.
"""

from __future__ import annotations

import argparse
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking"]


def _serve(folder: Path) -> tuple[subprocess.Popen, str]:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = subprocess.Popen(
        [sys.executable, "-m", "http.server", str(port), "-b", "127.0.0.1", "-d", str(folder)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    base = f"http://127.0.0.1:{port}/"
    for _ in range(100):
        try:
            urllib.request.urlopen(base + "index.json", timeout=1).read()
            return server, base
        except OSError:
            time.sleep(0.1)
    raise SystemExit("the static server did not start")


def _one_run(browser, url: str) -> tuple[float, float, int, int]:
    """(ms to ready, ms to the first frame, bytes fetched, of which the viewer's shared files)."""
    context = browser.new_context(viewport={"width": 1100, "height": 800})
    page = context.new_page()
    sizes: dict[str, int] = {}
    page.on("requestfinished", lambda r: sizes.__setitem__(r.url, r.sizes()["responseBodySize"]))
    page.goto(url)
    page.evaluate("window.simkitViewer.ready")
    ready = page.evaluate("performance.now()")
    page.wait_for_function("window.simkitViewer.firstFrame !== null", timeout=120_000)
    first = page.evaluate("window.simkitViewer.firstFrame")
    page.wait_for_load_state("networkidle")
    context.close()
    shared = sum(n for u, n in sizes.items() if "/viewer/" in u)
    return ready, first, sum(sizes.values()), shared


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("robots", nargs="+")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--site", type=Path, default=None, help="an already published site")
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    from simkit.publish import publish

    with tempfile.TemporaryDirectory() as tmp:
        site = args.site or Path(tmp) / "sim"
        index = publish(site, args.robots) if args.site is None else None
        if index is None:
            import json

            index = json.loads((site / "index.json").read_text())
        server, base = _serve(site)
        try:
            with sync_playwright() as pw:
                browser = pw.chromium.launch(executable_path=args.chromium, args=FLAGS)
                print("| kit | ready ms | first frame ms | page weight | of it the shared viewer |")
                print("|---|---|---|---|---|")
                for kit in index["kits"]:
                    if kit["name"] not in args.robots:
                        continue
                    runs = [_one_run(browser, base + kit["page"]) for _ in range(args.runs)]
                    ready = statistics.median(r[0] for r in runs)
                    first = statistics.median(r[1] for r in runs)
                    total, shared = runs[-1][2], runs[-1][3]
                    print(
                        f"| {kit['name']} | {ready:.0f} | {first:.0f} | "
                        f"{total / 1e6:.2f} MB | {shared / 1e6:.2f} MB |"
                    )
                browser.close()
        finally:
            server.terminate()


if __name__ == "__main__":
    main()
