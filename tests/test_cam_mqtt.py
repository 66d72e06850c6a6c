"""gravscale cam with an MQTT sink, against a real Mosquitto broker (Debian's
`mosquitto`) started here on a free loopback port, with Debian's `mosquitto_sub`
as the subscriber (a durable session). The bundled sample (three jumps in 12 s)
plays at real speed through the keypoints backend; after the first jump the
broker is stopped and started again once the daemon has written the second
jump's height. Every event the daemon wrote to its file sink must arrive exactly once,
in order, on gs/<device>/<event>; the retained status says online after each
connect and offline at the end (retained for late subscribers)."""
import getpass
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import json

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gs_kiosk import TOP, Daemon  # noqa: E402

BROKER = shutil.which("mosquitto") or "/usr/sbin/mosquitto"
SUB = shutil.which("mosquitto_sub") or "/usr/bin/mosquitto_sub"
CSV = os.path.join(TOP, "tests", "data", "sample_jumps.csv")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def port_open(port):
    with socket.socket() as s:
        return s.connect_ex(("127.0.0.1", port)) == 0


class Broker:
    def __init__(self, d, port):
        self.conf = os.path.join(d, "mosquitto.conf")
        with open(self.conf, "w") as f:
            # started as root it would switch to its own user and lose these files
            f.write("user %s\nlistener %d 127.0.0.1\nallow_anonymous true\npersistence true\n"
                    "persistence_location %s/\nlog_dest file %s/broker.log\n" % (getpass.getuser(), port, d, d))
        self.port = port
        self.proc = None

    def start(self):
        self.proc = subprocess.Popen([BROKER, "-c", self.conf], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        t0 = time.time()
        while not port_open(self.port):
            if time.time() - t0 > 10 or self.proc.poll() is not None:
                raise AssertionError("the broker did not start")
            time.sleep(0.02)

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)  # it saves the subscriber's session and queue
            self.proc.wait(10)


