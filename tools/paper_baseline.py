#!/usr/bin/env python3
"""The paper's method (Bieler, Guenel, Fua, Rhodin, sections 4.1-4.4) as a baseline.

    python3 tools/paper_baseline.py FILE.csv [--ransac] [--min-conf 0.5]

Reads a COCO-17 keypoint CSV (header t,x0,y0,c0,...,x16,y16,c16; pixels, y down;
missing keypoint = empty x,y and c = 0; dropped frames absent) and prints JSON
Lines in the same shape as `gravscale replay` (start, jump, height, summary), so
tools/evaluate.py treats both alike.  Python 3 standard library only.

Steps, each as the paper states it (our additions are marked OURS):
 4.1 COM = mass-weighted sum of segment centres (Clauser et al. 1969 table below).
 4.2 maxima = samples higher than every other sample within +-10 frames (OURS: a
     tie of two neighbours counts once);
     floor = median COM height over the first 100 frames; the flight interval of
     a maximum = the contiguous samples around it at least 15 % of the peak's
     rise above the floor.
 4.3 least-squares degree-2 polynomial in time (s) on the interval, frames with
     low keypoint confidence excluded; a = 2 x quadratic coefficient; q = 9.81 / a.
     --ransac: RANSAC on top of the same fit.
 4.4 stature_px = 1.17 x nose-to-ankle pixel distance, median over the first
     10 frames; height = stature_px x q; per trial = median over its jumps.
"""
import argparse
import csv
import json
import math
import random
import statistics
import sys

G_M_S2 = 9.81
N_KP = 17
MAX_WINDOW = 10          # paper 4.2: a maximum is the highest within +-10 frames
FLOOR_FRAMES = 100       # paper 4.2: floor = median over the first 100 frames
RISE_FRAC = 0.15         # paper 4.2: keep samples >= 15 % of the rise above the floor
STATURE_FACTOR = 1.17    # paper 4.4: pixel height / nose-to-ankle distance
STATURE_FRAMES = 10      # "measured at the first frames": median over the first 10
# Paper 4.3 drops AlphaPose detections with a low score; our CSV confidences are
# 0..1, so a frame whose mean keypoint confidence (missing = 0) is below this is
# left out of the fit (it still takes part in the detection of maxima).
MIN_MEAN_CONF = 0.5
# OURS: a COM needs at least this share of the body mass visible, else the frame has no COM.
MIN_MASS_FRAC = 0.5

# COCO-17 indices
NOSE, L_EYE, R_EYE, L_EAR, R_EAR = 0, 1, 2, 3, 4
L_SHO, R_SHO, L_ELB, R_ELB, L_WRI, R_WRI = 5, 6, 7, 8, 9, 10
L_HIP, R_HIP, L_KNEE, R_KNEE, L_ANK, R_ANK = 11, 12, 13, 14, 15, 16

# Segment mass fractions and centre-of-mass positions (fraction of the segment
# length from its proximal end): Clauser, C.E., McConville, J.T., Young, J.W.
# (1969) "Weight, volume and center of mass of segments of the human body",
# AMRL-TR-69-70, Wright-Patterson AFB (mean of 13 male cadavers), as commonly
# tabulated in biomechanics texts.  Mass: head 7.3 %, trunk 50.7 %, upper arm
# 2.6 %, forearm 1.6 %, hand 0.7 %, thigh 10.3 %, calf 4.3 %, foot 1.5 % (sums to
# 100 % with two of each limb segment).  Mapping onto COCO-17 (OURS, COCO has no
# vertex, neck, fingertip or toe points): head centre = mean of the visible face
# points (nose, eyes, ears); trunk from mid-shoulders to mid-hips at 0.38;
# hand and foot centres placed at the wrist and the ankle.
# (name, mass fraction, proximal keypoints, distal keypoints, fraction along)
CLAUSER_1969 = (
    ("head", 0.073, (NOSE, L_EYE, R_EYE, L_EAR, R_EAR), None, 0.0),
    ("trunk", 0.507, (L_SHO, R_SHO), (L_HIP, R_HIP), 0.380),
    ("l_upper_arm", 0.026, (L_SHO,), (L_ELB,), 0.513),
    ("r_upper_arm", 0.026, (R_SHO,), (R_ELB,), 0.513),
    ("l_forearm", 0.016, (L_ELB,), (L_WRI,), 0.390),
    ("r_forearm", 0.016, (R_ELB,), (R_WRI,), 0.390),
    ("l_hand", 0.007, (L_WRI,), None, 0.0),
    ("r_hand", 0.007, (R_WRI,), None, 0.0),
    ("l_thigh", 0.103, (L_HIP,), (L_KNEE,), 0.372),
    ("r_thigh", 0.103, (R_HIP,), (R_KNEE,), 0.372),
    ("l_calf", 0.043, (L_KNEE,), (L_ANK,), 0.371),
    ("r_calf", 0.043, (R_KNEE,), (R_ANK,), 0.371),
    ("l_foot", 0.015, (L_ANK,), None, 0.0),
    ("r_foot", 0.015, (R_ANK,), None, 0.0),
)


