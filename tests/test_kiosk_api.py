"""The kiosk's API and its rules (docs/kiosk.md), against a real `gravscale cam`
on the bundled sample (tests/data/sample_jumps.csv: three jumps of a 1.75 m
person) through the keypoints backend: athletes, visits and jumps as the events
said, CSV export, bad requests answered 4xx with nothing changed, no path
outside the page's files, Host and Origin checks on loopback, the token on
another address, and profile errors as one line with exit 2."""
import csv
import io
import os
import shutil
import sqlite3
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_kiosk import TOP, Daemon, request  # noqa: E402

CSV = os.path.join(TOP, "tests", "data", "sample_jumps.csv")
TOKEN = "s3cret-token-0123456789"


def profile(d, extra_kiosk="", name="p.cfg"):
    path = os.path.join(d, name)
    with open(path, "w") as f:
        f.write("[cam]\nbackend = keypoints\ndevice = %s\nrealtime = no\n"
                "[kiosk]\nport = 0\ndb = %s\nwait_for_athlete = yes\n%s"
                "[status]\ninterval_s = 0\n" % (CSV, os.path.join(d, "k.sqlite"), extra_kiosk))
    return path


class KioskApi(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="gs-kiosk-api-")
        cls.d = Daemon(["--config", profile(cls.dir)], cls.dir)
        cls.d.wait_url()
        cls.port = cls.d.port

    @classmethod
    def tearDownClass(cls):
        rc = cls.d.stop()
        shutil.rmtree(cls.dir, ignore_errors=True)
        assert rc == 0, rc

    def req(self, *a, **k):
        return request(self.port, *a, **k)

    def athletes(self):
        s, body, _ = self.req("GET", "/api/athletes")
        self.assertEqual(s, 200)
        return body

    def play(self):
        """Name the athlete: the held source plays; wait for its summary."""
        s, cur, _ = self.req("PUT", "/api/current", {"name": "  Ada Lovelace "})
        self.assertEqual(s, 200, cur)
        self.assertEqual(cur["name"], "Ada Lovelace")
        self.d.wait_stderr("the source ended", 60)
        return cur["id"]

    def test_1_waits_then_stores_what_the_events_said(self):
        s, st, _ = self.req("GET", "/api/state")
        self.assertEqual(s, 200)
        self.assertEqual(st["word"], "waiting")
        self.assertTrue(st["holding"])
        self.assertEqual([e["event"] for e in self.d.events()], ["start"],
                         "the source must not start before an athlete is named")
        aid = self.play()
        ev = self.d.events()
        jumps = [e for e in ev if e["event"] == "jump"]
        summ = [e for e in ev if e["event"] == "summary"][-1]
        self.assertEqual(len(jumps), summ["n_jumps"] + summ["n_rejected"], "every flight's event, a rejected one too")
        self.assertEqual(sum(j["accepted"] for j in jumps), 3, "the sample's three jumps")
        s, got, _ = self.req("GET", "/api/jumps?athlete=%d" % aid)
        self.assertEqual(s, 200)
        self.assertEqual(len(got), len(jumps))
        for e, j in zip(jumps, got):
            for k in ("jump_height_m", "flight_time_s", "takeoff_velocity_m_s", "height_m", "accepted", "reason"):
                self.assertEqual(e[k], j[k], k)
            self.assertEqual(j["event_json"], e, "the whole event is kept")
            self.assertEqual(j["athlete"], "Ada Lovelace")
        s, one, _ = self.req("GET", "/api/jumps/%d" % got[0]["id"])
        plot = one["track_json"]
        self.assertEqual(plot["units"], "m")
        self.assertGreater(len(plot["samples"]), 10)
        # the drawn parabola peaks at the COM's rise from take-off to the fit's apex, g/2 (t_apex - t_takeoff)^2
        j0 = jumps[0]
        g = j0["a_px_s2"] * j0["q_m_per_px"]
        self.assertAlmostEqual(plot["apex"][1], g / 2 * (j0["t_apex_s"] - j0["t_takeoff_s"]) ** 2, delta=0.002)
        self.assertAlmostEqual(plot["apex"][0], j0["t_apex_s"] - j0["t_takeoff_s"], delta=1e-3)
        s, sess, _ = self.req("GET", "/api/sessions?athlete=%d" % aid)
        self.assertEqual(len(sess), 1)
        end = [e for e in ev if e["event"] == "session" and e["state"] == "end"][0]
        self.assertEqual(sess[0]["n_jumps"], end["n_jumps"])
        self.assertAlmostEqual(sess[0]["stature_m"], end["stature_m"], places=4)
        self.assertEqual(sess[0]["end_reason"], "end_of_stream")
        self.assertAlmostEqual(sess[0]["best_jump_m"], end["best_jump_m"], places=4)
        self.assertAlmostEqual(sess[0]["mean_jump_m"], end["mean_jump_m"], places=4)
        s, day, _ = self.req("GET", "/api/sessions?day=" + sess[0]["day"])
        self.assertEqual([x["id"] for x in day], [sess[0]["id"]])
        s, a, _ = self.req("GET", "/api/athletes/%d" % aid)
        self.assertEqual(len(a["jumps"]), len(jumps))
        self.assertEqual(len(a["sessions"]), 1)
        # the live state after the end
        s, st, _ = self.req("GET", "/api/state")
        self.assertTrue(st["ended"])
        self.assertEqual(st["last_jump"]["event"], jumps[-1])
        self.assertEqual(len(st["jumps"]), len(jumps))
        best = max(j["jump_height_m"] for j in jumps if j["accepted"])
        self.assertEqual(st["best"]["jump_height_m"], best)
        # CSV: the same numbers, every event field as a column, a header
        s, text, h = self.req("GET", "/api/jumps.csv?athlete=%d" % aid)
        self.assertEqual(s, 200)
        self.assertTrue(h["content-type"].startswith("text/csv"))
        self.assertIn("attachment", h["content-disposition"])
        rows = list(csv.DictReader(io.StringIO(text)))
        self.assertEqual(len(rows), len(jumps))
        for e, r in zip(jumps, rows):
            self.assertAlmostEqual(float(r["jump_height_m"]), e["jump_height_m"], places=5)
            self.assertAlmostEqual(float(r["a_px_s2"]), e["a_px_s2"], delta=abs(e["a_px_s2"]) * 1e-5)
            self.assertEqual(r["athlete"], "Ada Lovelace")

    def test_2_bad_requests_change_nothing(self):
        before = self.athletes()
        db = os.path.join(self.dir, "k.sqlite")
        bad = [
            ("POST", "/api/athletes", {"name": ""}, None, 400),
            ("POST", "/api/athletes", {"name": "x" * 81}, None, 400),
            ("POST", "/api/athletes", {"name": "tab\there"}, None, 400),
            ("POST", "/api/athletes", {"name": 42}, None, 400),
            ("POST", "/api/athletes", {}, None, 400),
            ("POST", "/api/athletes", None, b'{"name": "\xff\xfe"}', 400),
            ("POST", "/api/athletes", None, b'{"name": ', 400),
            ("POST", "/api/athletes", None, b'["Ada"]', 400),
            ("PUT", "/api/current", {"athlete_id": 999999}, None, 404),
            ("PUT", "/api/current", {"athlete_id": "1"}, None, 400),
            ("PUT", "/api/current", {"nobody": 1}, None, 400),
            ("PATCH", "/api/athletes/999999", {"name": "Bob"}, None, 404),
            ("DELETE", "/api/sessions/999999", None, None, 404),
            ("DELETE", "/api/sessions/abc", None, None, 404),
            ("PATCH", "/api/sessions/1", {"athlete_id": "x"}, None, 400),
            ("PATCH", "/api/sessions/1", {}, None, 400),
            ("GET", "/api/sessions?day=2024-13-45", None, None, 400),
            ("GET", "/api/jumps?athlete=-1", None, None, 400),
            ("GET", "/api/jumps?session=1;DROP", None, None, 400),
            ("GET", "/api/nothing", None, None, 404),
            ("POST", "/api/state", {}, None, 405),
            ("DELETE", "/api/athletes", None, None, 405),
            ("OPTIONS", "/api/athletes", None, None, 405),
            ("POST", "/index.html", {}, None, 405),
        ]
        def dump():  # every row of every table (the daemon writes through the WAL)
            with sqlite3.connect("file:%s?mode=ro" % db, uri=True) as c:
                return [(t, c.execute("SELECT * FROM %s ORDER BY id" % t).fetchall())
                        for t in ("athletes", "runs", "sessions", "jumps")]
        rows = dump()
        for method, path, body, raw, want in bad:
            s, resp, _ = self.req(method, path, body, raw_body=raw,
                                  headers={"Content-Type": "application/json"} if raw else None)
            self.assertEqual(s, want, (method, path, body, raw, resp))
            if isinstance(resp, dict):
                self.assertIn("error", resp)
        s, resp, _ = self.req("POST", "/api/athletes", None, raw_body=b'{"name": "Eve"}',
                              headers={"Content-Type": "text/plain"})
        self.assertEqual(s, 415)
        s, resp, _ = self.req("POST", "/api/athletes", None, raw_body=b'{"name": "' + b"a" * 20000 + b'"}',
                              headers={"Content-Type": "application/json"})
        self.assertEqual(s, 413)
        self.assertEqual(self.athletes(), before)
        self.assertEqual(dump(), rows)

    def test_3_no_path_outside_the_page(self):
        for path in ["/../../../../etc/passwd", "/%2e%2e/%2e%2e/%2e%2e/etc/passwd", "/..%2f..%2fetc%2fpasswd",
                     "//etc/passwd", "/index.html/../../../etc/passwd", "/./kiosk.css/..%00/etc/passwd",
                     "/www/index.html", "/src/kiosk/www/index.html", "/k.sqlite", "/" + os.path.join(self.dir, "k.sqlite"),
                     "/./index.html", "/api/../index.html", "/%5c..%5c..%5cetc%5cpasswd", "/api/athletes/../../etc/passwd",
                     "/index.html?../../etc/passwd#x"]:
            s, body, _ = self.req("GET", path)
            self.assertEqual(s, 404 if "?" not in path else 200, path)
            self.assertNotIn("root:", str(body))
        for path, ctype in [("/", "text/html"), ("/index.html", "text/html"), ("/kiosk.js", "text/javascript"),
                            ("/kiosk.css", "text/css"), ("/history.html", "text/html"), ("/day.html", "text/html")]:
            s, body, h = self.req("GET", path)
            self.assertEqual(s, 200, path)
            self.assertTrue(h["content-type"].startswith(ctype), h)
            self.assertIn("default-src 'self'", h["content-security-policy"])

    def test_4_loopback_host_and_origin(self):
        before = self.athletes()
        # a page on another site that resolves its name to 127.0.0.1 (DNS rebinding)
        s, _, _ = self.req("GET", "/api/athletes", host="evil.example:%d" % self.port)
        self.assertEqual(s, 403)
        s, _, _ = self.req("POST", "/api/athletes", {"name": "Mallory"}, host="evil.example")
        self.assertEqual(s, 403)
        # a change sent by another site's page
        s, _, _ = self.req("POST", "/api/athletes", {"name": "Mallory"}, headers={"Origin": "http://evil.example"})
        self.assertEqual(s, 403)
        self.assertEqual(self.athletes(), before)
        s, _, _ = self.req("POST", "/api/athletes", {"name": "Mallory"},
                           headers={"Origin": "http://127.0.0.1:%d" % self.port}, host="localhost:%d" % self.port)
        self.assertEqual(s, 403, "the Origin is the page's own: it names the host the page came from")
        s, a, _ = self.req("POST", "/api/athletes", {"name": "Grace"},
                           headers={"Origin": "http://localhost:%d" % self.port}, host="localhost:%d" % self.port)
        self.assertIn(s, (200, 201), a)
        s, a2, _ = self.req("POST", "/api/athletes", {"name": "GRACE"})
        self.assertEqual(s, 200, "a name is one athlete whatever its case")
        self.assertEqual(a2["id"], a["id"])

    def test_5_rename_reassign_delete(self):
        s, g, _ = self.req("POST", "/api/athletes", {"name": "=cmd|' /C calc'!A0"})
        self.assertIn(s, (200, 201))
        s, sess, _ = self.req("GET", "/api/sessions")
        sid = sess[0]["id"]
        s, p, _ = self.req("PATCH", "/api/sessions/%d" % sid, {"athlete_id": g["id"]})
        self.assertEqual(s, 200, p)
        self.assertEqual(p["athlete_id"], g["id"])
        s, text, _ = self.req("GET", "/api/jumps.csv?session=%d" % sid)
        rows = list(csv.DictReader(io.StringIO(text)))
        self.assertEqual(rows[0]["athlete"], "'=cmd|' /C calc'!A0", "a formula is exported as text")
        s, r, _ = self.req("PATCH", "/api/athletes/%d" % g["id"], {"name": "Ada Lovelace"})
        self.assertEqual(s, 409, "two athletes of one name")
        s, r, _ = self.req("PATCH", "/api/athletes/%d" % g["id"], {"name": "Charles Babbage"})
        self.assertEqual(s, 200)
        self.assertEqual(r["name"], "Charles Babbage")
        s, r, _ = self.req("DELETE", "/api/sessions/%d" % sid)
        self.assertEqual(s, 200, r)
        s, r, _ = self.req("GET", "/api/sessions/%d" % sid)
        self.assertEqual(s, 404)
        s, r, _ = self.req("GET", "/api/jumps?session=%d" % sid)
        self.assertEqual(r, [], "a visit's jumps go with it")
        with sqlite3.connect(os.path.join(self.dir, "k.sqlite")) as c:
            self.assertEqual(c.execute("PRAGMA integrity_check").fetchone()[0], "ok")
            self.assertEqual(c.execute("PRAGMA journal_mode").fetchone()[0], "wal")
            self.assertEqual(c.execute("PRAGMA user_version").fetchone()[0], 1)


