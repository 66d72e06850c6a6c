#!/usr/bin/python3
"""The paper's method (tools/paper_baseline.py) as a NumPy batch program: the same
steps and the same JSON Lines, vectorised over the whole clip, as the fair batch
peer for speed comparisons (tools/bench_paper.py).

    /usr/bin/python3 tools/paper_numpy.py FILE.csv [--min-conf 0.5]

Needs numpy (Debian's python3-numpy, which tools/bootstrap.sh installs). The
maxima, the floor, the flight intervals, the stature and the outputs follow
paper_baseline.py step by step (tests/test_paper_numpy.py checks that both give
the same jumps); the fit solves the same centred normal equations with
numpy.linalg.solve instead of our own elimination, so values agree to rounding.
RANSAC is not provided (paper_baseline.py --ransac has it).
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import paper_baseline as pb  # noqa: E402  (constants, segment table and the output shape)


def read_csv(path):
    """(t, x, y, c) arrays sorted by time; a missing keypoint has NaN x, y and c = 0."""
    with open(path) as f:
        header = f.readline()
        if not header.split(",")[0].strip() == "t":
            raise ValueError("%s: expected a header starting with t" % path)
        try:
            a = np.loadtxt(f, delimiter=",", ndmin=2)
        except ValueError:  # empty fields (missing keypoints): the slower reader
            f.seek(0)
            a = np.genfromtxt(f, delimiter=",", skip_header=1, filling_values=np.nan, ndmin=2)
    n = 1 + 3 * pb.N_KP
    if a.shape[1] < n:
        a = np.hstack([a, np.full((a.shape[0], n - a.shape[1]), np.nan)])
    a = a[np.isfinite(a[:, 0])]
    a = a[np.argsort(a[:, 0], kind="stable")]
    t = a[:, 0]
    x, y, c = a[:, 1:n:3].copy(), a[:, 2:n:3].copy(), a[:, 3:n:3].copy()
    bad = ~(np.isfinite(x) & np.isfinite(y)) | ~np.isfinite(c) | ~(c > 0.0)
    x[bad] = np.nan
    y[bad] = np.nan
    c[bad] = 0.0
    return t, x, y, c


def mean_point(x, y, vis, idxs):
    """Per frame the mean of the visible points idxs, and whether there was one."""
    v = vis[:, idxs]
    n = v.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mx = np.where(v, x[:, idxs], 0.0).sum(axis=1) / n
        my = np.where(v, y[:, idxs], 0.0).sum(axis=1) / n
    return mx, my, n > 0


def com_clauser(x, y, c):
    """COM y per frame (NaN where less than MIN_MASS_FRAC of the mass is seen)."""
    vis = c > 0.0
    sy = np.zeros(len(x))
    m = np.zeros(len(x))
    for _name, frac, prox, dist, along in pb.CLAUSER_1969:
        px, py, ok = mean_point(x, y, vis, list(prox))
        if dist is not None:
            dx, dy, okd = mean_point(x, y, vis, list(dist))
            ok = ok & okd
            py = py + along * (dy - py)
        sy += np.where(ok, frac * py, 0.0)
        m += np.where(ok, frac, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(m >= pb.MIN_MASS_FRAC, sy / m, np.nan)


def stature_px(x, y, c):
    vis = c > 0.0
    ax, ay, ok = mean_point(x, y, vis, [pb.L_ANK, pb.R_ANK])
    ok &= vis[:, pb.NOSE]
    d = np.hypot(x[ok, pb.NOSE] - ax[ok], y[ok, pb.NOSE] - ay[ok])[:pb.STATURE_FRAMES]
    return pb.STATURE_FACTOR * float(np.median(d)) if len(d) else math.nan


def find_maxima(u, w=pb.MAX_WINDOW):
    """paper_baseline.find_maxima, vectorised: higher than the w before and the w after
    (a tie with the next sample skips it; three equal never count)."""
    n = len(u)
    if n == 0:
        return np.zeros(0, dtype=int)
    pad = np.concatenate([np.full(w, -np.inf), u, np.full(w + 2, -np.inf)])
    win = np.lib.stride_tricks.sliding_window_view(pad, w)
    left = win[0:n].max(axis=1)             # u[m-w .. m-1]
    right1 = win[w + 1:w + 1 + n].max(axis=1)  # u[m+1 .. m+w]
    right2 = np.lib.stride_tricks.sliding_window_view(pad, w - 1)[w + 2:w + 2 + n].max(axis=1)  # u[m+2 .. m+w]
    nxt = np.concatenate([u[1:], [np.nan]])
    nxt2 = np.concatenate([u[2:], [np.nan, np.nan]])
    tie = nxt == u
    ok = (u > left) & np.where(tie, u > right2, u > right1) & ~(tie & (nxt2 == u))
    return np.flatnonzero(ok)


def run_edge(below, m, step):
    """The first index from m in direction step (+1 / -1) where below is true; -1 / len if none."""
    n = len(below)
    span = 64
    while True:
        if step > 0:
            seg = below[m:min(n, m + span)]
            hit = np.flatnonzero(seg)
            if len(hit):
                return m + int(hit[0])
            if m + span >= n:
                return n
        else:
            lo = max(0, m - span + 1)
            hit = np.flatnonzero(below[lo:m + 1])
            if len(hit):
                return lo + int(hit[-1])
            if lo == 0:
                return -1
        span *= 4


def analyse(t, x, y, c, min_conf=pb.MIN_MEAN_CONF, g=pb.G_M_S2):
    size_px = stature_px(x, y, c)
    cy = com_clauser(x, y, c)
    have = np.isfinite(cy)
    ts, u, conf = t[have], -cy[have], c[have].mean(axis=1)
    jumps = []
    if len(u) == 0:
        return jumps, size_px
    floor = float(np.median(u[:pb.FLOOR_FRAMES]))
    seen = set()
    for m in find_maxima(u):
        rise = u[m] - floor
        if not rise > 0.0:
            continue
        below = u < floor + pb.RISE_FRAC * rise
        s, e = run_edge(below, m, -1) + 1, run_edge(below, m, +1) - 1
        if (s, e) in seen:
            continue
        seen.add((s, e))
        keep = np.arange(s, e + 1)[conf[s:e + 1] >= min_conf]
        j = {"event": "jump", "t_takeoff_s": float(ts[s]), "t_land_s": float(ts[e]),
             "flight_time_s": float(ts[e] - ts[s]), "t_apex_s": None, "a_px_s2": None,
             "q_m_per_px": None, "size_px": size_px, "height_m": None,
             "jump_height_m": None, "takeoff_velocity_m_s": None,
             "n_samples": int(len(keep)), "n_outliers": 0, "rms_px": None,
             "accepted": False, "reason": None}
        jumps.append(j)
        if len(keep) < 3:
            j["reason"] = "few_samples"
            continue
        kt, ky = ts[keep], -u[keep]
        t0 = kt.mean()
        d = kt - t0
        s_ = [np.sum(d ** k) for k in range(5)]
        A = np.array([[s_[0], s_[1], s_[2]], [s_[1], s_[2], s_[3]], [s_[2], s_[3], s_[4]]])
        b = np.array([np.sum(ky), np.sum(d * ky), np.sum(d * d * ky)])
        try:
            c0, c1, c2 = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            j["reason"] = "few_samples"
            continue
        a = 2.0 * c2
        res = c0 + c1 * d + c2 * d * d - ky
        j["rms_px"] = float(np.sqrt(np.mean(res * res)))
        j["a_px_s2"] = float(a)
        if abs(c2) > 0.0:
            j["t_apex_s"] = float(t0 - c1 / (2.0 * c2))
        pb.scale_jump(j, float(a), g, size_px)
    return jumps, size_px


def main(argv=None):
    ap = argparse.ArgumentParser(description="The paper's gravity-height method, in NumPy.")
    ap.add_argument("csv", help="COCO-17 keypoint CSV (t,x0,y0,c0,...)")
    ap.add_argument("--min-conf", type=float, default=pb.MIN_MEAN_CONF)
    ap.add_argument("--g", type=float, default=pb.G_M_S2)
    args = ap.parse_args(argv)
    try:
        jumps, _ = analyse(*read_csv(args.csv), min_conf=args.min_conf, g=args.g)
    except (OSError, ValueError) as e:
        sys.stderr.write("paper_numpy: %s\n" % e)
        return 1
    out = sys.stdout
    for ev in pb.events(jumps, "paper-numpy"):
        out.write(json.dumps(ev, allow_nan=False) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
