#!/usr/bin/python3
"""gravscale's streaming replay against the paper's batch method in NumPy
(tools/paper_numpy.py) on the same stream of noisy simulated jumps, in one run.

    /usr/bin/python3 tools/bench_paper.py [--frames 36000] [--repeat 5] [--build build] [--pure]

The stream is bench_replay's (build/bench_replay N --keep FILE: a COCO-17 person
standing and jumping every 3 s at 30 fps, pixels to 2 decimals with 1.5 px of
uniform noise; 36 000 frames = 20 min, 400 jumps). Each repeat runs, one after
the other, `gravscale replay --keypoints FILE` and `paper_numpy.py FILE` as
processes (stdout to /dev/null), and times the NumPy method in this process too
(reading the CSV and the method, without the interpreter's start and the
imports), next to bench_replay's own in-process figure for gravscale on the same
file (`gravscale` links the core and the I/O only and starts in about 1 ms: the
vision libraries are in gravscale-vision.so, which only `video` and `cam` load). Reported: the best and the median of the repeats (wall s, frames/s,
CPU s), the ratios, and both results (jumps found, median height). --pure also
runs the pure-Python paper_baseline.py once. Load: the 1-min load average
before and after. Needs numpy (Debian's python3-numpy).
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import paper_numpy  # noqa: E402

TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load1():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def timed(cmd):
    """wall s, CPU s (this child), stdout"""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, check=False)
    wall = time.monotonic() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit("bench_paper: %s failed: %s" % (" ".join(cmd), p.stderr.decode(errors="replace")))
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime), p.stdout.decode()


def summary(out):
    """(jumps accepted, final height) from JSON Lines"""
    evs = [json.loads(line) for line in out.splitlines() if line.strip()]
    acc = sum(1 for e in evs if e.get("event") == "jump" and e.get("accepted"))
    s = [e for e in evs if e.get("event") == "summary"]
    return acc, (s[-1].get("height_m") if s else None)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=36000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--build", default=os.path.join(TOP, "build"))
    ap.add_argument("--pure", action="store_true", help="also the pure-Python paper_baseline.py, once")
    a = ap.parse_args()
    prog = os.path.join(a.build, "gravscale")
    with tempfile.TemporaryDirectory() as tmp:
        csv = os.path.join(tmp, "stream.csv")
        br = subprocess.run([os.path.join(a.build, "bench_replay"), str(a.frames), "--keep", csv],
                            stdout=subprocess.PIPE, check=True, text=True).stdout
        # its in-process whole replay (reader, core, emitter, writer; best of 3): no process start
        inproc_fps = float(next(line.split()[2] for line in br.splitlines() if line.startswith("whole replay:")))
        size_mb = os.path.getsize(csv) / 1e6
        l0 = load1()
        gs, npp, npi = [], [], []
        for _ in range(a.repeat):
            gs.append(timed([prog, "replay", "--keypoints", csv]))
            npp.append(timed([sys.executable, os.path.join(TOP, "tools", "paper_numpy.py"), csv]))
            c0, t0 = time.process_time(), time.monotonic()
            jumps, _ = paper_numpy.analyse(*paper_numpy.read_csv(csv))
            npi.append((time.monotonic() - t0, time.process_time() - c0, None))
        pure = timed([sys.executable, os.path.join(TOP, "tools", "paper_baseline.py"), csv]) if a.pure else None
        l1 = load1()
    n = a.frames
    print("stream: %d COCO-17 frames (%.1f MB, %.0f s at 30 fps); %d repeats; load average %.2f before, %.2f after"
          % (n, size_mb, n / 30.0, a.repeat, l0, l1))
    print("%-38s %8s %8s %10s %8s | %s" % ("", "best s", "median s", "frames/s", "cpu s", "accepted jumps, height m"))
    rows = [("gravscale replay (process)", gs, summary(gs[0][2])),
            ("gravscale, in process (bench_replay)", [(n / inproc_fps, float("nan"), None)], (None, None)),
            ("paper, NumPy (process)", npp, summary(npp[0][2])),
            ("paper, NumPy (in process: read + method)", npi,
             (sum(1 for j in jumps if j["accepted"]), None))]
    if pure:
        rows.append(("paper, pure Python (process, once)", [pure], summary(pure[2])))
    for name, runs, res in rows:
        w = sorted(r[0] for r in runs)
        print("%-38s %8.3f %8.3f %10.0f %8.3f | %s, %s" % (name, w[0], statistics.median(w), n / w[0],
                                                            min(r[1] for r in runs), res[0], res[1]))
    best = lambda runs: min(r[0] for r in runs)  # noqa: E731
    print("gravscale faster than the NumPy method: x%.1f (processes, best of each), x%.1f (both in process)"
          % (best(npp) / best(gs), best(npi) * inproc_fps / n))
    return 0


if __name__ == "__main__":
    sys.exit(main())
