#!/usr/bin/env python3
"""tools/paper_numpy.py (the paper's method in NumPy, the batch peer of
tools/bench_paper.py) gives the jumps tools/paper_baseline.py gives: the same
events, intervals, sample counts and decisions, values to 1e-6 relative, on exact
parabolas (with q to 1e-6), on a clip with low-confidence glitches, dropped
frames and missing keypoints (empty fields), and on simulated trials of
tools/gen_jumps.py (noise, outliers, misses). Runs paper_numpy.py with Debian's
/usr/bin/python3 (numpy: python3-numpy, which tools/bootstrap.sh installs).
"""
import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NUMPY_PY = "/usr/bin/python3"


def _load(name, folder):
    spec = importlib.util.spec_from_file_location(name, os.path.join(TOP, folder, name + ".py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


pb = _load("paper_baseline", "tools")
fixtures = _load("test_evaluate", "tests")  # write_trial_csv, the rigid jumping skeleton


def numpy_events(path):
    p = subprocess.run([NUMPY_PY, os.path.join(TOP, "tools", "paper_numpy.py"), path],
                       capture_output=True, text=True, check=False)
    if p.returncode != 0:
        raise AssertionError("paper_numpy.py %s failed: %s" % (path, p.stderr))
    return [json.loads(line) for line in p.stdout.splitlines()]


def python_events(path):
    jumps, _ = pb.analyse(pb.read_keypoints_csv(path))
    return json.loads(json.dumps(pb.events(jumps, "paper")))


class SameAsTheBaseline(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        ok = subprocess.run([NUMPY_PY, "-c", "import numpy"], capture_output=True).returncode == 0
        self.assertTrue(ok, "%s cannot import numpy (apt-get install python3-numpy; tools/bootstrap.sh does)" % NUMPY_PY)

    def tearDown(self):
        self.tmp.cleanup()

    def same(self, path):
        a, b = python_events(path), numpy_events(path)
        self.assertEqual([e["event"] for e in a], [e["event"] for e in b], path)
        n_jumps = 0
        for x, y in zip(a, b):
            n_jumps += x["event"] == "jump"
            for k, vx in x.items():
                if k in ("version", "config"):
                    continue
                vy = y.get(k)
                if isinstance(vx, float) and isinstance(vy, (int, float)):
                    self.assertTrue(math.isclose(vx, vy, rel_tol=1e-6, abs_tol=1e-9), "%s %s: %r vs %r" % (path, k, vx, vy))
                else:
                    self.assertEqual(vx, vy, "%s %s" % (path, k))
        return n_jumps

    def test_exact_parabolas(self):
        for q, fps, flights in [(0.00281, 30.0, [(3.5, 3.95), (5.0, 5.52)]), (0.00150, 60.0, [(4.0, 4.61)]),
                                (0.00281, 25.0, [(3.5, 4.0), (5.0, 5.4), (6.5, 7.0)])]:
            path = os.path.join(self.tmp.name, "p.csv")
            fixtures.write_trial_csv(path, q, flights, fps=fps)
            self.assertGreaterEqual(self.same(path), len(flights))
            acc = [e for e in numpy_events(path) if e["event"] == "jump" and e["accepted"]]
            self.assertEqual(len(acc), len(flights))
            for e in acc:
                self.assertLess(abs(e["q_m_per_px"] / q - 1.0), 1e-6)

    def test_glitches_drops_and_missing_keypoints(self):
        path = os.path.join(self.tmp.name, "g.csv")
        fixtures.write_trial_csv(path, 0.003, [(3.5, 4.1), (6.0, 6.5)], bad_frames=(113, 20),
                                 drop_frames=(50, 51, 190))
        lines = open(path).read().splitlines()
        for k in (30, 31, 115, 200):  # the left wrist missing (empty x, y; c = 0), the nose too in one
            f = lines[k].split(",")
            f[1 + 3 * 9:1 + 3 * 9 + 3] = ["", "", "0"]
            if k == 200:
                f[1:4] = ["", "", "0"]
            lines[k] = ",".join(f)
        open(path, "w").write("\n".join(lines) + "\n")
        self.assertGreaterEqual(self.same(path), 2)

    def test_simulated_trials(self):
        out = os.path.join(self.tmp.name, "sim")
        subprocess.run([sys.executable, os.path.join(TOP, "tools", "gen_jumps.py"), "--out", out, "--subjects", "2",
                        "--types", "low,jack,walk", "--trials", "1", "--distances", "4", "--seed", "3", "--jobs", "1"],
                       check=True, capture_output=True)
        files = sorted(f for f in os.listdir(out) if f.endswith(".csv"))
        self.assertGreaterEqual(len(files), 6)
        jumps = sum(self.same(os.path.join(out, f)) for f in files)
        self.assertGreater(jumps, 0)


if __name__ == "__main__":
    unittest.main()
