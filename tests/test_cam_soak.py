"""A shortened soak run (tools/bench_soak.c): 5 minutes of synthetic jumping at
120 fps through `gravscale cam` as fast as it goes. Every true flight must be
emitted, the TCP client sink must carry the same bytes as the file sink, and
RSS must not grow by a megabyte. The full hour is a benchmark (docs/cam.md)."""
import os
import re
import subprocess
import sys
import unittest

PROGRAM = os.environ.get("GS_PROGRAM", "build/gravscale")
BENCH = os.path.join(os.path.dirname(PROGRAM), "bench_soak")


class SoakShort(unittest.TestCase):
    def test_five_minutes_at_120fps(self):
        if not os.path.exists(BENCH):
            self.skipTest("bench_soak not built")
        r = subprocess.run([BENCH, "--minutes", "5", "--program", PROGRAM],
                           capture_output=True, text=True, timeout=300)
        sys.stdout.write(r.stdout)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        m = re.search(r"true flights found (\d+) of (\d+)", r.stdout)
        self.assertIsNotNone(m, r.stdout)
        self.assertEqual(m.group(1), m.group(2))
        self.assertEqual(int(m.group(2)), 120)
        m = re.search(r"file (\d+) bytes, TCP (\d+) bytes", r.stdout)
        self.assertEqual(m.group(1), m.group(2))
        self.assertIn("bench_soak: OK", r.stdout)


if __name__ == "__main__":
    unittest.main()
