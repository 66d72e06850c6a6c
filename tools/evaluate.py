#!/usr/bin/env python3
"""Evaluate gravscale (and/or the paper's method) on a synthetic jump dataset.

    python3 tools/evaluate.py DATASET_DIR [--program build/gravscale] [--config CFG]
        [--method gravscale|paper|both] [--jobs 2] [--json OUT] [--bars]

DATASET_DIR/trials.jsonl holds one trial per line (subject, stature_m, distance_m,
jump_type, csv, q_m_per_px, flights[...]).  Each trial's CSV is run through
`PROGRAM replay --keypoints CSV [--config CFG]` and/or tools/paper_baseline.py,
both printing JSON Lines; a trial's estimate is its summary's height_m.
Prints the paper's tables (per subject, per jump type, detection, timing); see
docs/evaluation.md.  Exit 2 if any run failed (crash, non-zero exit, timeout),
else with --bars exit 1 if gravscale misses a bar, else 0.  Standard library only.
"""
import argparse
import concurrent.futures
import json
import math
import os
import shlex
import statistics
import subprocess
import sys

ONSPOT = ("low", "high", "jack", "funny")   # the paper's on-spot jump types (its tables 1 and 2)
MATCH_TOL_S = 0.1                           # take-off and landing each within 0.1 s of the truth
BAR_MAE_CM = 2.0
BAR_ME_CM = 1.0
BAR_FOUND = 0.95
HERE = os.path.dirname(os.path.abspath(__file__))
PAPER_SCRIPT = os.path.join(HERE, "paper_baseline.py")


