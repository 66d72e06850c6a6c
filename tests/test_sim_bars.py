"""The simulated people's bars on the held-out-like set (tools/gen_jumps.py, seed 7:
12 people, 4 and 7 m, countermovement, tucked and asymmetric jumps, jacks, walking and
lateral running) replayed through the built program and scored by tools/evaluate.py
against the simulator's exact truth: stature MAE <= 2.0 cm and |mean error| <= 1.0 cm
per person, no flight on a walk, and no accepted running stride more than 5 % off."""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROGRAM = os.environ.get("GS_PROGRAM", os.path.join(ROOT, "build", "gravscale"))
GEN = os.path.join(ROOT, "tools", "gen_jumps.py")
EVAL = os.path.join(ROOT, "tools", "evaluate.py")


class HeldOutLikeBars(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="gs_test_sim_")
        ds = os.path.join(cls.tmp, "ds")
        subprocess.run([sys.executable, GEN, "--preset", "heldout-like", "--out", ds, "--seed", "7",
                        "--jobs", "2"], check=True, stdout=subprocess.DEVNULL)
        out = os.path.join(cls.tmp, "ev.json")
        subprocess.run([sys.executable, EVAL, ds, "--program", PROGRAM, "--jobs", "2", "--json", out],
                       check=True, stdout=subprocess.DEVNULL)
        with open(out) as f:
            cls.ev = json.load(f)["methods"]["gravscale"]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_stature_per_person(self):
        e = self.ev["across_subjects"]["combined"]["error_cm"]
        self.assertEqual(e["n"], 12)
        self.assertLessEqual(e["mae"], 2.0)
        self.assertLessEqual(abs(e["me"]), 1.0)

    def test_every_trial_ran(self):
        self.assertEqual(self.ev["n_failed"], 0, self.ev["failures"])
        self.assertEqual(self.ev["n_trials"], 336)

    def test_nothing_on_walking(self):
        self.assertEqual(self.ev["detection"]["walk"]["false_flights"], 0)
        self.assertEqual(self.ev["n_walk_with_estimate"], 0)

    def test_running_strides_not_confidently_wrong(self):
        runs = [t for t in self.ev["trials"] if t["jump_type"] == "run"]
        self.assertEqual(len(runs), 24)
        for t in runs:
            if t["n_accepted"] and t["rel_error_pct"] is not None:
                self.assertLessEqual(abs(t["rel_error_pct"]), 5.0, t["trial"])


if __name__ == "__main__":
    unittest.main()
