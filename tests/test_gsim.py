#!/usr/bin/env python3
"""Physics and format tests of the synthetic jump generator (tools/gsim)."""

import csv
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))

from gsim import anthro, body, builders, dataset, detector  # noqa: E402
from gsim.camera import Camera  # noqa: E402
from gsim.motion import Flight, G, Infeasible  # noqa: E402


def build(jtype, seed, stature=1.75):
    """A finished motion of one type (retrying draws the generator would also reject)."""
    for attempt in range(60):
        rng = random.Random("test/%s/%d/%d" % (jtype, seed, attempt))
        sub = anthro.make_subject(random.Random("sub/%d" % seed), "S01", stature)
        try:
            return dataset.build_motion(sub, rng, jtype, 4.0), sub
        except Infeasible:
            continue
    raise RuntimeError("no feasible %s motion" % jtype)


def seg_com(m, t):
    """Whole-body COM summed here from the segment masses and segment COMs."""
    _, _, _, segs = m.state(t, want_segs=True)
    tot = sum(w for _, w, _ in segs)
    return tuple(sum(w * c[k] for _, w, c in segs) / tot for k in range(3))


def polyfit2(ts, zs):
    """Least-squares z = a + b t + c t^2 on centred time; returns (a, b, c)."""
    tm = sum(ts) / len(ts)
    x = [t - tm for t in ts]
    S = [sum(v ** k for v in x) for k in range(5)]
    r = [sum(z * v ** k for z, v in zip(zs, x)) for k in range(3)]
    A = [[S[0], S[1], S[2]], [S[1], S[2], S[3]], [S[2], S[3], S[4]]]
    # Gaussian elimination with partial pivoting
    M = [A[i] + [r[i]] for i in range(3)]
    for i in range(3):
        p = max(range(i, 3), key=lambda k: abs(M[k][i]))
        M[i], M[p] = M[p], M[i]
        for k in range(i + 1, 3):
            f = M[k][i] / M[i][i]
            M[k] = [M[k][j] - f * M[i][j] for j in range(4)]
    c = [0.0] * 3
    for i in (2, 1, 0):
        c[i] = (M[i][3] - sum(M[i][j] * c[j] for j in range(i + 1, 3))) / M[i][i]
    return c