class KioskToken(unittest.TestCase):
    """bind = 0.0.0.0 (the test talks to it on 127.0.0.1 only): every change needs the token."""

    def run_daemon(self, open_read):
        d = tempfile.mkdtemp(prefix="gs-kiosk-token-")
        self.addCleanup(shutil.rmtree, d, True)
        extra = "bind = 0.0.0.0\ntoken = %s\nopen_read = %s\n" % (TOKEN, "yes" if open_read else "no")
        dm = Daemon(["--config", profile(d, extra)], d)
        self.addCleanup(dm.stop)
        dm.wait_url()
        return dm.port

    def test_closed_reads_and_changes(self):
        port = self.run_daemon(open_read=False)
        auth = {"Authorization": "Bearer " + TOKEN}
        for path in ("/api/state", "/api/athletes", "/api/jumps.csv", "/events"):
            s, body, _ = request(port, "GET", path)
            self.assertEqual(s, 401, path)
        s, _, _ = request(port, "GET", "/api/state", headers={"Authorization": "Bearer wrong-token-000000000"})
        self.assertEqual(s, 401)
        s, st, _ = request(port, "GET", "/api/state", headers=auth)
        self.assertEqual(s, 200)
        s, st, _ = request(port, "GET", "/api/state", headers={"Cookie": "a=b; gs_token=" + TOKEN})
        self.assertEqual(s, 200, "the page's cookie opens reads (EventSource sends no headers)")
        s, _, _ = request(port, "GET", "/index.html")
        self.assertEqual(s, 200, "the page's files hold no data")
        s, _, _ = request(port, "PUT", "/api/current", {"name": "Ada"}, headers={"Cookie": "gs_token=" + TOKEN})
        self.assertEqual(s, 401, "a change needs the header, not the cookie (another site's form carries cookies)")
        s, _, _ = request(port, "PUT", "/api/current", {"name": "Ada"})
        self.assertEqual(s, 401)
        s, a, _ = request(port, "GET", "/api/athletes", headers=auth)
        self.assertEqual(a, [], "nothing changed")
        s, cur, _ = request(port, "PUT", "/api/current", {"name": "Ada"}, headers=auth)
        self.assertEqual(s, 200, cur)

    def test_open_reads(self):
        port = self.run_daemon(open_read=True)
        s, _, _ = request(port, "GET", "/api/state")
        self.assertEqual(s, 200)
        s, _, _ = request(port, "POST", "/api/athletes", {"name": "Ada"})
        self.assertEqual(s, 401)
        s, _, _ = request(port, "DELETE", "/api/current")
        self.assertEqual(s, 401)
        s, a, _ = request(port, "GET", "/api/athletes")
        self.assertEqual(a, [])
        s, _, _ = request(port, "POST", "/api/athletes", {"name": "Ada"}, headers={"Authorization": "Bearer " + TOKEN})
        self.assertEqual(s, 201)


