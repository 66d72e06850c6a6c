"""Replay of the bundled recorded track (tests/data/sample_jumps.csv, simulated
with stated truth in sample_jumps.truth.json) through the built program:
flights, times and heights against the truth, and the same answer from the
AlphaPose form of the same track. Run from the repository root; the program's
path comes from GS_PROGRAM (CTest sets it) or defaults to build/gravscale."""

import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROGRAM = os.environ.get("GS_PROGRAM", os.path.join(ROOT, "build", "gravscale"))
CSV = os.path.join(ROOT, "tests", "data", "sample_jumps.csv")
TRUTH = os.path.join(ROOT, "tests", "data", "sample_jumps.truth.json")
FRAME_S = 1.0 / 30.0


def replay(*args):
    out = subprocess.run([PROGRAM, "replay", *args], capture_output=True, text=True, timeout=60)
    if out.returncode != 0:
        raise AssertionError("replay failed (%d): %s" % (out.returncode, out.stderr))
    return [json.loads(line) for line in out.stdout.splitlines()]


class SampleReplay(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(TRUTH) as fh:
            cls.truth = json.load(fh)
        cls.events = replay("--keypoints", CSV)

    def jumps(self):
        return [e for e in self.events if e["event"] == "jump"]

    def test_stream_shape(self):
        kinds = [e["event"] for e in self.events]
        self.assertEqual(kinds[0], "start")
        self.assertEqual(kinds[-1], "summary")
        self.assertEqual(kinds.count("summary"), 1)
        # a height event follows every accepted jump
        for i, e in enumerate(self.events):
            if e["event"] == "jump" and e["accepted"]:
                self.assertEqual(self.events[i + 1]["event"], "height")

    def test_every_flight_found_with_its_times(self):
        jumps = [j for j in self.jumps() if j["accepted"]]
        self.assertEqual(len(jumps), len(self.truth["flights"]))
        g = 9.81
        for j, fl in zip(jumps, self.truth["flights"]):
            # the feet's times (COCO-17: the ankles), within two frames of the simulated toe-off and touch-down
            self.assertAlmostEqual(j["t_takeoff_s"], fl["t_takeoff_s"], delta=2 * FRAME_S)
            self.assertAlmostEqual(j["t_land_s"], fl["t_land_s"], delta=2 * FRAME_S)
            self.assertAlmostEqual(j["flight_time_s"], fl["flight_time_s"], delta=2 * FRAME_S)
            # g T^2 / 8 from the flight time, within the 2-frame error of T (about 4 cm at T = 0.55 s)
            self.assertAlmostEqual(j["jump_height_m"], g * j["flight_time_s"] ** 2 / 8, places=3)
            self.assertAlmostEqual(j["jump_height_m"], fl["jump_height_m"], delta=0.05)
            # v0 = g (t_apex - t_takeoff): a frame of take-off error is 0.33 m/s, the rise follows
            self.assertAlmostEqual(j["takeoff_velocity_m_s"], fl["takeoff_velocity_m_s"], delta=0.35)
            self.assertAlmostEqual(j["com_rise_m"], j["takeoff_velocity_m_s"] ** 2 / (2 * g), places=3)
            self.assertAlmostEqual(j["com_rise_m"], fl["com_rise_m"], delta=0.1)
            # each flight's own height within 5 % of the stature
            self.assertAlmostEqual(j["height_m"], self.truth["stature_m"],
                                   delta=0.05 * self.truth["stature_m"])
            self.assertIsNone(j["reason"])
            self.assertIsNone(j["contact_time_s"])  # standing between the jumps: no rebound

    def test_summary_against_stature(self):
        s = self.events[-1]
        stature = self.truth["stature_m"]
        self.assertEqual(s["n_jumps"], 3)
        self.assertAlmostEqual(s["height_m"], stature, delta=0.04 * stature)
        lo, hi = s["ci95_m"]
        self.assertLess(lo, stature)
        self.assertGreater(hi, stature)

    def test_alphapose_form_gives_the_same_answer(self):
        # write the CSV as an AlphaPose result list (frame index = round(t * 30))
        with open(CSV) as fh:
            rows = fh.read().splitlines()
        header = rows[0].split(",")
        self.assertEqual(header[0], "t")
        results = []
        for line in rows[1:]:
            f = line.split(",")
            idx = round(float(f[0]) * 30.0)
            kps = []
            for k in range(17):
                x, y, c = f[1 + 3 * k: 4 + 3 * k]
                kps += [float(x) if x else 0.0, float(y) if y else 0.0, float(c)]
            results.append({"image_id": "%06d.jpg" % idx, "category_id": 1,
                            "keypoints": kps, "score": 2.5, "idx": 0})
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "sample.alphapose.json")
            with open(path, "w") as fh:
                json.dump(results, fh)
            ap = replay("--keypoints", path, "--format", "alphapose", "--fps", "30")
        # times differ only by the CSV's 6-decimal rounding of k/30
        csv_jumps = self.jumps()
        ap_jumps = [j for j in ap if j["event"] == "jump"]
        self.assertEqual(len(csv_jumps), len(ap_jumps))
        for a, b in zip(csv_jumps, ap_jumps):
            self.assertAlmostEqual(a["t_takeoff_s"], b["t_takeoff_s"], delta=0.002)
            self.assertAlmostEqual(a["height_m"], b["height_m"], delta=0.002)
        self.assertAlmostEqual(ap[-1]["height_m"], self.events[-1]["height_m"], delta=0.002)

    def test_nmea_lines_carry_the_same_numbers(self):
        out = subprocess.run([PROGRAM, "replay", "--keypoints", CSV, "--output-format", "nmea"],
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.splitlines()
        self.assertTrue(lines[-1].startswith("$GSSUM,"))
        for line in lines:
            self.assertLessEqual(len(line) + 2, 82)
            body, cs = line[1:].split("*")
            x = 0
            for ch in body:
                x ^= ord(ch)
            self.assertEqual("%02X" % x, cs)
        summary = lines[-1][1:].split("*")[0].split(",")
        self.assertAlmostEqual(float(summary[1]), self.events[-1]["height_m"], places=3)


if __name__ == "__main__":
    unittest.main(verbosity=2)
