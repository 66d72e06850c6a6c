#!/usr/bin/env python3
"""Generate synthetic jump trials with ground truth (see docs/simulator.md)."""

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from gsim import dataset  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--preset", choices=sorted(dataset.PRESETS), help="a named configuration")
    ap.add_argument("--subjects", type=int, default=12)
    ap.add_argument("--stature", default="1.50:1.95", help="stature range lo:hi in m")
    ap.add_argument("--distances", default="4,7")
    ap.add_argument("--types", default="low,high,jack,funny",
                    help="comma list of low,high,jack,funny,walk,run")
    ap.add_argument("--trials", type=int, default=3, help="trials per subject, distance, type")
    ap.add_argument("--fps", type=float, default=30.0, choices=[30.0, 60.0, 120.0])
    ap.add_argument("--res", default="1080p", choices=["1080p", "720p", "vga"])
    ap.add_argument("--roll-deg", default="0", help="fixed roll or a range lo:hi (random sign)")
    ap.add_argument("--noise", default="medium", choices=["low", "medium", "high"])
    ap.add_argument("--distortion", action="store_true", help="small radial lens distortion")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=0, help="worker processes (0: auto)")
    a = ap.parse_args(argv)
    if a.preset:
        p = dataset.PRESETS[a.preset]
        opts = {"subjects": p["subjects"], "stature": p["stature"], "distances": p["distances"],
                "fps": p["fps"], "res": p["res"], "types": p["types"] + p["extra"],
                "extra": p["extra"], "trials": p["trials"], "roll": p["roll"],
                "noise": p["noise"], "seed": a.seed, "distortion": a.distortion}
    else:
        lo, hi = (float(v) for v in a.stature.split(":"))
        if ":" in a.roll_deg:
            r = tuple(float(v) for v in a.roll_deg.split(":"))
        else:
            r = (float(a.roll_deg), float(a.roll_deg))
        types = [t for t in a.types.split(",") if t]
        for t in types:
            if t not in dataset.TYPES:
                ap.error("unknown type %r" % t)
        opts = {"subjects": a.subjects, "stature": (lo, hi),
                "distances": [float(v) for v in a.distances.split(",")], "fps": a.fps,
                "res": a.res, "types": types, "extra": [t for t in types if t in ("walk", "run")],
                "trials": a.trials, "roll": r, "noise": a.noise, "seed": a.seed,
                "distortion": a.distortion}
        if r[0] == r[1]:
            opts["roll_fixed"] = r[0]
    t0 = time.time()
    recs = dataset.generate(opts, a.out, a.jobs or None)
    print("%d trials in %s (%.1f s)" % (len(recs), a.out, time.time() - t0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
