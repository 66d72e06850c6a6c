#!/usr/bin/env python3
"""Film a motion-capture recording with a virtual pinhole camera into a replay CSV.

    python3 tools/film_mocap.py TRIAL.trc --out OUT.csv [--grf TRIAL_grf.mot]
        [--stature 1.68] [--layout blazepose33|coco17] [--view front|side|side-left]
        [--distance 4] [--fps 30] [--phase RANDOM|0..1] [--noise none|low|medium|high]
        [--errors] [--resolution 1080p] [--hfov 60] [--camera-height 1.2] [--seed N]

Markers (TRC, metres, Y up) become BlazePose-33 or COCO-17 keypoints (joint
centres from the markers, the head from C7 and anthropometric ratios: the
recordings have no head markers), projected by a camera `--distance` m in front
of (or beside) the place of the jumps, sampled at `--fps` with a random phase
against the 100 Hz capture, with the simulator's keypoint noise. OUT.csv is
`gravscale replay` input; OUT.truth.json beside it holds the truth: the force
plates' flights (airborne = summed vertical force below 20 N, crossings
interpolated between samples), each with its flight time, g T^2/8, the true
scale at the COM's depth (q = depth / focal length), the COM's rise from the
markers, the frames a perfect frame-by-frame classifier would count airborne,
and for a rebound after a landing the ground-contact time and the reactive
strength index. docs/mocap.md says what the filming leaves out.
"""

import argparse
import json
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from gsim import detector, mocap  # noqa: E402
from gsim.camera import Camera, RESOLUTIONS  # noqa: E402

VIEWS = ("front", "side", "side-left")


def stature_from_setup(trc_path):
    """The stated stature in rescaling_setup.xml beside the recording, or None."""
    p = os.path.join(os.path.dirname(os.path.abspath(trc_path)), "rescaling_setup.xml")
    try:
        with open(p) as f:
            s = f.read()
    except OSError:
        return None
    a, b = s.find("<height>"), s.find("</height>")
    try:
        return float(s[a + 8:b]) if a >= 0 and b > a else None
    except ValueError:
        return None


def to_world(view, c):
    """Lab point (X forward, Y up, Z right) -> camera world (x right on screen, y away
    from the camera, z up), the jump spot c on the y = 0 line."""
    cx, cz = c

    def f(p):
        x, y, z = p[0] - cx, p[1], p[2] - cz
        if view == "front":       # the person faces the camera
            return (-z, -x, y)
        if view == "side":        # the right side toward the camera
            return (x, -z, y)
        return (-x, z, y)         # side-left
    return f


def depth(cam, P):
    d = (P[0] - cam.C[0], P[1] - cam.C[1], P[2] - cam.C[2])
    return d[0] * cam.za[0] + d[1] * cam.za[1] + d[2] * cam.za[2]