class CamMqtt(unittest.TestCase):
    def setUp(self):
        for p in (BROKER, SUB):
            if not os.access(p, os.X_OK):
                self.fail("%s is not installed (tools/bootstrap.sh installs mosquitto and mosquitto-clients)" % p)
        self.dir = tempfile.mkdtemp(prefix="gs-cam-mqtt-")
        self.addCleanup(shutil.rmtree, self.dir, True)
        self.port = free_port()
        self.broker = Broker(self.dir, self.port)
        self.broker.start()
        self.addCleanup(self.broker.stop)

    def test_every_event_once_across_a_broker_restart(self):
        msgs, lock = [], threading.Lock()
        sub = subprocess.Popen([SUB, "-h", "127.0.0.1", "-p", str(self.port), "-t", "gs/#", "-q", "1", "-c",
                                "-i", "gs-test-fleet", "-F", "%r %q %t %p"], stdout=subprocess.PIPE, text=True)
        self.addCleanup(lambda: (sub.terminate(), sub.wait(5)))

        def read():
            for line in sub.stdout:
                with lock:
                    msgs.append((time.time(), line.rstrip("\n")))
        threading.Thread(target=read, daemon=True).start()
        time.sleep(0.3)  # subscribed
        events_path = os.path.join(self.dir, "events.jsonl")
        cfg = os.path.join(self.dir, "fleet.cfg")
        with open(cfg, "w") as f:
            f.write("[cam]\nbackend = keypoints\ndevice = %s\n[sink.stdout]\nenabled = no\n[sink.file]\npath = %s\n"
                    "[sink.mqtt]\nhost = 127.0.0.1\nport = %d\ntopic_prefix = gs\ndevice = kiosk-7\nqos = 1\n"
                    "backoff_min_s = 0.1\nbackoff_max_s = 0.5\n[status]\ninterval_s = 0\n" % (CSV, events_path, self.port))
        d = Daemon(["--config", cfg], self.dir)
        self.addCleanup(d.stop)

        def wait_for(pred, timeout_s, what):
            t0 = time.time()
            while time.time() - t0 < timeout_s:
                with lock:
                    if pred(list(msgs)):
                        return
                time.sleep(0.02)
            self.fail("timed out waiting for " + what + ": " + repr(msgs))
        wait_for(lambda m: any(" gs/kiosk-7/height " in x for _, x in m), 20, "the first height")
        time.sleep(0.3)
        self.broker.stop()
        def file_events():
            with open(events_path) as f:
                return [json.loads(l) for l in f.read().splitlines()]
        n_before = len(file_events())
        # the broker stays away until the daemon has written the second jump's height (not a fixed
        # time: a slow, sanitized build plays the same sample later)
        t0 = time.time()
        while sum(e["event"] == "height" for e in file_events()) < 2 and time.time() - t0 < 20:
            time.sleep(0.05)
        time.sleep(0.5)
        n_during = len(file_events()) - n_before
        self.broker.start()
        rc = d.proc.wait(40)
        self.assertEqual(rc, 0, d.stderr())
        d.stop()
        wait_for(lambda m: any(x.endswith(" gs/kiosk-7/status offline") for _, x in m), 10, "offline at the end")
        time.sleep(0.3)
        self.assertGreaterEqual(n_during, 2, "the second jump and its height happen while the broker is away")
        with open(events_path) as f:
            lines = f.read().splitlines()
        events = [json.loads(l) for l in lines]
        self.assertEqual(sum(e["event"] == "jump" and e["accepted"] for e in events), 3, "the sample's three jumps")
        with lock:
            got = [x for _, x in msgs]
        status = [x for x in got if " gs/kiosk-7/status " in x]
        rest = [x for x in got if " gs/kiosk-7/status " not in x]
        # every line once, in order, on its event's topic, at QoS 1 as configured
        self.assertEqual(len(rest), len(lines), "\n".join(rest))
        for line, e, m in zip(lines, events, rest):
            retain, qos, topic, payload = m.split(" ", 3)
            self.assertEqual(topic, "gs/kiosk-7/" + e["event"])
            self.assertEqual(payload, line)
            self.assertEqual((retain, qos), ("0", "1"))
        # availability: online after each connect, offline last (a broker that stops sends the will,
        # and a subscriber that subscribes again gets the retained value again)
        words = [s.split(" ")[-1] for s in status]
        self.assertEqual(words[0], "online")
        self.assertEqual(words[-1], "offline")
        self.assertGreaterEqual(words.count("online"), 2, words)
        late = subprocess.run([SUB, "-h", "127.0.0.1", "-p", str(self.port), "-t", "gs/kiosk-7/status", "-C", "1",
                               "-W", "5", "-F", "%r %p"], capture_output=True, text=True, timeout=10)
        self.assertEqual(late.stdout.strip(), "1 offline", "a late subscriber reads the retained status")
        self.assertIn("4 flights (3 accepted)", d.stderr())
        print("mqtt: %d events, %d of them while the broker was away, each once" % (len(lines), n_during))

    def test_nmea_daemon_gives_mqtt_json(self):
        """A daemon writing NMEA to its other sinks still publishes every event as JSON."""
        sub = subprocess.Popen([SUB, "-h", "127.0.0.1", "-p", str(self.port), "-t", "gs/#", "-q", "1",
                                "-F", "%t %p", "-W", "30"], stdout=subprocess.PIPE, text=True)
        self.addCleanup(lambda: (sub.terminate(), sub.wait(5)))
        time.sleep(0.3)
        nmea_path = os.path.join(self.dir, "events.nmea")
        cfg = os.path.join(self.dir, "nmea.cfg")
        with open(cfg, "w") as f:
            f.write("[core]\nformat = nmea\n[cam]\nbackend = keypoints\ndevice = %s\nrealtime = no\n"
                    "[sink.stdout]\nenabled = no\n[sink.file]\npath = %s\n[sink.mqtt]\nhost = 127.0.0.1\n"
                    "port = %d\ntopic_prefix = gs\ndevice = cam-2\n[status]\ninterval_s = 0\n"
                    % (CSV, nmea_path, self.port))
        d = Daemon(["--config", cfg], self.dir, "nmea")
        self.addCleanup(d.stop)
        self.assertEqual(d.proc.wait(30), 0, d.stderr())
        time.sleep(0.5)
        sub.terminate()
        out = sub.communicate(timeout=5)[0].splitlines()
        with open(nmea_path) as f:
            nmea = f.read().splitlines()
        self.assertTrue(all(l.startswith("$GS") for l in nmea), nmea)
        events = [(l.split(" ", 1)[0], json.loads(l.split(" ", 1)[1])) for l in out
                  if not l.startswith("gs/cam-2/status ")]
        kinds = {"$GSSTA": "start", "$GSSES": "session", "$GSJMP": "jump", "$GSHGT": "height", "$GSSUM": "summary"}
        self.assertEqual([kinds[l[:6]] for l in nmea], [e["event"] for _, e in events])
        for topic, e in events:
            self.assertEqual(topic, "gs/cam-2/" + e["event"])
        # the same jumps: NMEA's height field (3 decimals) against the JSON's
        jumps = [e for _, e in events if e["event"] == "jump"]
        for line, e in zip([l for l in nmea if l.startswith("$GSJMP")], jumps):
            self.assertAlmostEqual(float(line.split(",")[5]), e["height_m"], places=3)


if __name__ == "__main__":
    unittest.main(verbosity=2)
