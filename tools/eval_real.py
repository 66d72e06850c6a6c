#!/usr/bin/env python3
"""Run gravscale on every real recording in ../shared/data/real and print a table.

    python3 tools/eval_real.py [--program build/gravscale] [--shared ../shared]
                               [--only NAME[,NAME]] [--json OUT] [--jobs N]

Each clip is run as a user would run it (`gravscale video CLIP`, the ball or the
pose detector) and its result compared with the truth its SOURCE.txt states:
a size range, a jump's flight time and height, a consistency check (the juggling
balls' sizes agree) or "nothing may be reported". The table says per clip what
came out, what the truth is and whether it meets it. Exit status 0 always (a
report, not a test; the tests assert their own bars).
"""

import argparse
import concurrent.futures
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TOP = os.path.dirname(HERE)

# name, file (under data/real), detector, extra args, truth
#   truth kinds: ("size", lo_m, hi_m) the summary's size; ("none",) nothing accepted;
#   ("jump", flight_s, tol_s, jump_m, tol_m) the pose jump; ("agree", rel) the tracks' sizes agree;
#   ("reject_or", lo_m, hi_m) rejected, or else within the range; ("any",) robustness only;
#   ("arcs_agree", rel) two accepted flights or more, every two within rel and three combined SEs
CLIPS = [
    ("ameen", "bouncing_ball_ameen/bounceAmeen.avi", "ball", [], ("size", 0.0687 * 0.97, 0.0687 * 1.03)),
    ("kth_720p", "tennis_bounce_kth/single_ball_1-long_720p30.mp4", "ball", [], ("size", 0.0654 * 0.95, 0.0686 * 1.05)),
    ("kth_60fps_multi", "tennis_bounce_kth/balls_60fps_1_cut.mp4", "ball", [], ("size", 0.0654 * 0.95, 0.0686 * 1.05)),
    ("table_3ftstrip", "tennis_drop_table_3ftstrip/tennis_ball_reference.mp4", "ball", [], ("size", 0.0621, 0.0720)),
    ("basketball", "basketball_freethrow_sideon/FreeThrow.mp4", "ball", [], ("size", 0.220, 0.257)),
    ("redball_portrait", "redball_drop_bounce_portrait/RedBall.mp4", "ball", [], ("any",)),
    ("pinkball_portrait", "pinkball_toss_bounces_portrait/ball.mp4", "ball", [], ("arcs_agree", 0.08)),
    ("knobbyball", "knobbyball_vertical_toss_whiteboard/ball.MOV", "ball", [], ("any",)),
    ("juggling", "juggling_3balls_lowres/juggling_low_quality.mp4", "ball", [], ("agree", 0.05)),
    ("tilted_drop", "tennis_drop_blanket_portrait_tilted/h1_f1_r1.mp4", "ball", [], ("reject_or", 0.0654 * 0.95, 0.0686 * 1.05)),
    ("vtest_ball", "opencv_vtest/vtest_first15s_h264.mp4", "ball", [], ("none",)),
    ("vtest_pose", "opencv_vtest/vtest_first15s_h264.mp4", "pose", [], ("none",)),
    ("gym_cmj", "jumpvision_jumps/cmj_gym_handheld_30fps.mp4", "pose", [], ("jump", 0.789, 0.017, 0.7634, 0.02)),
]


def run_clip(program, shared, clip):
    name, rel, det, extra, truth = clip
    path = os.path.join(shared, "data", "real", rel)
    if not os.path.exists(path):
        return {"name": name, "missing": True}
    cmd = [program, "video", path, "--detector", det] + extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    events = []
    for line in p.stdout.splitlines():
        try:
            events.append(json.loads(line))
        except ValueError:
            pass
    jumps = [e for e in events if e.get("event") == "jump"]
    summaries = [e for e in events if e.get("event") == "summary"]
    return {"name": name, "rc": p.returncode, "stderr": p.stderr.strip()[-300:], "jumps": jumps,
            "summaries": summaries, "truth": truth, "detector": det}


def fmt_m(v, digits=4):
    return "null" if v is None else ("%.*f" % (digits, v))