def _num(s):
    s = s.strip()
    if s == "":
        return math.nan
    try:
        return float(s)
    except ValueError:
        return math.nan


def read_keypoints_csv(path):
    """Return [(t_s, [(x, y, c)] * 17)], sorted by time; missing keypoints have NaN x, y and c = 0."""
    frames = []
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = next(rows, None)
        if header is None or header[0].strip() != "t":
            raise ValueError("%s: expected a header starting with t" % path)
        for row in rows:
            if not row or row[0].strip() == "":
                continue
            t = _num(row[0])
            if not math.isfinite(t):
                continue
            kps = []
            for j in range(N_KP):
                base = 1 + 3 * j
                x = _num(row[base]) if base < len(row) else math.nan
                y = _num(row[base + 1]) if base + 1 < len(row) else math.nan
                c = _num(row[base + 2]) if base + 2 < len(row) else 0.0
                if not (math.isfinite(x) and math.isfinite(y)) or not math.isfinite(c) or c <= 0.0:
                    x, y, c = math.nan, math.nan, 0.0
                kps.append((x, y, c))
            frames.append((t, kps))
    frames.sort(key=lambda fr: fr[0])
    return frames


def _mean_point(kps, idxs):
    pts = [kps[i] for i in idxs if kps[i][2] > 0.0]
    if not pts:
        return None
    return (sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts))


def com_clauser(kps):
    """COM (x, y) in px of one frame, or None when less than MIN_MASS_FRAC of the mass is visible."""
    sx = sy = m = 0.0
    for _name, frac, prox, dist, along in CLAUSER_1969:
        p = _mean_point(kps, prox)
        if p is None:
            continue
        if dist is not None:
            d = _mean_point(kps, dist)
            if d is None:
                continue
            p = (p[0] + along * (d[0] - p[0]), p[1] + along * (d[1] - p[1]))
        sx += frac * p[0]
        sy += frac * p[1]
        m += frac
    if m < MIN_MASS_FRAC:
        return None
    return (sx / m, sy / m)


def mean_confidence(kps):
    return sum(k[2] for k in kps) / len(kps)


def nose_ankle_px(kps):
    """Distance from the nose to the mid-point of the ankles (one ankle if only one is seen), None if unknown."""
    if kps[NOSE][2] <= 0.0:
        return None
    a = _mean_point(kps, (L_ANK, R_ANK))
    if a is None:
        return None
    return math.hypot(kps[NOSE][0] - a[0], kps[NOSE][1] - a[1])


def stature_px(frames, n=STATURE_FRAMES, factor=STATURE_FACTOR):
    """1.17 x nose-to-ankle distance, median over the first n frames where it can be measured."""
    vals = []
    for _t, kps in frames:
        d = nose_ankle_px(kps)
        if d is not None:
            vals.append(d)
            if len(vals) == n:
                break
    if not vals:
        return math.nan
    return factor * statistics.median(vals)


def find_maxima(u, window=MAX_WINDOW):
    """Indices m with u[m] > u[t] for every other t in [m-window, m+window] (clipped at the ends).
    OURS: two equal highest samples side by side (an apex exactly between two frames)
    count once, at the first; three or more equal samples (a flat track) never count."""
    out = []
    n = len(u)
    for m in range(n):
        lo, hi = max(0, m - window), min(n, m + window + 1)
        tie = m + 1 if m + 1 < n and u[m + 1] == u[m] else -1
        if all(u[m] > u[t] for t in range(lo, hi) if t != m and t != tie):
            if tie >= 0 and m + 2 < n and u[m + 2] == u[m]:
                continue
            out.append(m)
    return out


def floor_level(u, n=FLOOR_FRAMES):
    """Median COM height over the first n samples (the person is expected to start standing)."""
    return statistics.median(u[:n]) if u else math.nan


