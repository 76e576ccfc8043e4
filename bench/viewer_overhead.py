#!/usr/bin/python3
"""Overhead of the live viewer (issue #17 item 4): `pspslam run --realtime` on bonn_crowd_dev with
and without `--viewer` + a headless chromium showing the page, in interleaved pairs (the order
inside a pair alternates). Per run: fps and frames processed (stats.json) and the run's own CPU
time per processed frame (user + system of the pspslam process alone, from wait4: on a shared,
loaded machine fps mostly measures the other processes, CPU time much less). Prints each run and
the medians. Usage: bench/viewer_overhead.py [BUILD_DIR] [--pairs N] [--dynamic MODE]
[--no-browser] [--interval MS]
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

root = Path(__file__).resolve().parent.parent
shared = Path(os.environ.get("PSPSLAM_SHARED", root.parent / "shared"))
# The server is local: no proxy.
opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))


class Run:
    """One pspslam process; reaped with wait4 so its own CPU time is known."""

    def __init__(self, command, log):
        self.process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        self.status = None
        self.usage = None

    def finished(self, block=False):
        if self.status is None:
            pid, status, usage = os.wait4(self.process.pid, 0 if block else os.WNOHANG)
            if pid:
                self.status, self.usage = os.waitstatus_to_exitcode(status), usage
        return self.status is not None


def run_once(cli, sequence, mode, out, viewer, attach_browser=True, interval_ms=None):
    command = [str(cli), "run", "--sequence", str(sequence), "--config",
               str(root / "config/bonn.yaml"), "--dynamic", mode, "--realtime", "--quiet",
               "--out", str(out)]
    if viewer:
        command += ["--viewer", "127.0.0.1:0"]
        if interval_ms is not None:
            command += ["--viewer-interval", str(interval_ms)]
    browser = None
    profile = None
    pages = 0
    log = open(out.parent / (out.name + ".log"), "w+")
    run = Run(command, log)
    try:
        if viewer:
            # The page opens as soon as the address is printed, before the first frame.
            url = None
            while url is None and not run.finished():
                log.seek(0)
                match = re.search(r"http://127\.0\.0\.1:\d+/", log.read())
                url = match.group(0) if match else None
                time.sleep(0.02)
            if attach_browser:
                profile = tempfile.mkdtemp(prefix="viewer_overhead_chromium_")
                browser = subprocess.Popen(
                    ["chromium", "--headless", "--no-sandbox", "--no-proxy-server",
                     "--enable-unsafe-swiftshader", "--remote-debugging-port=0",
                     "--window-size=1400,900", f"--user-data-dir={profile}", url],
                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            # Proof that a page is attached: the server counts its open event streams.
            while not run.finished():
                try:
                    state = json.loads(opener.open(url + "api/live/state", timeout=5).read())
                    pages = max(pages, state["state"]["pages"])
                except (OSError, ValueError, KeyError):
                    pass
                time.sleep(0.5)
            if pages == 0 and attach_browser:
                raise SystemExit("no page attached to the viewer during the run")
        run.finished(block=True)
    finally:
        if browser:
            browser.terminate()
            browser.wait()
        if profile:
            shutil.rmtree(profile, ignore_errors=True)
    if run.status != 0:
        log.seek(0)
        raise SystemExit(f"run failed ({run.status}):\n{log.read()}")
    stats = json.loads((out / "stats.json").read_text())
    cpu_ms = 1000.0 * (run.usage.ru_utime + run.usage.ru_stime) / stats["frames"]
    return {"fps": stats["fps"], "frames": stats["frames"],
            "dropped": stats.get("realtime_dropped_frames", 0), "cpu_ms": cpu_ms, "pages": pages}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("build", nargs="?", default=str(root / "build"))
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--dynamic", default="full")
    parser.add_argument("--no-browser", action="store_true",
                        help="the viewer without a page attached (the server's own cost)")
    parser.add_argument("--interval", type=int, default=None,
                        help="--viewer-interval MS of the viewed runs (default: the run's own)")
    args = parser.parse_args()
    cli = Path(args.build) / "apps/pspslam"
    sequence = shared / "data/bonn_crowd_dev"
    work = Path(tempfile.mkdtemp(prefix="viewer_overhead_"))
    with_name = "viewer only" if args.no_browser else "viewer+chromium"
    print(f"# {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC, load {os.getloadavg()}")
    results = {False: [], True: []}
    for pair in range(args.pairs):
        for viewer in ([False, True] if pair % 2 == 0 else [True, False]):
            out = work / f"pair{pair}_{'viewer' if viewer else 'plain'}"
            r = run_once(cli, sequence, args.dynamic, out, viewer, not args.no_browser,
                         args.interval)
            results[viewer].append(r)
            print(f"pair {pair} {with_name if viewer else 'plain':15s}: {r['fps']:.2f} fps, "
                  f"{r['frames']} frames processed, {r['dropped']} dropped by the feed, "
                  f"{r['cpu_ms']:.1f} CPU ms/frame, {r['pages']} page(s) attached, "
                  f"load {os.getloadavg()[0]:.2f}", flush=True)
    for key, what in (("fps", "fps"), ("frames", "frames processed"),
                      ("cpu_ms", "CPU ms per processed frame")):
        plain = statistics.median(r[key] for r in results[False])
        viewed = statistics.median(r[key] for r in results[True])
        print(f"median {what}: plain {plain:.2f}, {with_name} {viewed:.2f} "
              f"({100 * (viewed / plain - 1):+.1f} %)")
    print(f"# end {time.strftime('%Y-%m-%d %H:%M:%S', time.gmtime())} UTC, load {os.getloadavg()}")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