class Motions(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.m = {}
        for jt, seed in (("high", 1), ("low", 2), ("funny", 3), ("jack", 4), ("run", 5),
                         ("walk", 6), ("walk", 7)):
            cls.m[(jt, seed)] = build(jt, seed)

    def flights(self):
        for key, (b, sub) in self.m.items():
            for ph in b.m.phases:
                if isinstance(ph, Flight):
                    yield key, b, ph

    def test_flight_com_is_ballistic(self):
        n = 0
        for key, b, fl in self.flights():
            ts, zs, xs, ys = [], [], [], []
            t = fl.t0 + 1e-3
            while t < fl.t1 - 1e-3:
                c = seg_com(b.m, t)
                ts.append(t)
                xs.append(c[0])
                ys.append(c[1])
                zs.append(c[2])
                t += 1e-3
            a = 2 * polyfit2(ts, zs)[2]
            self.assertLess(abs(-a - 9.81) / 9.81, 1e-9, "%s: a=%r" % (key, a))
            for hs in (xs, ys):
                self.assertLess(abs(polyfit2(ts, hs)[2]), 1e-8, key)   # constant horizontal speed
            n += 1
        self.assertGreaterEqual(n, 10)

    def test_velocity_continuous_at_events(self):
        h = 2e-5
        for key, b, fl in self.flights():
            m = b.m
            for te in (fl.t0, fl.t1):
                cl = [seg_com(m, te - k * h) for k in (1, 2, 3)]
                cr = [seg_com(m, te + k * h) for k in (1, 2, 3)]
                for k in range(3):
                    vl = (3 * cl[0][k] - 4 * cl[1][k] + cl[2][k]) / (2 * h)
                    vr = (-3 * cr[0][k] + 4 * cr[1][k] - cr[2][k]) / (2 * h)
                    self.assertLess(abs(vl - vr), 3e-3, "%s t=%.4f axis %d: %g vs %g"
                                    % (key, te, k, vl, vr))
            # stated take-off speed equals the COM's vertical speed at take-off
            rec = [f for f in b.flights if abs(f["t_takeoff_s"] - fl.t0) < 1e-12][0]
            self.assertAlmostEqual(rec["takeoff_velocity_m_s"], fl.v0[2], places=9)
            self.assertAlmostEqual(rec["t_land_s"], fl.t1, places=12)
            self.assertAlmostEqual(rec["com_rise_m"], fl.v0[2] ** 2 / (2 * G), places=12)
            self.assertAlmostEqual(rec["jump_height_m"], G * (fl.t1 - fl.t0) ** 2 / 8, places=12)

    def test_feet_on_floor_in_stance_and_above_in_flight(self):
        for key, (b, sub) in self.m.items():
            m = b.m
            T = b.t
            for i in range(400):
                t = T * (i + 0.5) / 400
                ph = m.phase_at(t)
                pts = m.state(t)[0]
                feet = {n: pts[n] for n in ("l_heel", "l_ball", "r_heel", "r_ball")}
                low = min(v[2] for v in feet.values())
                if isinstance(ph, Flight):
                    self.assertGreater(low, -1e-3, "%s flight t=%.3f" % (key, t))
                    continue
                if ph.walk:
                    # walking keeps its lowest foot point (toes included) on the floor
                    low = min(pts[n][2] for n in ("l_heel", "l_ball", "l_toe", "r_heel",
                                                    "r_ball", "r_toe"))
                    self.assertAlmostEqual(low, 0.0, places=9, msg="%s t=%.3f" % (key, t))
                    continue
                if ph.support == "both":  # standing and jumping: the toes are support points too
                    feet.update({n: pts[n] for n in ("l_toe", "r_toe")})
                sup = [n for n in feet if ph.support == "both" or n[0] == ph.support.lower()]
                self.assertAlmostEqual(min(feet[n][2] for n in sup), 0.0, places=9,
                                       msg="%s t=%.3f" % (key, t))
                self.assertGreater(low, -2e-3, "%s t=%.3f (free foot)" % (key, t))
                names = ("l_ball", "r_ball") if ph.support == "both" else \
                    (("l_" if ph.support == "L" else "r_") + "ball",)
                rx = sum(pts[n][0] for n in names) / len(names)
                ry = sum(pts[n][1] for n in names) / len(names)
                self.assertAlmostEqual(rx, ph.anchor[0], places=9)   # no sliding
                self.assertAlmostEqual(ry, ph.anchor[1], places=9)

    def test_standing_vertex_is_stature(self):
        for st in (1.50, 1.62, 1.75, 1.88, 1.95):
            for seed in range(5):
                sub = anthro.make_subject(random.Random(seed), "S", st)
                p = body.neutral_pose()
                pu, _, _ = body.upper(sub, p)
                pl, _, _ = body.leg(sub, p, "L", 0.0)
                self.assertAlmostEqual(pu["vertex"][2] - pl["l_heel"][2], st, places=12)
                self.assertAlmostEqual(sum(v * (2 if k in ("uarm", "farm", "hand", "thigh",
                                                           "shank", "foot") else 1)
                                           for k, v in sub.mass.items()), 1.0, places=12)
                f = sub.head["fractions"]
                self.assertTrue(0.925 <= f["eye"] <= 0.945, f)
                self.assertTrue(0.918 <= f["tragion"] <= 0.94, f)
                self.assertTrue(0.895 <= f["nose_tip"] <= 0.92, f)
                self.assertTrue(0.035 <= sub.L["ankle_h"] / st <= 0.046)
        # in the trials, quiet standing keeps the vertex within 1 cm of stature
        b, sub = self.m[("high", 1)]
        v = b.m.state(0.5)[0]["vertex"][2]
        self.assertLess(abs(v - sub.stature_m), 0.015)

    def test_walk_never_airborne(self):
        for key in (("walk", 6), ("walk", 7)):
            b, _ = self.m[key]
            m = b.m
            self.assertEqual(b.flights, [])
            dt = 1e-3
            n = int(b.t / dt)
            zs = [m.state(i * dt)[1][2] for i in range(n)]
            run = 0
            worst = 0
            for i in range(1, n - 1):
                a = (zs[i + 1] - 2 * zs[i] + zs[i - 1]) / (dt * dt)
                run = run + 1 if abs(a + G) < 0.5 else 0
                worst = max(worst, run)
            self.assertLess(worst * dt, 0.05, key)
            # the COM rises and falls by a few centimetres while walking
            mid = zs[int(0.45 * n):int(0.55 * n)]
            self.assertTrue(0.01 < max(mid) - min(mid) < 0.08, (key, max(mid) - min(mid)))

    def test_run_flights_short(self):
        b, _ = self.m[("run", 5)]
        self.assertGreaterEqual(len(b.flights), 2)
        for f in b.flights:
            self.assertTrue(0.09 <= f["flight_time_s"] <= 0.20, f)

    def test_jump_heights_in_type_ranges(self):
        lim = {"high": (0.25, 0.5), "low": (0.05, 0.15), "jack": (0.04, 0.12)}
        for (jt, seed), (b, _) in self.m.items():
            if jt in lim:
                for f in b.flights:
                    self.assertTrue(lim[jt][0] - 1e-9 <= f["com_rise_m"] <= lim[jt][1] + 1e-9)
        self.assertGreaterEqual(len(self.m[("jack", 4)][0].flights), 4)


class CameraTests(unittest.TestCase):
    CASES = [  # (point, expected u, v) for a level camera at (0, -4, 1.2), f from 60 deg
        ((0.0, 0.0, 1.2), 960.0, 540.0),
        ((0.5, 0.0, 1.2), None, 540.0),
        ((0.0, 0.0, 2.0), 960.0, None),
        ((0.3, 1.0, 0.4), None, None),
    ]

    def test_level_camera_hand_computation(self):
        cam = Camera(1920, 1080, 60.0, 4.0, 1.2, 1.2)
        f = 960.0 / math.tan(math.radians(30.0))
        for P, eu, ev in self.CASES:
            u, v = cam.project(P)
            depth = P[1] + 4.0
            self.assertAlmostEqual(u, 960.0 + f * P[0] / depth, places=9)
            self.assertAlmostEqual(v, 540.0 - f * (P[2] - 1.2) / depth, places=9)
            if eu is not None:
                self.assertAlmostEqual(u, eu, places=9)
            if ev is not None:
                self.assertAlmostEqual(v, ev, places=9)

    def test_pitched_and_rolled_camera(self):
        D, hc, ha = 7.0, 0.9, 1.3
        cam = Camera(1280, 720, 55.0, D, hc, ha, roll_deg=30.0)
        f = 640.0 / math.tan(math.radians(27.5))
        th = math.atan2(ha - hc, D)
        P = (0.4, 0.2, 1.7)
        dy, dz = P[1] + D, P[2] - hc
        zc = dy * math.cos(th) + dz * math.sin(th)
        yc = dy * math.sin(th) - dz * math.cos(th)     # image down
        xn, yn = P[0] / zc, yc / zc
        r = math.radians(30.0)
        xr = math.cos(r) * xn + math.sin(r) * yn
        yr = -math.sin(r) * xn + math.cos(r) * yn
        u, v = cam.project(P)
        self.assertAlmostEqual(u, 640 + f * xr, places=9)
        self.assertAlmostEqual(v, 360 + f * yr, places=9)
        self.assertAlmostEqual(cam.q_m_per_px, D / f, places=15)
        self.assertIsNone(cam.project((0.0, -8.0, 1.0)))   # behind the camera


class DetectorTests(unittest.TestCase):
    def test_noise_statistics(self):
        for level, k in (("low", 0.002), ("medium", 0.003), ("high", 0.004)):
            rng = random.Random(11)
            truth = [(500.0 + 20 * j, 300.0 + 15 * j) for j in range(17)]
            n = 3000
            dets, st = detector.detect(rng, [truth] * n, 30.0, 600.0, level, 1920, 1080)
            sig = k * 600.0
            errs, pairs, conf = [], [], []
            last = None
            for d in dets:
                if d is None:
                    last = None
                    continue
                e = d[5]
                if e is not None and abs(e[0] - truth[5][0]) < 6 * sig:
                    errs.append(e[0] - truth[5][0])
                    if last is not None:
                        pairs.append((last, e[0] - truth[5][0]))
                    last = e[0] - truth[5][0]
                else:
                    last = None
                for q in d:
                    if q is not None:
                        conf.append(q[2])
            sd = math.sqrt(sum(v * v for v in errs) / len(errs))
            self.assertLess(abs(sd / sig - 1), 0.12, (level, sd, sig))
            mx = sum(a for a, _ in pairs) / len(pairs)
            my = sum(b for _, b in pairs) / len(pairs)
            cov = sum((a - mx) * (b - my) for a, b in pairs) / len(pairs)
            rho = cov / (sd * sd)
            self.assertLess(abs(rho - detector.RHO), 0.1, (level, rho))
            r_out, r_swap, r_miss, r_drop = detector.RATES[level]
            self.assertLess(abs(st["dropped"] / n - r_drop), 0.006)
            self.assertLess(abs(st["outliers"] / (n * 17 * (1 - r_drop)) - r_out), 0.004)
            self.assertLess(abs(st["missed"] / (n * 17 * (1 - r_drop)) - r_miss), 0.004)
            self.assertTrue(min(conf) > 0 and max(conf) < 1)


class Files(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp()
        cls.dirs = []
        for i in range(2):
            d = os.path.join(cls.tmp, "run%d" % i)
            subprocess.check_call([sys.executable, os.path.join(ROOT, "tools", "gen_jumps.py"),
                                   "--out", d, "--subjects", "1", "--distances", "7",
                                   "--types", "high,jack", "--trials", "1", "--seed", "5",
                                   "--jobs", "1"], stdout=subprocess.DEVNULL)
            cls.dirs.append(d)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp)

    def test_deterministic_for_seed(self):
        a, b = self.dirs
        names = sorted(os.listdir(a))
        self.assertEqual(names, sorted(os.listdir(b)))
        for n in names:
            with open(os.path.join(a, n), "rb") as fa, open(os.path.join(b, n), "rb") as fb:
                self.assertEqual(fa.read(), fb.read(), n)

    def test_records_and_q(self):
        with open(os.path.join(self.dirs[0], "trials.jsonl")) as f:
            recs = [json.loads(line) for line in f]
        self.assertEqual(len(recs), 2)
        for r in recs:
            with open(os.path.join(self.dirs[0], r["trial"] + ".truth.json")) as f:
                tr = json.load(f)
            cam = tr["camera"]
            f_px = (r["width"] / 2) / math.tan(math.radians(cam["hfov_deg"]) / 2)
            self.assertAlmostEqual(r["q_m_per_px"], r["distance_m"] / f_px, places=15)
            self.assertTrue(r["flights"])
            for fl in r["flights"]:
                self.assertAlmostEqual(fl["flight_time_s"], fl["t_land_s"] - fl["t_takeoff_s"],
                                       places=5)

    def test_csv_and_alphapose_agree(self):
        for name in os.listdir(self.dirs[0]):
            if not name.endswith(".csv"):
                continue
            base = os.path.join(self.dirs[0], name[:-4])
            with open(base + ".csv") as f:
                rows = list(csv.reader(f))
            with open(base + ".alphapose.json") as f:
                ap = json.load(f)
            self.assertEqual(rows[0][0], "t")
            self.assertEqual(len(rows[0]), 52)
            self.assertEqual(len(rows) - 1, len(ap))
            fps = 30.0
            prev = -1
            for row, a in zip(rows[1:], ap):
                k = int(a["image_id"][:-4])
                self.assertGreater(k, prev)
                prev = k
                self.assertEqual(row[0], "%.6f" % (k / fps))
                self.assertEqual(a["category_id"], 1)
                self.assertEqual(len(a["keypoints"]), 51)
                for j in range(17):
                    x, y, c = row[1 + 3 * j: 4 + 3 * j]
                    ax, ay, ac = a["keypoints"][3 * j: 3 * j + 3]
                    if x == "":
                        self.assertEqual((y, float(c), ac), ("", 0.0, 0.0))
                    else:
                        self.assertEqual((float(x), float(y), float(c)), (ax, ay, ac))
                        self.assertGreater(float(c), 0.0)

    def test_cli_rejects_bad_input(self):
        for args in (["--types", "hop"], ["--fps", "25"], ["--res", "4k"], ["--noise", "extreme"]):
            p = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "gen_jumps.py"),
                                "--out", os.path.join(self.tmp, "bad")] + args,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            self.assertNotEqual(p.returncode, 0, args)


class Sample(unittest.TestCase):
    def test_bundled_sample(self):
        base = os.path.join(ROOT, "tests", "data", "sample_jumps")
        with open(base + ".truth.json") as f:
            tr = json.load(f)
        self.assertEqual(len(tr["flights"]), 3)
        with open(base + ".csv") as f:
            rows = list(csv.reader(f))
        self.assertEqual(len(rows[0]), 52)
        t_end = float(rows[-1][0])
        self.assertTrue(7.0 < t_end < 14.0, t_end)
        self.assertEqual(tr["fps"], 30.0)


if __name__ == "__main__":
    unittest.main()
