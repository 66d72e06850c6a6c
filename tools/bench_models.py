#!/usr/bin/env python3
"""Milliseconds per frame of the converted BlazePose models in OpenCV 4.6's DNN module.

    tools/bench_models.py [--threads 1,2] [--runs 30] [--warmup 5] [MODEL ...]

MODEL is a file name in models/ without .onnx (default: the detector, the three
landmark models and their _noseg variants). Runs in the venv .venv/ (Debian's
cv2, the same library as the C++ build). One frame = setInput + forward of every
graph output on a fixed random input; the median and the fastest of --runs
frames are printed (wall clock), with the median CPU time of the process per
frame (all its threads) and the machine's load average: other processes on the
same cores stretch the wall clock, while the one-thread CPU time stays close to
the cost of the network itself.
"""
import argparse
import os
import sys
import time

TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(TOP, ".venv")
if os.path.realpath(sys.prefix) != os.path.realpath(VENV):
    py = os.path.join(VENV, "bin", "python")
    if not os.access(py, os.X_OK):
        sys.exit("bench_models: no venv at %s; run tools/fetch_models.sh" % VENV)
    os.execv(py, [py, os.path.abspath(__file__)] + sys.argv[1:])

import cv2  # noqa: E402
import numpy as np  # noqa: E402

DEFAULT = ["pose_detection", "pose_landmark_lite", "pose_landmark_full", "pose_landmark_heavy",
           "pose_landmark_lite_noseg", "pose_landmark_full_noseg", "pose_landmark_heavy_noseg"]


def bench(name, threads, runs, warmup):
    f = os.path.join(TOP, "models", name + ".onnx")
    if not os.path.exists(f):
        sys.exit("bench_models: %s missing; run tools/fetch_models.sh" % f)
    cv2.setNumThreads(threads)
    net = cv2.dnn.readNetFromONNX(f)
    side = 224 if "detection" in name else 256
    x = np.random.default_rng(0).uniform(0, 1, (1, 3, side, side)).astype(np.float32)
    outs = net.getUnconnectedOutLayersNames()
    wall, cpu = [], []
    for i in range(warmup + runs):
        t0, c0 = time.perf_counter(), time.process_time()
        net.setInput(x)
        net.forward(outs)
        if i >= warmup:
            wall.append((time.perf_counter() - t0) * 1e3)
            cpu.append((time.process_time() - c0) * 1e3)
    return float(np.median(wall)), float(min(wall)), float(np.median(cpu))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models", nargs="*", default=DEFAULT)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--warmup", type=int, default=5)
    a = ap.parse_args()
    print("OpenCV %s, %d cores, load average before: %s" % (
        cv2.__version__, os.cpu_count(), " ".join("%.2f" % v for v in os.getloadavg())))
    print("%-28s %7s %12s %10s %12s" % ("model", "threads", "median ms", "best ms", "CPU ms"))
    for th in [int(t) for t in a.threads.split(",")]:
        for m in a.models:
            med, best, cpu = bench(m, th, a.runs, a.warmup)
            print("%-28s %7d %12.1f %10.1f %12.1f" % (m, th, med, best, cpu))
    print("load average after: %s" % " ".join("%.2f" % v for v in os.getloadavg()))


if __name__ == "__main__":
    main()