# ---------------------------------------------------------------- statistics
def _finite(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def median(xs):
    xs = [x for x in xs if _finite(x)]
    return statistics.median(xs) if xs else None


def _sd(xs):
    # sample standard deviation (n - 1); unknown for fewer than two values
    return statistics.stdev(xs) if len(xs) >= 2 else None


def me_sd(errors):
    """Mean signed error and the SD of the signed errors (the paper's bias, ME +- SD)."""
    xs = [x for x in errors if _finite(x)]
    return {"me": statistics.fmean(xs) if xs else None, "sd": _sd(xs), "n": len(xs)}


def mae_sd(errors):
    """Mean absolute error and the SD of the absolute errors (the paper's accuracy, MAE +- SD)."""
    xs = [abs(x) for x in errors if _finite(x)]
    return {"mae": statistics.fmean(xs) if xs else None, "sd": _sd(xs), "n": len(xs)}


def both_stats(errors):
    a, b = me_sd(errors), mae_sd(errors)
    return {"me": a["me"], "me_sd": a["sd"], "mae": b["mae"], "mae_sd": b["sd"], "n": a["n"]}


# ---------------------------------------------------------------- running
def load_trials(dataset_dir):
    path = os.path.join(dataset_dir, "trials.jsonl")
    trials = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                trials.append(json.loads(line))
            except json.JSONDecodeError as e:
                raise SystemExit("evaluate: %s:%d: %s" % (path, n, e))
    return trials


def method_command(method, csv_path, program, config, paper_args):
    if method == "paper":
        return [sys.executable, PAPER_SCRIPT, csv_path] + list(paper_args)
    cmd = [sys.executable, program] if program.endswith(".py") else [program]
    cmd += ["replay", "--keypoints", csv_path]
    if config:
        cmd += ["--config", config]
    return cmd


def parse_events(text):
    """JSON objects of the output, one a line; other lines are counted, not fatal."""
    events, bad = [], 0
    for line in text.splitlines():
        line = line.strip()
        if not line:
            continue
        try:
            ev = json.loads(line)
        except json.JSONDecodeError:
            bad += 1
            continue
        if isinstance(ev, dict):
            events.append(ev)
        else:
            bad += 1
    return events, bad


def run_trial(method, trial, dataset_dir, program, config, paper_args, timeout_s):
    csv_path = os.path.join(dataset_dir, trial["csv"])
    cmd = method_command(method, csv_path, program, config, paper_args)
    res = {"trial": trial.get("trial"), "method": method, "cmd": cmd, "failed": False,
           "error": None, "events": [], "bad_lines": 0}
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
    except subprocess.TimeoutExpired:
        res.update(failed=True, error="timeout after %g s" % timeout_s)
        return res
    except OSError as e:
        res.update(failed=True, error="cannot run: %s" % e)
        return res
    if p.returncode != 0:
        tail = (p.stderr or "").strip().splitlines()[-3:]
        res.update(failed=True, error="exit status %d%s" % (
            p.returncode, (": " + " | ".join(tail)) if tail else ""))
    res["events"], res["bad_lines"] = parse_events(p.stdout)
    return res


# ---------------------------------------------------------------- scoring one trial
def match_flights(true_flights, jumps, tol_s=MATCH_TOL_S):
    """One-to-one matching of accepted jump events to true flights: a pair qualifies when
    take-off and landing each differ by at most tol_s; pairs are taken greedily, closest
    first (sum of both differences).  Returns [(flight index, jump index)] sorted by flight."""
    cands = []
    for fi, f in enumerate(true_flights):
        for ji, j in enumerate(jumps):
            if not (_finite(j.get("t_takeoff_s")) and _finite(j.get("t_land_s"))):
                continue
            d0 = abs(j["t_takeoff_s"] - f["t_takeoff_s"])
            d1 = abs(j["t_land_s"] - f["t_land_s"])
            if d0 <= tol_s + 1e-9 and d1 <= tol_s + 1e-9:
                cands.append((d0 + d1, fi, ji))
    cands.sort()
    used_f, used_j, pairs = set(), set(), []
    for _c, fi, ji in cands:
        if fi in used_f or ji in used_j:
            continue
        used_f.add(fi)
        used_j.add(ji)
        pairs.append((fi, ji))
    pairs.sort()
    return pairs


def score_trial(trial, run):
    """Per-trial numbers from one run's events."""
    events = run["events"] if run else []
    summaries = [e for e in events if e.get("event") == "summary"]
    summary = summaries[-1] if summaries else {}
    jumps = [e for e in events if e.get("event") == "jump"]
    accepted = [j for j in jumps if j.get("accepted") is True]
    est = summary.get("height_m")
    est = est if _finite(est) else None
    stature = trial["stature_m"]
    q_est = median([j.get("q_m_per_px") for j in accepted])
    q_true = trial.get("q_m_per_px")
    flights = trial.get("flights") or []
    pairs = match_flights(flights, accepted)
    timing = []
    for fi, ji in pairs:
        f, j = flights[fi], accepted[ji]

        def diff(key, scale, j=j, f=f):
            a, b = j.get(key), f.get(key)
            return (a - b) * scale if _finite(a) and _finite(b) else None
        timing.append({"flight": fi, "jump_height_cm": diff("jump_height_m", 100.0),
                       "com_rise_cm": diff("com_rise_m", 100.0),
                       "flight_time_ms": diff("flight_time_s", 1000.0),
                       "takeoff_velocity_m_s": diff("takeoff_velocity_m_s", 1.0)})
    return {
        "trial": trial.get("trial"), "subject": trial.get("subject"),
        "distance_m": trial.get("distance_m"), "jump_type": trial.get("jump_type"),
        "stature_m": stature, "height_m": est,
        "error_cm": (est - stature) * 100.0 if est is not None else None,
        "rel_error_pct": (est - stature) / stature * 100.0 if est is not None else None,
        "q_true": q_true, "q_est": q_est,
        "q_rel_error_pct": ((q_est - q_true) / q_true * 100.0
                            if q_est is not None and _finite(q_true) and q_true != 0 else None),
        "n_accepted": len(accepted), "n_rejected": len(jumps) - len(accepted),
        "n_true_flights": len(flights), "n_matched": len(pairs),
        "missing": est is None, "failed": bool(run and run["failed"]),
        "error": run["error"] if run else "not run", "timing": timing,
    }


# ---------------------------------------------------------------- tables
def _group(jt):
    if jt in ONSPOT:
        return "onspot"
    if jt in ("walk", "run"):
        return jt
    return "other"


def per_subject(rows, distances):
    out = []
    subjects = sorted({r["subject"] for r in rows if _group(r["jump_type"]) == "onspot"})
    for s in subjects:
        mine = [r for r in rows if r["subject"] == s and _group(r["jump_type"]) == "onspot"]
        stature = median([r["stature_m"] for r in mine])
        row = {"subject": s, "stature_m": stature, "n_trials": len(mine),
               "n_missing": sum(1 for r in mine if r["missing"]), "by_distance": {}}
        for d in distances:
            rd = [r for r in mine if r["distance_m"] == d]
            h = median([r["height_m"] for r in rd])
            row["by_distance"][_dkey(d)] = {
                "n_trials": len(rd), "height_m": h,
                "error_cm": (h - stature) * 100.0 if h is not None else None,
                "rel_error_pct": (h - stature) / stature * 100.0 if h is not None else None,
                "q_rel_error_pct": median([r["q_rel_error_pct"] for r in rd]),
            }
        h = median([r["height_m"] for r in mine])
        row["combined"] = {"height_m": h,
                           "error_cm": (h - stature) * 100.0 if h is not None else None,
                           "rel_error_pct": (h - stature) / stature * 100.0 if h is not None else None,
                           "q_rel_error_pct": median([r["q_rel_error_pct"] for r in mine])}
        out.append(row)
    across = {"by_distance": {}, "combined": {}}
    for d in distances:
        k = _dkey(d)
        across["by_distance"][k] = {
            f: both_stats([s["by_distance"][k][f] for s in out])
            for f in ("error_cm", "rel_error_pct", "q_rel_error_pct")}
    across["combined"] = {f: both_stats([s["combined"][f] for s in out])
                          for f in ("error_cm", "rel_error_pct", "q_rel_error_pct")}
    return out, across


def per_type(rows, distances, types):
    out = {}
    for jt in types:
        out[jt] = {}
        for d in distances:
            rd = [r for r in rows if r["jump_type"] == jt and r["distance_m"] == d]
            out[jt][_dkey(d)] = {"n_trials": len(rd), "n_missing": sum(1 for r in rd if r["missing"]),
                                 "h_error_cm": both_stats([r["error_cm"] for r in rd]),
                                 "q_rel_error_pct": both_stats([r["q_rel_error_pct"] for r in rd])}
    return out


def detection(rows, group):
    rd = [r for r in rows if _group(r["jump_type"]) == group]
    n_true = sum(r["n_true_flights"] for r in rd)
    n_found = sum(r["n_matched"] for r in rd)
    n_acc = sum(r["n_accepted"] for r in rd)
    return {"n_trials": len(rd), "true_flights": n_true, "found": n_found,
            "found_frac": n_found / n_true if n_true else None,
            "accepted_events": n_acc, "precision": n_found / n_acc if n_acc else None,
            "false_flights": n_acc - n_found}


def timing(rows, group):
    pairs = [t for r in rows if _group(r["jump_type"]) == group for t in r["timing"]]
    return {"n_pairs": len(pairs),
            "jump_height_cm": both_stats([p["jump_height_cm"] for p in pairs]),
            "flight_time_ms": both_stats([p["flight_time_ms"] for p in pairs]),
            "takeoff_velocity_m_s": both_stats([p["takeoff_velocity_m_s"] for p in pairs])}


def _dkey(d):
    return "%g" % d


def summarize(trials, runs):
    """All numbers of one method: runs maps trial name -> run result."""
    rows = [score_trial(t, runs.get(t.get("trial"))) for t in trials]
    distances = sorted({r["distance_m"] for r in rows if _finite(r["distance_m"])})
    types_present = [jt for jt in ONSPOT if any(r["jump_type"] == jt for r in rows)]
    subjects, across = per_subject(rows, distances)
    det = {g: detection(rows, g) for g in ("onspot", "walk", "run", "other")}
    run_h = {_dkey(d): both_stats([r["error_cm"] for r in rows
                                   if r["jump_type"] == "run" and r["distance_m"] == d])
             for d in distances}
    return {
        # walks have no flight, so no estimate is expected of them: they are not "missing"
        "n_trials": len(rows),
        "n_missing": sum(1 for r in rows if r["missing"] and _group(r["jump_type"]) != "walk"),
        "n_walk_with_estimate": sum(1 for r in rows if not r["missing"] and r["jump_type"] == "walk"),
        "n_missing_onspot": sum(1 for r in rows if r["missing"] and _group(r["jump_type"]) == "onspot"),
        "n_failed": sum(1 for r in rows if r["failed"]),
        "failures": [{"trial": r["trial"], "error": r["error"]} for r in rows if r["failed"]],
        "distances_m": distances, "per_subject": subjects, "across_subjects": across,
        "per_type": per_type(rows, distances, types_present),
        "detection": det, "timing": {g: timing(rows, g) for g in ("onspot", "run")},
        "run_height_error_cm": run_h, "trials": rows,
    }


def bars(summary):
    """The held-out bars on gravscale: combined per-subject MAE and |ME|, detection, walks."""
    comb = summary["across_subjects"]["combined"]["error_cm"]
    found = summary["detection"]["onspot"]["found_frac"]
    walk_ff = summary["detection"]["walk"]["false_flights"]
    checks = {
        "mae_cm": {"value": comb["mae"], "limit": BAR_MAE_CM,
                   "ok": comb["mae"] is not None and comb["mae"] <= BAR_MAE_CM},
        "abs_me_cm": {"value": abs(comb["me"]) if comb["me"] is not None else None, "limit": BAR_ME_CM,
                      "ok": comb["me"] is not None and abs(comb["me"]) <= BAR_ME_CM},
        "found_frac": {"value": found, "limit": BAR_FOUND, "ok": found is not None and found >= BAR_FOUND},
        "walk_false_flights": {"value": walk_ff, "limit": 0, "ok": walk_ff == 0},
    }
    return {"ok": all(c["ok"] for c in checks.values()), "checks": checks}


# ---------------------------------------------------------------- printing
def _f(v, nd=1):
    return "n/a" if v is None else "%.*f" % (nd, v)


def _pm(a, b, nd=1):
    return "%s+-%s" % (_f(a, nd), _f(b, nd))


def _me(s, nd=1):
    return _pm(s["me"], s["me_sd"], nd)


def _mae(s, nd=1):
    return _pm(s["mae"], s["mae_sd"], nd)


def print_report(name, s, out=sys.stdout):
    w = out.write
    dk = [_dkey(d) for d in s["distances_m"]]
    w("\n=== method: %s ===  trials %d, missing estimates %d (on-spot %d; walks not counted), failed runs %d\n" % (
        name, s["n_trials"], s["n_missing"], s["n_missing_onspot"], s["n_failed"]))
    for fl in s["failures"]:
        w("  FAILED %s: %s\n" % (fl["trial"], fl["error"]))

    w("\n-- per subject (on-spot jumps; per subject = median of its trials' estimates) --\n")
    hdr = "%-8s %7s" % ("subject", "h[cm]")
    for k in dk:
        hdr += " | %6s %6s %7s" % ("e%sm" % k, "rel%", "q_rel%")
    hdr += " | %6s %6s %7s | miss" % ("e_all", "rel%", "q_rel%")
    w(hdr + "\n")
    for r in s["per_subject"]:
        line = "%-8s %7s" % (r["subject"], _f(r["stature_m"] * 100.0 if r["stature_m"] else None))
        for k in dk:
            b = r["by_distance"][k]
            line += " | %6s %6s %7s" % (_f(b["error_cm"]), _f(b["rel_error_pct"]), _f(b["q_rel_error_pct"]))
        c = r["combined"]
        line += " | %6s %6s %7s | %d/%d" % (_f(c["error_cm"]), _f(c["rel_error_pct"]),
                                            _f(c["q_rel_error_pct"]), r["n_missing"], r["n_trials"])
        w(line + "\n")
    a = s["across_subjects"]
    for label, fn in (("ME+-SD", _me), ("MAE+-SD", _mae)):
        w("%s across subjects:\n" % label)
        for k in dk:
            b = a["by_distance"][k]
            w("  %4s m: h %s cm, rel %s %%, q %s %%\n" % (
                k, fn(b["error_cm"]), fn(b["rel_error_pct"]), fn(b["q_rel_error_pct"])))
        c = a["combined"]
        w("  all   : h %s cm, rel %s %%, q %s %%  (n=%d subjects)\n" % (
            fn(c["error_cm"]), fn(c["rel_error_pct"]), fn(c["q_rel_error_pct"]), c["error_cm"]["n"]))

    w("\n-- per jump type (over trials) --\n")
    for jt, byd in s["per_type"].items():
        for k in dk:
            b = byd[k]
            if not b["n_trials"]:
                continue
            w("  %-5s %4s m: h ME %s MAE %s cm | q ME %s MAE %s %% (n=%d, missing %d)\n" % (
                jt, k, _me(b["h_error_cm"]), _mae(b["h_error_cm"]),
                _me(b["q_rel_error_pct"]), _mae(b["q_rel_error_pct"]), b["n_trials"], b["n_missing"]))

    w("\n-- detection (accepted jump events vs true flights, +-%.1f s, one-to-one) --\n" % MATCH_TOL_S)
    for g in ("onspot", "run", "other"):
        d = s["detection"][g]
        if not d["n_trials"]:
            continue
        w("  %-6s: found %d/%d (%s %%), precision %s %% (%d accepted, %d false)\n" % (
            g, d["found"], d["true_flights"],
            _f(d["found_frac"] * 100 if d["found_frac"] is not None else None),
            _f(d["precision"] * 100 if d["precision"] is not None else None),
            d["accepted_events"], d["false_flights"]))
    d = s["detection"]["walk"]
    if d["n_trials"]:
        w("  walk  : false flights %d on %d trials (must be 0); walks with a height estimate %d\n" % (
            d["false_flights"], d["n_trials"], s["n_walk_with_estimate"]))

    w("\n-- timing (matched flights) --\n")
    for g in ("onspot", "run"):
        t = s["timing"][g]
        if not t["n_pairs"]:
            continue
        w("  %-6s: jump height ME %s MAE %s cm | flight time ME %s MAE %s ms | "
          "take-off v ME %s MAE %s m/s (n=%d)\n" % (
              g, _me(t["jump_height_cm"]), _mae(t["jump_height_cm"]),
              _me(t["flight_time_ms"], 0), _mae(t["flight_time_ms"], 0),
              _me(t["takeoff_velocity_m_s"], 3), _mae(t["takeoff_velocity_m_s"], 3), t["n_pairs"]))
    if s["detection"]["run"]["n_trials"]:
        w("\n-- run trials, height error per trial --\n")
        for k in dk:
            b = s["run_height_error_cm"][k]
            if b["n"]:
                w("  %4s m: ME %s MAE %s cm (n=%d)\n" % (k, _me(b), _mae(b), b["n"]))


# ---------------------------------------------------------------- main
def run_all(trials, dataset_dir, methods, program, config, paper_args, jobs, timeout_s):
    results = {m: {} for m in methods}
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as ex:
        futs = {ex.submit(run_trial, m, t, dataset_dir, program, config, paper_args, timeout_s): (m, t)
                for m in methods for t in trials}
        for fut in concurrent.futures.as_completed(futs):
            m, t = futs[fut]
            results[m][t.get("trial")] = fut.result()
    return results


def main(argv=None):
    ap = argparse.ArgumentParser(description="Evaluate gravscale and the paper's method on a jump dataset.")
    ap.add_argument("dataset", help="folder with trials.jsonl and the trial CSVs")
    ap.add_argument("--program", default=os.environ.get("GS_PROGRAM", "build/gravscale"),
                    help="gravscale program (default $GS_PROGRAM or build/gravscale); a .py runs with python3")
    ap.add_argument("--config", default=None, help="config file passed to gravscale")
    ap.add_argument("--method", choices=("gravscale", "paper", "both"), default="gravscale")
    ap.add_argument("--paper-args", default="", help="extra arguments for paper_baseline.py, e.g. --ransac")
    ap.add_argument("--jobs", type=int, default=2, help="trials run in parallel")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per run")
    ap.add_argument("--json", dest="json_out", default=None, help="write every number here")
    ap.add_argument("--bars", action="store_true",
                    help="exit 1 if gravscale misses MAE<=2 cm, |ME|<=1 cm, found>=95%% or has a walk false flight")
    args = ap.parse_args(argv)

    methods = ["gravscale", "paper"] if args.method == "both" else [args.method]
    if args.bars and "gravscale" not in methods:
        ap.error("--bars needs --method gravscale or both")
    if "gravscale" in methods and not os.path.isfile(args.program):
        sys.stderr.write("evaluate: program not found: %s (build it or pass --program)\n" % args.program)
        return 2
    trials = load_trials(args.dataset)
    results = run_all(trials, args.dataset, methods, args.program, args.config,
                      shlex.split(args.paper_args), args.jobs, args.timeout)
    report = {"dataset": os.path.abspath(args.dataset), "methods": {}}
    for m in methods:
        s = summarize(trials, results[m])
        report["methods"][m] = s
        print_report(m if m != "paper" or not args.paper_args else "paper " + args.paper_args, s)
    if len(methods) > 1:
        sys.stdout.write("\n-- comparison (combined per subject, cm; on-spot detection) --\n")
        for m in methods:
            s = report["methods"][m]
            c = s["across_subjects"]["combined"]["error_cm"]
            d = s["detection"]["onspot"]
            sys.stdout.write("  %-10s MAE %s  ME %s  found %s %%  precision %s %%  walk false %d  missing %d\n" % (
                m, _mae(c), _me(c), _f(d["found_frac"] * 100 if d["found_frac"] is not None else None),
                _f(d["precision"] * 100 if d["precision"] is not None else None),
                s["detection"]["walk"]["false_flights"], s["n_missing"]))
    rc = 0
    if "gravscale" in methods:
        b = bars(report["methods"]["gravscale"])
        report["bars"] = b
        sys.stdout.write("\n-- bars (gravscale): %s --\n" % ("PASS" if b["ok"] else "MISS"))
        for k, c in b["checks"].items():
            sys.stdout.write("  %-18s %-8s limit %-5s %s\n" % (
                k, _f(c["value"], 3) if isinstance(c["value"], float) else c["value"],
                c["limit"], "ok" if c["ok"] else "MISS"))
        if args.bars and not b["ok"]:
            rc = 1
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump(report, f, indent=1, allow_nan=False)
            f.write("\n")
    if any(report["methods"][m]["n_failed"] for m in methods):
        sys.stderr.write("evaluate: some runs failed\n")
        rc = 2
    return rc


if __name__ == "__main__":
    sys.exit(main())
