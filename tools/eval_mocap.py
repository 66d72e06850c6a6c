#!/usr/bin/env python3
"""Real people's jumps against their force plates: film every motion-capture trial
with the virtual camera (tools/film_mocap.py) in several set-ups and replay it.

    python3 tools/eval_mocap.py [DIR ...] [--program build/gravscale] [--layouts blazepose33,coco17]
        [--distances 4,7] [--fps 30,60] [--views front,side] [--phases 2] [--noise medium]
        [--errors] [--json OUT] [--trials] [--jobs N]

DIR: folders with TRIAL.trc + TRIAL_grf.mot (default: every folder under
../shared/data/mocap). Per layout it prints flight time, jump height (g T^2/8),
the COM's rise, q and, for rebounds, contact time and RSI against the plates,
next to what a perfect whole-frame count of airborne frames would give; flights
found (an accepted jump within 0.1 s of the plates' take-off and landing) and
false flights (accepted jumps that match no plate flight, the step off a box
among them). --trials adds a line per replay.
"""

import argparse
import concurrent.futures
import glob
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import film_mocap  # noqa: E402

MATCH_S = 0.1


def trials_in(dirs):
    out = []
    for d in dirs:
        for trc in sorted(glob.glob(os.path.join(d, "*.trc"))):
            grf = trc[:-4] + "_grf.mot"
            if os.path.exists(grf):
                out.append((trc, grf))
    return out


def run_one(args):
    program, trc, grf, layout, view, dist, fps, seed, noise, errors, tmp = args
    header, rows, truth = film_mocap.film(trc, grf, None, layout, view, dist, fps, None, noise, errors, seed=seed)
    path = os.path.join(tmp, "%s_%s_%s_%g_%g_%d.csv" % (os.path.basename(trc)[:-4], layout, view, dist, fps, seed))
    film_mocap.write_csv(path, header, rows)
    p = subprocess.run([program, "replay", "--keypoints", path], capture_output=True, text=True)
    events = [json.loads(l) for l in p.stdout.splitlines() if l.startswith("{")]
    os.unlink(path)
    return {"trial": os.path.basename(trc), "layout": layout, "view": view, "distance_m": dist, "fps": fps,
            "seed": seed, "rc": p.returncode, "stderr": p.stderr[-300:], "truth": truth,
            "jumps": [e for e in events if e.get("event") == "jump"],
            "summary": next((e for e in events if e.get("event") == "summary"), None)}


def match(run):
    """Pairs (truth flight, jump or None) and the accepted jumps that match nothing."""
    acc = [j for j in run["jumps"] if j.get("accepted")]
    pairs, used = [], set()
    for fl in run["truth"]["flights"]:
        best = None
        for k, j in enumerate(run["jumps"]):
            if j.get("t_takeoff_s") is None or j.get("t_land_s") is None:
                continue
            if abs(j["t_takeoff_s"] - fl["t_takeoff_s"]) <= MATCH_S and abs(j["t_land_s"] - fl["t_land_s"]) <= MATCH_S:
                best = k
        if best is not None:
            used.add(best)
        pairs.append((fl, run["jumps"][best] if best is not None else None))
    false = [j for k, j in enumerate(run["jumps"]) if j.get("accepted") and k not in used]
    return pairs, false, acc


def stats(v):
    v = [x for x in v if x is not None]
    if not v:
        return None, None, 0
    return sum(abs(x) for x in v) / len(v), sum(v) / len(v), len(v)