def judge(r):
    """(result text, truth text, verdict) of one clip's run."""
    truth = r["truth"]
    acc = [j for j in r["jumps"] if j.get("accepted")]
    n = "%d/%d acc" % (len(acc), len(r["jumps"]))
    sizes = [s.get("height_m") for s in r["summaries"] if s.get("height_m") is not None]
    kind = truth[0]
    if kind == "none":
        return n, "nothing", "ok" if not acc else "FALSE"
    if kind == "any":
        return "%s, size %s" % (n, ",".join(fmt_m(s) for s in sizes) or "null"), "robustness", "-"
    if kind == "size":
        lo, hi = truth[1], truth[2]
        s = sizes[0] if sizes else None
        ok = s is not None and lo <= s <= hi
        return "%s, size %s" % (n, fmt_m(s)), "%.4f-%.4f" % (lo, hi), "ok" if ok else "MISS"
    if kind == "reject_or":
        lo, hi = truth[1], truth[2]
        s = sizes[0] if sizes else None
        ok = s is None or lo <= s <= hi
        return "%s, size %s" % (n, fmt_m(s)), "rejected or %.4f-%.4f" % (lo, hi), "ok" if ok else "WRONG"
    if kind == "agree":
        ok = len(sizes) >= 2 and max(sizes) / min(sizes) - 1.0 <= truth[1]
        return "%s, sizes %s" % (n, ",".join(fmt_m(s) for s in sizes) or "null"), \
            "sizes agree %d %%" % round(100 * truth[1]), "ok" if ok else "MISS"
    if kind == "arcs_agree":
        fl = [(j["height_m"], j.get("height_se_m") or 0.0) for j in acc if j.get("height_m") is not None]
        ok = len(fl) >= 2 and all(abs(a - b) <= 3.0 * (sa * sa + sb * sb) ** 0.5 and abs(a / b - 1.0) <= truth[1]
                                  for i, (a, sa) in enumerate(fl) for (b, sb) in fl[i + 1:])
        return "%s, flights %s" % (n, ",".join(fmt_m(a) for a, _ in fl) or "null"), \
            "flights agree %d %%, 3 SE" % round(100 * truth[1]), "ok" if ok else "MISS"
    if kind == "jump":
        ft, ft_tol, jh, jh_tol = truth[1:]
        js = r["jumps"]
        if not js:
            return "no flight", "T %.3f s, h %.4f m" % (ft, jh), "MISS"
        j = max(js, key=lambda e: e.get("flight_time_s") or 0.0)
        t = j.get("flight_time_s")
        h = j.get("jump_height_m")
        ok = t is not None and h is not None and abs(t - ft) <= ft_tol and abs(h - jh) <= jh_tol
        w = ",".join(j.get("warnings") or [])
        return ("T %s s, h %s m, stature %s%s" % (fmt_m(t, 3), fmt_m(h), fmt_m(j.get("height_m"), 3),
                                                 (" [" + w + "]") if w else "")), \
            "T %.3f±%.3f, h %.4f±%.2f" % (ft, ft_tol, jh, jh_tol), "ok" if ok else "MISS"
    return n, "?", "?"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--program", default=os.environ.get("GS_PROGRAM", os.path.join(TOP, "build", "gravscale")))
    ap.add_argument("--shared", default=os.environ.get("GS_SHARED_DIR", os.path.join(TOP, "..", "shared")))
    ap.add_argument("--only", default="", help="comma-separated clip names")
    ap.add_argument("--json", help="write every run's events here")
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args(argv)
    clips = CLIPS
    if a.only:
        want = set(a.only.split(","))
        clips = [c for c in CLIPS if c[0] in want]
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
        runs = list(ex.map(lambda c: run_clip(a.program, a.shared, c), clips))
    print("%-18s %-6s %-58s %-26s %s" % ("clip", "det", "result", "truth", "verdict"))
    for r in runs:
        if r.get("missing"):
            print("%-18s %-6s %-58s" % (r["name"], "", "(clip absent)"))
            continue
        res, tr, v = judge(r)
        if r["rc"] != 0:
            res = "exit %d: %s" % (r["rc"], r["stderr"][-50:])
            v = "ERROR"
        print("%-18s %-6s %-58s %-26s %s" % (r["name"], r["detector"], res, tr, v))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(runs, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
