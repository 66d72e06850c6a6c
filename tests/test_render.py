#!/usr/bin/env python3
"""test_render.py - tools/render_ball's truth against physics and projection
computed here independently: a small clip without drag (free fall and bounces
are then closed-form), one with drag (it must fall more slowly), the sphere's
image size against f*D/Z, and the AVI's frame count."""
import json
import math
import os
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_PROGRAM = os.environ.get("GS_PROGRAM", os.path.join(ROOT, "build", "gravscale"))
RENDER = os.path.join(os.path.dirname(_PROGRAM), "render_ball")
G = 9.81
FAILS = []


def check(cond, msg):
    if not cond:
        FAILS.append(msg)
        print("FAIL:", msg)


def render(d, name, extra):
    out = os.path.join(d, name + ".avi")
    args = [RENDER, "--out", out, "--width", "320", "--height", "240", "--fps", "60", "--duration-s", "1.4",
            "--dist-m", "1.5", "--x-m", "0.3", "--drop-m", "0.5", "--release-s", "0.1", "--hfov-deg", "65",
            "--floor-frac", "0.9"] + extra
    r = subprocess.run(args, capture_output=True, text=True)
    check(r.returncode == 0, "%s: exit %d %s" % (name, r.returncode, r.stderr))
    truth = json.load(open(os.path.join(d, name + ".json")))
    rows = []
    with open(os.path.join(d, name + ".frames.csv")) as f:
        keys = f.readline().strip().split(",")
        for line in f:
            rows.append(dict(zip(keys, map(float, line.split(",")))))
    return out, truth, rows


def avi_frames(path):
    with open(path, "rb") as f:
        head = f.read(64)
    if head[0:4] != b"RIFF" or head[8:12] != b"AVI ":
        return None
    i = head.find(b"avih")
    return struct.unpack("<I", head[i + 8 + 16:i + 8 + 20])[0]  # dwTotalFrames


def main():
    if not os.access(RENDER, os.X_OK):
        print("render_ball not built (no OpenCV): skipped")
        return 0
    with tempfile.TemporaryDirectory() as d:
        clip, t, rows = render(d, "nodrag", ["--drag", "0"])
        _, td, _ = render(d, "drag", ["--drag", "1"])
        # camera from the field of view
        f = 160.0 / math.tan(math.radians(32.5))
        check(abs(t["camera"]["f_px"] - f) < 1e-6 * f, "f_px %g, expected %g" % (t["camera"]["f_px"], f))
        check(avi_frames(clip) == t["frames"] == 84, "frame count: avi %s, truth %s" % (avi_frames(clip), t["frames"]))
        # no drag: the first impact after sqrt(2 h / g), the next after 2 e v / g
        r = 0.5 * t["diameter_m"]
        t1 = 0.1 + math.sqrt(2 * 0.5 / G)
        v1 = 0.72 * math.sqrt(2 * G * 0.5)
        b = t["bounces_s"]
        check(abs(b[0] - t1) < 2e-4, "first impact %.5f s, expected %.5f" % (b[0], t1))
        check(abs(b[1] - (t1 + 2 * v1 / G)) < 3e-4, "second impact %.5f s, expected %.5f" % (b[1], t1 + 2 * v1 / G))
        check(abs(t["flights"][1]["apex_bottom_m"] - 0.5 * 0.72 ** 2) < 2e-3,
              "first bounce apex %.4f m, expected %.4f" % (t["flights"][1]["apex_bottom_m"], 0.5 * 0.72 ** 2))
        # with drag the ball falls more slowly and rises less
        check(td["bounces_s"][0] > b[0] + 1e-4, "drag: impact %.5f not later than %.5f" % (td["bounces_s"][0], b[0]))
        check(td["flights"][1]["apex_bottom_m"] < t["flights"][1]["apex_bottom_m"] - 2e-3, "drag: bounce not lower")
        # the held ball's image: projection of its centre, minor axis ~ f D / Z
        h = t["camera"]["height_m"]
        yc = 0.5 + r
        row = rows[0]
        d3 = math.sqrt(0.3 ** 2 + (h - yc) ** 2 + 1.5 ** 2)
        sa = r / d3
        ct = 1.5 / d3
        minor = 2 * f * sa / math.sqrt(ct * ct - sa * sa)
        check(abs(row["minor_px"] - minor) < 1e-3, "minor axis %.4f px, expected %.4f" % (row["minor_px"], minor))
        check(abs(row["minor_px"] / (f * t["diameter_m"] / 1.5) - 1) < 0.005, "minor axis vs f D / Z")
        check(row["major_px"] > row["minor_px"], "off-axis sphere: major axis > minor")
        # image of the centre (the ellipse's centre lies slightly outward of it)
        u = 160 + f * 0.3 / 1.5
        v = 120 + f * (h - yc) / 1.5
        check(abs(row["u_px"] - u) < 0.2 and abs(row["v_px"] - v) < 0.2,
              "held centre (%.2f, %.2f), expected about (%.2f, %.2f)" % (row["u_px"], row["v_px"], u, v))
        # no drag, level camera, fronto-parallel fall: q from the true centres is exact
        for fl in t["flights"]:
            if fl["n_frames"] >= 8:
                e = fl["q_fit_true_m_per_px"] / fl["q_true_m_per_px"] - 1
                check(abs(e) < 0.003, "flight %d: q from the true centres off by %.3f %%" % (fl["index"], 100 * e))
        # with drag the drop (falling only) gives a larger q
        fd = td["flights"][0]
        if fd["n_frames"] >= 8:
            check(fd["q_fit_true_m_per_px"] > fd["q_true_m_per_px"], "drag: the drop's q is not larger")
        # bad options are usage errors
        r2 = subprocess.run([RENDER, "--out", os.path.join(d, "x.avi"), "--dist-m", "abc"], capture_output=True,
                            text=True)
        check(r2.returncode == 2 and "--dist-m" in r2.stderr, "bad value: exit %d %s" % (r2.returncode, r2.stderr))
    print("%d failure(s)" % len(FAILS))
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
