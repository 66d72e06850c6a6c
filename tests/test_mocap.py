"""Real people's jumps against their force plates: the motion-capture drop jumps of
../shared/data/mocap/ filmed by the virtual camera (tools/film_mocap.py) from the front
and the side, at 4 and 7 m, 30 and 60 fps, in both keypoint layouts, and replayed
through the built program. Flight time, jump height (g T^2 / 8) and q against the
plates' truth; every flight found; the step off the box never reported as a jump.
Skipped when the recordings are absent. Also: film_mocap's bad-input errors."""

import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import eval_mocap  # noqa: E402

PROGRAM = os.environ.get("GS_PROGRAM", os.path.join(ROOT, "build", "gravscale"))
SHARED = os.environ.get("GS_SHARED_DIR", os.path.join(ROOT, "..", "shared"))
MOCAP = os.path.join(SHARED, "data", "mocap", "opencap_s4")
FILM = os.path.join(ROOT, "tools", "film_mocap.py")

# per layout: flight time MAE (s), jump height MAE (m), |mean| jump height error (m), q MAE (relative)
BARS = {"blazepose33": (0.008, 0.010, 0.005, 0.010), "coco17": (0.015, 0.015, 0.008, 0.012)}


def mae(v):
    return sum(abs(x) for x in v) / len(v)


@unittest.skipUnless(os.path.isdir(MOCAP), "the motion-capture recordings are absent")
class MocapJumps(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="gs_test_mocap_")
        trials = eval_mocap.trials_in([MOCAP])
        jobs = [(PROGRAM, trc, grf, layout, view, dist, fps, 1, "medium", False, cls.tmp)
                for layout in BARS for trc, grf in trials for view in ("front", "side")
                for dist in (4.0, 7.0) for fps in (30.0, 60.0)]
        import concurrent.futures
        with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 2) as ex:
            cls.runs = list(ex.map(eval_mocap.run_one, jobs))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_runs_clean(self):
        self.assertGreaterEqual(len(self.runs), 32)
        for r in self.runs:
            self.assertEqual(r["rc"], 0, r["stderr"])

    def test_against_the_plates(self):
        for layout, (bar_t, bar_h, bar_me, bar_q) in BARS.items():
            ft, jh, q = [], [], []
            n_fl = n_found = n_false = 0
            for r in self.runs:
                if r["layout"] != layout:
                    continue
                pairs, false, _ = eval_mocap.match(r)
                n_false += len(false)
                for fl, j in pairs:
                    n_fl += 1
                    if j is None or not j["accepted"]:
                        continue
                    n_found += 1
                    ft.append(j["flight_time_s"] - fl["flight_time_s"])
                    jh.append(j["jump_height_m"] - fl["jump_height_m"])
                    # the flight time and its jump height are one measure: g T^2 / 8
                    self.assertAlmostEqual(j["jump_height_m"], 9.81 * j["flight_time_s"] ** 2 / 8, delta=0.002)
                    if j["q_m_per_px"] is not None:
                        q.append(j["q_m_per_px"] / fl["q_m_per_px"] - 1.0)
            print("%s: %d/%d found, %d false; flight time MAE %.1f ms, jump height MAE %.2f cm (ME %+.2f), "
                  "q MAE %.2f %%" % (layout, n_found, n_fl, n_false, 1e3 * mae(ft), 1e2 * mae(jh),
                                     1e2 * sum(jh) / len(jh), 1e2 * mae(q)))
            self.assertGreaterEqual(n_found, 0.95 * n_fl, layout)
            self.assertEqual(n_false, 0, "%s: the step off the box or another motion reported as a jump" % layout)
            self.assertLess(mae(ft), bar_t, layout)
            self.assertLess(mae(jh), bar_h, layout)
            self.assertLess(abs(sum(jh) / len(jh)), bar_me, layout)
            self.assertGreaterEqual(len(q), 0.9 * n_found, layout)
            self.assertLess(mae(q), bar_q, layout)

    def test_falls_are_rejected(self):
        # every step off the box that the program saw as a flight is rejected as a fall
        seen = 0
        for r in self.runs:
            for fall in r["truth"]["falls"]:
                for j in r["jumps"]:
                    if j["t_land_s"] is not None and abs(j["t_land_s"] - fall["t_land_s"]) < 0.1:
                        seen += 1
                        self.assertFalse(j["accepted"], (r["trial"], r["layout"], r["view"], j))
        print("steps off the box seen as flights: %d, all rejected" % seen)

    def test_rebound_contact_time(self):
        # the drop jump's ground contact before the rebound, against the plates
        err = []
        for r in self.runs:
            pairs, _, _ = eval_mocap.match(r)
            for fl, j in pairs:
                if j is not None and j["accepted"] and fl.get("contact_time_s") is not None:
                    self.assertIsNotNone(j["contact_time_s"], (r["trial"], r["layout"], r["view"]))
                    err.append(j["contact_time_s"] - fl["contact_time_s"])
                    self.assertAlmostEqual(j["rsi"], j["jump_height_m"] / j["contact_time_s"], delta=0.01)
        self.assertGreater(len(err), 0)
        print("contact time: MAE %.1f ms over %d rebounds" % (1e3 * mae(err), len(err)))
        self.assertLess(mae(err), 0.04)


@unittest.skipUnless(os.path.isdir(MOCAP), "the motion-capture recordings are absent")
class FilmBadInput(unittest.TestCase):
    def film(self, trc, grf):
        out = os.path.join(self.tmp, "out.csv")
        p = subprocess.run([sys.executable, FILM, trc, "--grf", grf, "--out", out, "--stature", "1.7"],
                           capture_output=True, text=True, timeout=120)
        return p, out

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="gs_test_film_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def corrupt(self, src, line_no, field_no, name):
        with open(src) as f:
            lines = f.read().split("\n")
        cols = lines[line_no - 1].split("\t")
        cols[field_no] = "abc"
        lines[line_no - 1] = "\t".join(cols)
        dst = os.path.join(self.tmp, name)
        with open(dst, "w") as f:
            f.write("\n".join(lines))
        return dst

    def test_bad_marker_value(self):
        trc = self.corrupt(os.path.join(MOCAP, "DJ1.trc"), 12, 2, "bad.trc")
        p, out = self.film(trc, os.path.join(MOCAP, "DJ1_grf.mot"))
        self.assertEqual(p.returncode, 1)
        self.assertIn("bad.trc:12: field 'C7'", p.stderr)
        self.assertFalse(os.path.exists(out) or os.path.exists(out[:-4] + ".truth.json"), "nothing half-written")

    def test_bad_force_value(self):
        mot = self.corrupt(os.path.join(MOCAP, "DJ1_grf.mot"), 20, 2, "bad_grf.mot")
        p, out = self.film(os.path.join(MOCAP, "DJ1.trc"), mot)
        self.assertEqual(p.returncode, 1)
        self.assertIn("bad_grf.mot:20: field 'ground_force_1_vy'", p.stderr)
        self.assertFalse(os.path.exists(out))

    def test_missing_file(self):
        p, out = self.film(os.path.join(self.tmp, "none.trc"), os.path.join(MOCAP, "DJ1_grf.mot"))
        self.assertEqual(p.returncode, 1)
        self.assertIn("none.trc", p.stderr)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main(verbosity=2)