class KioskProfileErrors(unittest.TestCase):
    def one_line_exit_2(self, cfg_text, fragment, pre=None):
        d = tempfile.mkdtemp(prefix="gs-kiosk-bad-")
        self.addCleanup(shutil.rmtree, d, True)
        if pre:
            pre(d)
        p = os.path.join(d, "bad.cfg")
        with open(p, "w") as f:
            f.write(cfg_text.replace("DIR", d))
        dm = Daemon(["--config", p], d)
        try:
            rc = dm.proc.wait(30)
        finally:
            dm.out.close()
            dm.err.close()
        err = dm.stderr()
        self.assertEqual(rc, 2, err)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertIn(fragment, err)
        self.assertIn("bad.cfg", err)
        with open(dm.out_path) as f:
            self.assertEqual(f.read(), "", "nothing half-written")

    def test_profile_errors(self):
        base = "[cam]\nbackend = keypoints\ndevice = %s\n" % CSV
        self.one_line_exit_2(base + "[kiosk]\nbind = 0.0.0.0\n", "[kiosk] key 'token'")
        self.one_line_exit_2(base + "[kiosk]\ntoken = short\n", "[kiosk] key 'token'")
        self.one_line_exit_2(base + "[kiosk]\nbind = localhost\n", "[kiosk] key 'bind'")
        self.one_line_exit_2(base + "[kiosk]\nport = 70000\n", "[kiosk] key 'port'")
        self.one_line_exit_2(base + "[kiosk]\nresult_hold_s = 0\n", "[kiosk] key 'result_hold_s'")
        self.one_line_exit_2(base + "[kiosk]\ncolour = red\n", "colour")
        self.one_line_exit_2("[cam]\nbackend = v4l2\n[kiosk]\nwait_for_athlete = yes\n", "wait_for_athlete")
        self.one_line_exit_2(base + "[kiosk]\nport = 0\ndb = DIR/no/such/dir/k.sqlite\n", "k.sqlite")

        def foreign(d):
            with sqlite3.connect(os.path.join(d, "other.sqlite")) as c:
                c.execute("CREATE TABLE t(x)")
        self.one_line_exit_2(base + "[kiosk]\nport = 0\ndb = DIR/other.sqlite\n", "another program", foreign)

        def newer(d):
            with sqlite3.connect(os.path.join(d, "new.sqlite")) as c:
                c.execute("CREATE TABLE t(x)")
                c.execute("PRAGMA application_id = %d" % 0x47534b31)
                c.execute("PRAGMA user_version = 99")
        self.one_line_exit_2(base + "[kiosk]\nport = 0\ndb = DIR/new.sqlite\n", "schema version 99", newer)

        def text(d):
            with open(os.path.join(d, "notdb.sqlite"), "w") as f:
                f.write("hello, this is not a database at all, not at all\n" * 20)
        self.one_line_exit_2(base + "[kiosk]\nport = 0\ndb = DIR/notdb.sqlite\n", "notdb.sqlite", text)

    def test_port_in_use(self):
        import socket
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        self.addCleanup(s.close)
        port = s.getsockname()[1]
        self.one_line_exit_2("[cam]\nbackend = keypoints\ndevice = %s\n[kiosk]\nport = %d\ndb = DIR/k.sqlite\n"
                             % (CSV, port), "%d" % port)


if __name__ == "__main__":
    unittest.main(verbosity=2)