def flight_interval(u, m, floor, frac=RISE_FRAC):
    """(s, e) inclusive: the contiguous samples around maximum m at least frac x (u[m] - floor) above
    the floor; None when the peak does not rise above the floor."""
    rise = u[m] - floor
    if not rise > 0.0:
        return None
    thr = floor + frac * rise
    s = m
    while s - 1 >= 0 and u[s - 1] >= thr:
        s -= 1
    e = m
    while e + 1 < len(u) and u[e + 1] >= thr:
        e += 1
    return (s, e)


def _solve3(a, b):
    """Gaussian elimination with partial pivoting on a 3x3 system; None when singular."""
    m = [list(a[i]) + [b[i]] for i in range(3)]
    for col in range(3):
        piv = max(range(col, 3), key=lambda r: abs(m[r][col]))
        if abs(m[piv][col]) < 1e-300:
            return None
        m[col], m[piv] = m[piv], m[col]
        for r in range(col + 1, 3):
            f = m[r][col] / m[col][col]
            for k in range(col, 4):
                m[r][k] -= f * m[col][k]
    x = [0.0, 0.0, 0.0]
    for r in (2, 1, 0):
        x[r] = (m[r][3] - sum(m[r][k] * x[k] for k in range(r + 1, 3))) / m[r][r]
    return x


def polyfit2(ts, ys, t0=None):
    """Least-squares y = c0 + c1 (t - t0) + c2 (t - t0)^2; returns (c0, c1, c2, t0) or None.
    Time is centred on t0 (default: mean time) so the normal equations stay well conditioned."""
    n = len(ts)
    if n < 3:
        return None
    if t0 is None:
        t0 = sum(ts) / n
    s = [0.0] * 5
    r = [0.0] * 3
    for t, y in zip(ts, ys):
        d = t - t0
        p = 1.0
        for k in range(5):
            s[k] += p
            if k < 3:
                r[k] += p * y
            p *= d
    c = _solve3([[s[0], s[1], s[2]], [s[1], s[2], s[3]], [s[2], s[3], s[4]]], r)
    if c is None:
        return None
    return (c[0], c[1], c[2], t0)


def _eval2(fit, t):
    d = t - fit[3]
    return fit[0] + fit[1] * d + fit[2] * d * d


def ransac_fit2(ts, ys, thr_px, iters=200, seed=0):
    """RANSAC on top of the degree-2 fit: best 3-point consensus, then least squares on its inliers.
    Returns (fit, inlier mask) or (None, None)."""
    n = len(ts)
    if n < 3:
        return None, None
    rng = random.Random(seed)
    best = None
    for _ in range(iters):
        idx = rng.sample(range(n), 3)
        f = polyfit2([ts[i] for i in idx], [ys[i] for i in idx])
        if f is None:
            continue
        mask = [abs(_eval2(f, ts[i]) - ys[i]) <= thr_px for i in range(n)]
        cnt = sum(mask)
        if best is None or cnt > best[0]:
            best = (cnt, mask)
    if best is None or best[0] < 3:
        return None, None
    mask = best[1]
    fit = polyfit2([ts[i] for i in range(n) if mask[i]], [ys[i] for i in range(n) if mask[i]])
    return fit, mask


def com_track(frames):
    """[(t_s, y_px, mean_conf)] for frames with a COM (y down)."""
    out = []
    for t, kps in frames:
        c = com_clauser(kps)
        if c is not None:
            out.append((t, c[1], mean_confidence(kps)))
    return out


