#!/usr/bin/python3
"""Overhead of the live viewer (issue #17 item 4): `pspslam run --realtime` on bonn_crowd_dev with
and without `--viewer` + a headless chromium showing the page, in interleaved pairs (the order
inside a pair alternates), fps and frames processed from stats.json; prints each run and the
medians. Usage: bench/viewer_overhead.py [BUILD_DIR] [--pairs N] [--dynamic MODE]
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path

# The server is local: no proxy.
opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))

root = Path(__file__).resolve().parent.parent
shared = Path(os.environ.get("PSPSLAM_SHARED", root.parent / "shared"))


def run_once(cli, sequence, mode, out, viewer, attach_browser=True):
    command = [str(cli), "run", "--sequence", str(sequence), "--config", str(root / "config/bonn.yaml"),
               "--dynamic", mode, "--realtime", "--quiet", "--out", str(out)]
    if viewer:
        command += ["--viewer", "127.0.0.1:0"]
    browser = None
    pages = 0
    log = open(out.parent / (out.name + ".log"), "w+")
    process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
    try:
        if viewer:
            # The page opens as soon as the address is printed, before the first frame.
            url = None
            while url is None and process.poll() is None:
                log.seek(0)
                match = re.search(r"http://127\.0\.0\.1:\d+/", log.read())
                url = match.group(0) if match else None
                time.sleep(0.02)
            profile = tempfile.mkdtemp(prefix="viewer_overhead_chromium_")
            browser = None if not attach_browser else subprocess.Popen(
                ["chromium", "--headless", "--no-sandbox", "--no-proxy-server",
                 "--enable-unsafe-swiftshader", "--remote-debugging-port=0",
                 "--window-size=1400,900", f"--user-data-dir={profile}", url],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            # Proof that a page is attached: the server counts its open event streams.
            pages = 0
            while process.poll() is None:
                try:
                    state = json.loads(opener.open(url + "api/live/state", timeout=5).read())
                    pages = max(pages, state["state"]["pages"])
                except (OSError, ValueError):
                    pass
                time.sleep(0.5)
            if pages == 0 and attach_browser:
                raise SystemExit("no page attached to the viewer during the run")
        process.wait(timeout=600)
    finally:
        if browser:
            browser.terminate()
            browser.wait()
        if viewer:
            shutil.rmtree(profile, ignore_errors=True)
    if process.returncode != 0:
        log.seek(0)
        raise SystemExit(f"run failed ({process.returncode}):\n{log.read()}")
    stats = json.loads((out / "stats.json").read_text())
    return stats["fps"], stats["frames"], stats.get("realtime_dropped_frames", 0), pages if viewer else 0


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("build", nargs="?", default=str(root / "build"))
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--dynamic", default="full")
    parser.add_argument("--no-browser", action="store_true",
                        help="the viewer without a page attached (the server's own cost)")
    args = parser.parse_args()
    cli = Path(args.build) / "apps/pspslam"
    sequence = shared / "data/bonn_crowd_dev"
    work = Path(tempfile.mkdtemp(prefix="viewer_overhead_"))
    print(f"# {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC, load {os.getloadavg()}")
    results = {False: [], True: []}
    for pair in range(args.pairs):
        order = [False, True] if pair % 2 == 0 else [True, False]
        for viewer in order:
            out = work / f"pair{pair}_{'viewer' if viewer else 'plain'}"
            fps, frames, dropped, pages = run_once(cli, sequence, args.dynamic, out, viewer,
                                                   not args.no_browser)
            results[viewer].append((fps, frames))
            print(f"pair {pair} {('viewer+chromium' if not args.no_browser else 'viewer only    ') if viewer else 'plain          '}: "
                  f"{fps:.2f} fps, {frames} frames processed, {dropped} dropped by the feed, "
                  f"{pages} page(s) attached, "
                  f"load {os.getloadavg()[0]:.2f}", flush=True)
    plain = statistics.median(f for f, _ in results[False])
    viewed = statistics.median(f for f, _ in results[True])
    plain_frames = statistics.median(n for _, n in results[False])
    viewed_frames = statistics.median(n for _, n in results[True])
    print(f"median fps: plain {plain:.2f}, viewer {viewed:.2f} ({100 * (viewed / plain - 1):+.1f} %)")
    print(f"median frames processed: plain {plain_frames}, viewer {viewed_frames} "
          f"({100 * (viewed_frames / plain_frames - 1):+.1f} %)")
    print(f"# end {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC, load {os.getloadavg()}")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