def film(trc, grf=None, stature_m=None, layout="blazepose33", view="front", distance_m=4.0, fps=30.0,
         phase=None, noise="medium", errors=False, resolution="1080p", hfov_deg=60.0, camera_height_m=1.2,
         seed=1):
    """-> (header, rows, truth): rows are [t, x0, y0, c0, ...] with None for a missing keypoint."""
    rng = random.Random(seed)
    times, m, rate = mocap.load_trc(trc)
    if stature_m is None:
        stature_m = stature_from_setup(trc)
    if stature_m is None:
        raise ValueError("%s: no stature given (--stature) and no rescaling_setup.xml beside it" % trc)
    phases = mocap.plate_phases(mocap.load_mot(grf)) if grf else []
    names = mocap.LAYOUTS[layout]

    kp_at = lambda t: (lambda mk: mocap.keypoints3d(mk, stature_m) if mk else None)(  # noqa: E731
        mocap.interp_markers(times, m, t))
    # the camera looks at the place of the jumps: the pelvis over the last flight (else the trial's middle)
    if phases and phases[-1][0] is not None:
        ts = [0.5 * (phases[-1][0] + phases[-1][1])]
    else:
        ts = [times[len(times) // 2]]
    spots = [kp_at(t) for t in ts]
    hips = [mocap._mid(k["l_hip"], k["r_hip"]) for k in spots if k]
    c = (sum(h[0] for h in hips) / len(hips), sum(h[2] for h in hips) / len(hips))
    world = to_world(view, c)
    w_px, h_px = RESOLUTIONS[resolution]
    cam = Camera(w_px, h_px, hfov_deg, distance_m, camera_height_m, 1.0)
    if phase is None:
        phase = rng.random()
    dt = 1.0 / fps
    t = times[0] + phase * dt
    frame_t = []
    while t <= times[-1]:
        frame_t.append(t)
        t += dt

    body_px = stature_m * cam.f_px / distance_m
    sig = detector.NOISE_K[noise] * body_px if noise != "none" else 0.0
    r_out, _, r_miss, r_drop = detector.RATES[noise if noise != "none" else "low"]
    if not errors:
        r_out = r_miss = r_drop = 0.0
    innov = math.sqrt(1.0 - detector.RHO ** 2)
    ar = [[0.0, 0.0] for _ in names]
    prev_px = [None] * len(names)
    rows, com_track = [], []
    for t in frame_t:
        kp = kp_at(t)
        for j in range(len(names)):
            for a in range(2):
                ar[j][a] = detector.RHO * ar[j][a] + innov * rng.gauss(0.0, sig) if sig > 0 else 0.0
        if kp is None or rng.random() < r_drop:
            prev_px = [None] * len(names)
            continue
        row = [t]
        cur_px = []
        for j, n in enumerate(names):
            P = kp.get(n)
            p = cam.project(world(P)) if P is not None else None
            cur_px.append(p)
            if p is None or rng.random() < r_miss:
                row += [None, None, 0.0]
                continue
            speed = math.hypot(p[0] - prev_px[j][0], p[1] - prev_px[j][1]) if prev_px[j] else 0.0
            sb = detector.BLUR * speed if sig > 0 else 0.0
            x = p[0] + ar[j][0] + (rng.gauss(0.0, sb) if sb > 0 else 0.0)
            y = p[1] + ar[j][1] + (rng.gauss(0.0, sb) if sb > 0 else 0.0)
            cf = rng.uniform(0.80, 0.99) / (1.0 + 0.02 * speed)
            if rng.random() < r_out:
                ang = rng.uniform(0.0, 2.0 * math.pi)
                mag = rng.uniform(0.05, 0.30) * body_px
                x, y = x + mag * math.cos(ang), y + mag * math.sin(ang)
                cf = rng.uniform(0.05, 0.9)
            if not (0.0 <= x < w_px and 0.0 <= y < h_px):
                row += [None, None, 0.0]
                continue
            row += [x, y, cf]
        prev_px = cur_px
        rows.append(row)
        com = mocap.com3d(kp)
        com_track.append((t, com))

    truth = {"trial": os.path.basename(trc), "stature_m": stature_m, "layout": layout, "view": view,
             "distance_m": distance_m, "fps": fps, "phase": phase, "noise": noise, "errors": errors,
             "sigma_px": sig, "body_px": body_px, "camera": cam.to_dict(), "flights": [], "falls": []}
    prev_land = None
    for (t_off, t_on) in phases:
        if t_off is None:
            truth["falls"].append({"t_land_s": t_on})
            prev_land = t_on
            continue
        T = t_on - t_off
        inside = [(tt, p) for tt, p in com_track if t_off <= tt <= t_on and p is not None]
        q = [depth(cam, world(p)) / cam.f_px for _, p in inside]
        com_at = lambda tq: (lambda mk: mocap.com3d(mocap.keypoints3d(mk, stature_m)) if mk else None)(  # noqa: E731
            mocap.interp_markers(times, m, tq))
        c0 = com_at(t_off)
        rise = None
        if c0 is not None:
            hs = [com_at(t_off + k * 0.005) for k in range(int(T / 0.005) + 1)]
            hs = [h[1] for h in hs if h is not None]
            rise = max(hs) - c0[1] if hs else None
        n_air = sum(1 for tt in frame_t if t_off <= tt <= t_on)
        fl = {"t_takeoff_s": t_off, "t_land_s": t_on, "flight_time_s": T, "jump_height_m": mocap.G * T * T / 8.0,
              "q_m_per_px": sum(q) / len(q) if q else None, "com_rise_m": rise,
              "frames_airborne": n_air, "count_flight_time_s": n_air / fps,
              "count_jump_height_m": mocap.G * (n_air / fps) ** 2 / 8.0}
        if prev_land is not None:
            fl["contact_time_s"] = t_off - prev_land
            fl["rsi"] = fl["jump_height_m"] / fl["contact_time_s"]
        truth["flights"].append(fl)
        prev_land = t_on
    header = ["t"] + ["%s%d" % (a, j) for j in range(len(names)) for a in ("x", "y", "c")]
    return header, rows, truth


def write_csv(path, header, rows):
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for r in rows:
            out = ["%.6f" % r[0]]
            for k in range(1, len(r), 3):
                x, y, c = r[k:k + 3]
                out += ["", "", "0"] if x is None else ["%.2f" % x, "%.2f" % y, "%.3f" % c]
            f.write(",".join(out) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("trc")
    ap.add_argument("--out", required=True, help="CSV to write; the truth goes to OUT.truth.json")
    ap.add_argument("--grf", help="force plates (OpenSim MOT); default: TRIAL_grf.mot beside the TRC when present")
    ap.add_argument("--stature", type=float, help="m (default: rescaling_setup.xml beside the TRC)")
    ap.add_argument("--layout", choices=sorted(mocap.LAYOUTS), default="blazepose33")
    ap.add_argument("--view", choices=VIEWS, default="front")
    ap.add_argument("--distance", type=float, default=4.0, help="camera to the jump spot, m")
    ap.add_argument("--fps", type=float, default=30.0)
    ap.add_argument("--phase", type=float, help="first frame's offset in frames, 0..1 (default random)")
    ap.add_argument("--noise", choices=("none",) + tuple(sorted(detector.NOISE_K)), default="medium")
    ap.add_argument("--errors", action="store_true", help="also outliers, misses and dropped frames")
    ap.add_argument("--resolution", choices=sorted(RESOLUTIONS), default="1080p")
    ap.add_argument("--hfov", type=float, default=60.0, help="horizontal field of view, degrees")
    ap.add_argument("--camera-height", type=float, default=1.2, help="m above the floor")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args(argv)
    grf = a.grf
    if grf is None:
        cand = a.trc[:-4] + "_grf.mot" if a.trc.endswith(".trc") else None
        grf = cand if cand and os.path.exists(cand) else None
    try:
        header, rows, truth = film(a.trc, grf, a.stature, a.layout, a.view, a.distance, a.fps, a.phase, a.noise,
                                   a.errors, a.resolution, a.hfov, a.camera_height, a.seed)
    except (OSError, ValueError) as e:
        print("film_mocap: %s" % e, file=sys.stderr)
        return 1
    tmp = a.out + ".part"
    write_csv(tmp, header, rows)
    with open(tmp + ".json", "w") as f:
        json.dump(truth, f, indent=1)
    base = a.out[:-4] if a.out.endswith(".csv") else a.out
    os.replace(tmp + ".json", base + ".truth.json")
    os.replace(tmp, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