def fmt(s, unit, k=1.0, nd=1):
    mae, me, n = s
    if mae is None:
        return "%-20s" % "-"
    return "%-20s" % ("%.*f / %+.*f %s" % (nd, mae * k, nd, me * k, unit))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="*")
    ap.add_argument("--program", default=os.environ.get("GS_PROGRAM", os.path.join(os.path.dirname(HERE), "build", "gravscale")))
    ap.add_argument("--layouts", default="blazepose33,coco17")
    ap.add_argument("--distances", default="4,7")
    ap.add_argument("--fps", default="30,60")
    ap.add_argument("--views", default="front,side")
    ap.add_argument("--phases", type=int, default=2, help="random phases (seeds) per set-up")
    ap.add_argument("--noise", default="medium")
    ap.add_argument("--errors", action="store_true")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--json")
    ap.add_argument("--trials", action="store_true")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    a = ap.parse_args(argv)
    dirs = a.dirs or sorted(glob.glob(os.path.join(os.path.dirname(HERE), "..", "shared", "data", "mocap", "*")))
    trials = trials_in(dirs)
    if not trials:
        print("eval_mocap: no TRIAL.trc with TRIAL_grf.mot in %s" % " ".join(dirs), file=sys.stderr)
        return 1
    tmp = tempfile.mkdtemp(prefix="gs_mocap_")
    jobs = []
    for layout in a.layouts.split(","):
        for trc, grf in trials:
            for view in a.views.split(","):
                for dist in [float(x) for x in a.distances.split(",")]:
                    for fps in [float(x) for x in a.fps.split(",")]:
                        for s in range(a.phases):
                            jobs.append((a.program, trc, grf, layout, view, dist, fps, a.seed + s, a.noise,
                                         a.errors, tmp))
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
        runs = list(ex.map(run_one, jobs))
    os.rmdir(tmp)
    print("%d trials x %d set-ups; errors as MAE / ME" % (len(trials), len(runs) // len(trials)))
    hdr = "%-12s %-20s %-20s %-20s %-20s %-20s %-20s %-20s %-7s %-6s %s" % (
        "layout", "flight time", "  whole-frame count", "jump height gT²/8", "  whole-frame count",
        "COM rise", "q", "contact time", "found", "false", "stature")
    print(hdr)
    for layout in a.layouts.split(","):
        ft, ftc, jh, jhc, rise, q, ct, st = [], [], [], [], [], [], [], []
        n_fl = n_found = n_false = 0
        for r in runs:
            if r["layout"] != layout:
                continue
            pairs, false, acc = match(r)
            n_false += len(false)
            for fl, j in pairs:
                n_fl += 1
                ftc.append(fl["count_flight_time_s"] - fl["flight_time_s"])
                jhc.append(fl["count_jump_height_m"] - fl["jump_height_m"])
                if j is None or not j.get("accepted"):
                    continue
                n_found += 1
                if j.get("flight_time_s") is not None:
                    ft.append(j["flight_time_s"] - fl["flight_time_s"])
                if j.get("jump_height_m") is not None:
                    jh.append(j["jump_height_m"] - fl["jump_height_m"])
                if j.get("com_rise_m") is not None and fl.get("com_rise_m") is not None:
                    rise.append(j["com_rise_m"] - fl["com_rise_m"])
                if j.get("q_m_per_px") is not None and fl.get("q_m_per_px"):
                    q.append(j["q_m_per_px"] / fl["q_m_per_px"] - 1.0)
                if j.get("contact_time_s") is not None and fl.get("contact_time_s") is not None:
                    ct.append(j["contact_time_s"] - fl["contact_time_s"])
            s = r["summary"]
            if s and s.get("height_m") is not None:
                st.append(s["height_m"] - r["truth"]["stature_m"])
            if a.trials:
                for fl, j in pairs:
                    print("  %-9s %-6s %-9s %gm %gfps s%d: T %s (truth %.4f) h %s (%.4f) q %s (%.6f)%s" % (
                        r["trial"], layout[:6], r["view"], r["distance_m"], r["fps"], r["seed"],
                        "%.4f" % j["flight_time_s"] if j else "-", fl["flight_time_s"],
                        "%.4f" % j["jump_height_m"] if j and j.get("jump_height_m") is not None else "-",
                        fl["jump_height_m"], "%.6f" % j["q_m_per_px"] if j and j.get("q_m_per_px") else "-",
                        fl["q_m_per_px"] or 0.0,
                        "" if j and j.get("accepted") else (" REJ " + str(j.get("reason")) if j else " MISSED")))
                for j in false:
                    print("  %-9s %-6s %-9s %gm %gfps s%d: FALSE flight %.3f-%.3f s h %s" % (
                        r["trial"], layout[:6], r["view"], r["distance_m"], r["fps"], r["seed"],
                        j["t_takeoff_s"], j["t_land_s"], j.get("height_m")))
        print("%-12s %s %s %s %s %s %-20s %s %-7s %-6d %s" % (
            layout, fmt(stats(ft), "ms", 1000.0), fmt(stats(ftc), "ms", 1000.0),
            fmt(stats(jh), "cm", 100.0, 2), fmt(stats(jhc), "cm", 100.0, 2), fmt(stats(rise), "cm", 100.0, 2),
            ("%.2f %% (|mean| %.2f)" % (stats(q)[0] * 100, abs(stats(q)[1]) * 100)) if q else "-",
            fmt(stats(ct), "ms", 1000.0), "%d/%d" % (n_found, n_fl), n_false,
            fmt(stats(st), "cm", 100.0) + (" (%d runs)" % len(st) if st else "")))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(runs, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
