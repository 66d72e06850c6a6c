"""Trials and datasets: motion + camera + detector -> CSV, AlphaPose JSON, truth."""

import json
import math
import os
import random

from . import anthro, body, builders
from .camera import Camera, RESOLUTIONS
from .detector import detect
from .motion import Infeasible, G, D2R

TYPES = ("low", "high", "jack", "funny", "walk", "run")
EXTRA = ("vertex", "l_heel", "r_heel", "l_ball", "r_ball")


def build_motion(sub, rng, jtype, view_w):
    """Stand, 1-4 movements of the type (jacks: one rhythmic series), stand."""
    u = rng.uniform
    if jtype == "run":
        direction = 1 if rng.random() < 0.5 else -1
        b = builders.Builder(sub, rng, -direction * math.pi / 2, x0=-direction * 0.38 * view_w)
        b.stand(u(1.5, 3.0))
        b.run(direction, 0.76 * view_w)
        b.stand(u(1.0, 2.0))
        return b
    if jtype == "walk":
        across = rng.random() < 0.6
        direction = 1 if rng.random() < 0.5 else -1
        yaw = -direction * math.pi / 2 if across else math.pi + u(-20, 20) * D2R
        x0 = -direction * 0.35 * view_w if across else 0.0
        b = builders.Builder(sub, rng, yaw, x0=x0)
        b.stand(u(1.5, 3.0))
        b.walk(u(2.5, 4.5) if across else u(3.0, 6.0), across, direction)
        b.stand(u(1.0, 2.0))
        return b
    b = builders.Builder(sub, rng, math.pi + u(-20, 20) * D2R)
    b.stand(u(1.5, 3.0))
    if jtype == "jack":
        b.jacks(rng.randint(4, 10))
    else:
        n = rng.randint(1, 4)
        for i in range(n):
            b.cmj(jtype)
            if i < n - 1:
                b.stand(u(0.8, 2.0))
    b.stand(u(1.0, 2.0))
    return b


def make_camera(rng, res, distance, roll_deg, distortion):
    W, H = RESOLUTIONS[res]
    u = rng.uniform
    k1 = u(-0.05, 0.05) if distortion else 0.0
    return Camera(W, H, u(50.0, 75.0), distance, u(0.8, 1.6), u(0.8, 1.2), roll_deg, k1, 0.0)


def fmt(v, nd):
    s = "%.*f" % (nd, v)
    return "0" if s in ("-0", "-0.0") else s


def generate_trial(spec, outdir):
    """spec: dict with trial, subject, stature_m, sex_seed, distance_m, jump_type, fps, res,
    roll_deg, noise, seed, distortion. Writes the files; returns the trials.jsonl record."""
    attempt = 0
    while True:
        rng = random.Random("%s/%s/%d" % (spec["seed"], spec["trial"], attempt))
        srng = random.Random("%s/%s" % (spec["seed"], spec["subject"]))
        sub = anthro.make_subject(srng, spec["subject"], spec["stature_m"])
        cam = make_camera(rng, spec["res"], spec["distance_m"], spec["roll_deg"],
                          spec.get("distortion", False))
        view_w = 2 * spec["distance_m"] * math.tan(math.radians(cam.hfov_deg) / 2)
        try:
            b = build_motion(sub, rng, spec["jump_type"], view_w)
            frames = sample(b, cam, spec["fps"])
            break
        except Infeasible:
            attempt += 1
            if attempt > 40:
                raise
    return write_trial(spec, outdir, sub, cam, b, frames, rng)


def sample(b, cam, fps):
    m = b.m
    n = int(math.floor(b.t * fps))
    frames = []
    for k in range(n):
        t = k / fps
        pts, com, _, _ = m.state(t)
        px = [cam.project(pts[name]) for name in body.COCO]
        ex = {name: cam.project(pts[name]) for name in EXTRA}
        frames.append((k, t, pts, com, px, ex, cam.project(com)))
    return frames