def analyse(frames, use_ransac=False, min_conf=MIN_MEAN_CONF, g=G_M_S2, min_rise=0.0):
    """Run the paper's steps on decoded frames; returns (jumps, stature_px).
    min_rise (OURS, 0 = the paper): a maximum must rise at least this fraction of
    stature_px above the floor, a stand-in for the paper's hand-picked snippets."""
    size_px = stature_px(frames)
    track = com_track(frames)
    ts = [p[0] for p in track]
    u = [-p[1] for p in track]           # upward COM position (image y points down)
    conf = [p[2] for p in track]
    jumps = []
    if not track:
        return jumps, size_px
    floor = floor_level(u)
    seen = set()
    rise_px = min_rise * size_px if math.isfinite(size_px) else 0.0
    for m in find_maxima(u):
        if min_rise > 0.0 and not u[m] - floor >= rise_px:
            continue
        iv = flight_interval(u, m, floor)
        if iv is None or iv in seen:
            continue
        seen.add(iv)
        s, e = iv
        keep = [i for i in range(s, e + 1) if conf[i] >= min_conf]
        j = {"event": "jump", "t_takeoff_s": ts[s], "t_land_s": ts[e],
             "flight_time_s": ts[e] - ts[s], "t_apex_s": None, "a_px_s2": None,
             "q_m_per_px": None, "size_px": size_px, "height_m": None,
             "jump_height_m": None, "takeoff_velocity_m_s": None,
             "n_samples": len(keep), "n_outliers": 0, "rms_px": None,
             "accepted": False, "reason": None, "i_peak": m}
        kt = [ts[i] for i in keep]
        ky = [-u[i] for i in keep]       # fit in image y (down) so a > 0 means falling
        fit, mask = None, None
        if use_ransac:
            thr = max(2.0, 0.01 * size_px) if math.isfinite(size_px) else 2.0
            fit, mask = ransac_fit2(kt, ky, thr)
        else:
            fit = polyfit2(kt, ky)
            mask = [True] * len(kt)
        if fit is None:
            j["reason"] = "few_samples"
            jumps.append(j)
            continue
        a = 2.0 * fit[2]
        res = [_eval2(fit, kt[i]) - ky[i] for i in range(len(kt)) if mask[i]]
        j["n_outliers"] = len(kt) - sum(mask)
        j["rms_px"] = math.sqrt(sum(r * r for r in res) / len(res))
        j["a_px_s2"] = a
        if abs(fit[2]) > 0.0:
            j["t_apex_s"] = fit[3] - fit[1] / (2.0 * fit[2])
        scale_jump(j, a, g, size_px)
        jumps.append(j)
    return jumps, size_px


def scale_jump(j, a, g, size_px):
    """The jump's q, height and (OURS) ballistic figures from its acceleration a (px/s^2)
    and accept flag or reason (j is updated)."""
    # OURS: a parabola opening the wrong way has no gravity in it; q would be negative.
    if not a > 0.0:
        j["reason"] = "implausible_acceleration"
        return
    q = g / a
    j["q_m_per_px"] = q
    j["height_m"] = size_px * q if math.isfinite(size_px) else None
    # OURS, not in the paper: ballistic jump height and take-off speed from the interval's duration.
    tf = j["flight_time_s"]
    j["jump_height_m"] = g * tf * tf / 8.0
    j["takeoff_velocity_m_s"] = g * tf / 2.0
    if j["height_m"] is None:
        j["reason"] = "no_size"
    else:
        j["accepted"] = True


def _clean(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def events(jumps, method_name):
    """The gravscale-shaped JSON Lines events (as dicts) for a list of jumps."""
    out = [{"event": "start", "version": "paper-baseline", "config": method_name,
            "fps_source": None, "fps_origin": "timestamps", "layout": "coco17"}]
    heights = []
    n_rej = 0
    for idx, j in enumerate(jumps):
        ev = {"event": "jump", "track": 0, "index": idx}
        ev.update({k: _clean(v) for k, v in j.items() if k != "i_peak"})
        ev["warnings"] = []
        out.append(ev)
        if j["accepted"]:
            heights.append(j["height_m"])
            out.append({"event": "height", "track": 0, "height_m": statistics.median(heights),
                        "ci95_m": None, "n_jumps": len(heights)})
        else:
            n_rej += 1
    out.append({"event": "summary", "track": 0,
                "height_m": statistics.median(heights) if heights else None,
                "ci95_m": None, "n_jumps": len(heights), "n_rejected": n_rej})
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description="The paper's gravity-height method as a baseline.")
    ap.add_argument("csv", help="COCO-17 keypoint CSV (t,x0,y0,c0,...)")
    ap.add_argument("--ransac", action="store_true", help="RANSAC on top of the parabola fit (paper 4.3)")
    ap.add_argument("--min-conf", type=float, default=MIN_MEAN_CONF,
                    help="drop frames from the fit whose mean keypoint confidence is below this")
    ap.add_argument("--g", type=float, default=G_M_S2, help="gravity, m/s^2")
    ap.add_argument("--min-rise", type=float, default=0.0,
                    help="OURS, not the paper (0): ignore maxima rising less than this fraction "
                         "of the stature in px above the floor (e.g. 0.05)")
    args = ap.parse_args(argv)
    frames = read_keypoints_csv(args.csv)
    jumps, _ = analyse(frames, use_ransac=args.ransac, min_conf=args.min_conf, g=args.g,
                       min_rise=args.min_rise)
    name = ("paper-ransac" if args.ransac else "paper") + \
        ("" if args.min_rise <= 0.0 else " min-rise %g" % args.min_rise)
    for ev in events(jumps, name):
        sys.stdout.write(json.dumps(ev, allow_nan=False) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