def write_trial(spec, outdir, sub, cam, b, frames, rng):
    fps = spec["fps"]
    # person's pixel height: standing vertex to heel in the first frame
    ex0 = frames[0][5]
    heel = ((ex0["l_heel"][0] + ex0["r_heel"][0]) / 2, (ex0["l_heel"][1] + ex0["r_heel"][1]) / 2)
    body_px = math.hypot(ex0["vertex"][0] - heel[0], ex0["vertex"][1] - heel[1])
    dets, stats = detect(rng, [f[4] for f in frames], fps, body_px, spec["noise"], cam.width,
                         cam.height)
    name = spec["trial"]
    csv_name = name + ".csv"
    ap_name = name + ".alphapose.json"
    lines = ["t," + ",".join("x%d,y%d,c%d" % (j, j, j) for j in range(17))]
    ap = []
    for (k, t, _, _, _, _, _), det in zip(frames, dets):
        if det is None:
            continue
        row = [fmt(t, 6)]
        kp = []
        for d in det:
            if d is None:
                row += ["", "", "0"]
                kp += [0.0, 0.0, 0.0]
            else:
                xs, ys, cs = fmt(d[0], 2), fmt(d[1], 2), fmt(d[2], 3)
                row += [xs, ys, cs]
                kp += [float(xs), float(ys), float(cs)]
        lines.append(",".join(row))
        cs = [kp[3 * j + 2] for j in range(17) if kp[3 * j + 2] > 0]
        score = sum(cs) / len(cs) if cs else 0.0
        ap.append({"image_id": "%06d.jpg" % k, "category_id": 1, "keypoints": kp,
                   "score": round(score + 1.0, 4), "idx": 0})
    with open(os.path.join(outdir, csv_name), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(outdir, ap_name), "w") as f:
        json.dump(ap, f, separators=(",", ":"))
    flights = [{k: round(v, 6) for k, v in fl.items() if k != "takeoff_velocity_h_m_s"}
               for fl in b.flights]
    rec = {"trial": name, "subject": spec["subject"], "stature_m": spec["stature_m"],
           "distance_m": spec["distance_m"], "jump_type": spec["jump_type"], "fps": float(fps),
           "width": cam.width, "height": cam.height, "roll_deg": spec["roll_deg"],
           "noise": spec["noise"], "seed": spec["seed"], "csv": csv_name, "alphapose": ap_name,
           "q_m_per_px": cam.q_m_per_px, "flights": flights}
    truth = dict(rec)
    truth.update({
        "camera": cam.to_dict(), "subject_model": sub.to_dict(), "body_px": body_px,
        "detector": stats, "g_m_s2": G, "duration_s": b.t,
        "flights_full": b.flights,
        "frames": [{"frame": k, "t": round(t, 6), "com_m": [round(v, 6) for v in com],
                    "com_px": [round(v, 3) for v in cpx] if cpx else None,
                    "vertex_px": [round(v, 3) for v in ex["vertex"]] if ex["vertex"] else None}
                   for (k, t, _, com, _, ex, cpx) in frames],
    })
    with open(os.path.join(outdir, name + ".truth.json"), "w") as f:
        json.dump(truth, f, separators=(",", ":"))
    return rec


PRESETS = {
    "heldout-like": {"subjects": 12, "stature": (1.57, 1.88), "distances": [4.0, 7.0], "fps": 30,
                     "res": "1080p", "types": ["low", "high", "jack", "funny"], "trials": 3,
                     "extra": ["walk", "run"], "roll": (0.0, 0.0), "noise": "medium"},
    "hard": {"subjects": 12, "stature": (1.50, 1.95), "distances": [7.0], "fps": 120,
             "res": "vga", "types": ["low", "high", "jack", "funny"], "trials": 3,
             "extra": ["walk", "run"], "roll": (15.0, 45.0), "noise": "high"},
}


def draw_roll(rng, rng_range):
    """A fixed roll is used as given; a range lo:hi draws |roll| in it with a random sign."""
    lo, hi = rng_range
    if lo == hi:
        return float(lo)
    return round(rng.uniform(lo, hi) * (1 if rng.random() < 0.5 else -1), 3)


def plan(opts):
    """Trial specs for a dataset. opts: dict of CLI options (see tools/gen_jumps.py)."""
    rng = random.Random("plan/%s" % opts["seed"])
    lo, hi = opts.get("stature", (1.50, 1.95))
    stats = anthro.statures(opts["subjects"], lo, hi, rng)
    specs = []
    for si, H in enumerate(stats):
        sid = "S%02d" % (si + 1)
        for d in opts["distances"]:
            types = list(opts["types"])
            for jt in types:
                ntr = opts["trials"] if jt not in opts.get("extra", []) else 1
                for tr in range(1, ntr + 1):
                    roll = draw_roll(rng, opts["roll"])
                    specs.append({"trial": "%s_d%g_%s_t%d" % (sid, d, jt, tr), "subject": sid,
                                  "stature_m": H, "distance_m": d, "jump_type": jt,
                                  "fps": opts["fps"], "res": opts["res"], "roll_deg": roll,
                                  "noise": opts["noise"], "seed": opts["seed"],
                                  "distortion": opts.get("distortion", False)})
            for jt in opts.get("extra", []):
                if jt in types:
                    continue
                specs.append({"trial": "%s_d%g_%s_t1" % (sid, d, jt), "subject": sid,
                              "stature_m": H, "distance_m": d, "jump_type": jt,
                              "fps": opts["fps"], "res": opts["res"],
                              "roll_deg": draw_roll(rng, opts["roll"]),
                              "noise": opts["noise"], "seed": opts["seed"],
                              "distortion": opts.get("distortion", False)})
    return specs


def _work(args):
    spec, outdir = args
    return generate_trial(spec, outdir)


def generate(opts, outdir, jobs=None):
    os.makedirs(outdir, exist_ok=True)
    specs = plan(opts)
    jobs = jobs or min(4, os.cpu_count() or 1)
    if jobs > 1 and len(specs) > 1:
        import multiprocessing
        with multiprocessing.Pool(jobs) as pool:
            recs = pool.map(_work, [(s, outdir) for s in specs], chunksize=1)
    else:
        recs = [_work((s, outdir)) for s in specs]
    with open(os.path.join(outdir, "trials.jsonl"), "w") as f:
        for r in recs:
            f.write(json.dumps(r, separators=(",", ":")) + "\n")
    return recs
