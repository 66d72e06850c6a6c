"""gs_kiosk.py - start `gravscale cam` with a kiosk and talk to it (loopback only),
for the kiosk's tests."""
import http.client
import json
import os
import re
import signal
import subprocess
import time

PROGRAM = os.environ.get("GS_PROGRAM", "build/gravscale")
TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Daemon:
    """gravscale cam with its stdout (the events) in a file and its stderr read for the page's URL."""

    def __init__(self, args, workdir, name="cam", env=None):
        self.out_path = os.path.join(workdir, name + ".out")
        self.err_path = os.path.join(workdir, name + ".err")
        self.out = open(self.out_path, "wb")
        self.err = open(self.err_path, "wb")
        self.t_start = time.time()
        self.proc = subprocess.Popen([PROGRAM, "cam"] + args, stdout=self.out, stderr=self.err, cwd=TOP, env=env)
        self.url = None
        self.port = None

    def wait_url(self, timeout_s=30):
        t0 = time.time()
        while time.time() - t0 < timeout_s:
            m = re.search(r"kiosk page on (http://[0-9.]+:(\d+)/)", self.stderr())
            if m:
                self.url, self.port = m.group(1), int(m.group(2))
                return self.url
            if self.proc.poll() is not None:
                raise AssertionError("gravscale cam exited %d: %s" % (self.proc.returncode, self.stderr()))
            time.sleep(0.02)
        raise AssertionError("no kiosk URL on stderr: " + self.stderr())

    def stderr(self):
        with open(self.err_path, "rb") as f:
            return f.read().decode("utf-8", "replace")

    def events(self):
        with open(self.out_path, "rb") as f:
            return [json.loads(l) for l in f.read().decode().splitlines() if l.startswith("{")]

    def wait_stderr(self, pattern, timeout_s):
        t0 = time.time()
        while time.time() - t0 < timeout_s:
            if re.search(pattern, self.stderr()):
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        raise AssertionError("'%s' not on stderr after %g s: %s" % (pattern, timeout_s, self.stderr()))

    def stop(self, sig=signal.SIGTERM, timeout_s=15):
        """The exit code; a second call only returns it."""
        if self.out.closed:
            return self.proc.returncode
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            rc = self.proc.wait(timeout_s)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            raise AssertionError("gravscale cam did not stop within %g s after signal %d" % (timeout_s, sig))
        self.out.close()
        self.err.close()
        return rc


def request(port, method, path, body=None, headers=None, host=None, raw_body=None):
    """(status, parsed JSON or text, headers) of one request to 127.0.0.1:port."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=20)
    c.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    c.putheader("Host", host if host is not None else "127.0.0.1:%d" % port)
    data = raw_body
    if body is not None:
        data = json.dumps(body).encode()
        c.putheader("Content-Type", "application/json")
    for k, v in (headers or {}).items():
        c.putheader(k, v)
    if data is not None:
        c.putheader("Content-Length", str(len(data)))
    c.endheaders(data)
    r = c.getresponse()
    text = r.read()
    hdrs = dict((k.lower(), v) for k, v in r.getheaders())
    c.close()
    if hdrs.get("content-type", "").startswith("application/json"):
        return r.status, json.loads(text), hdrs
    return r.status, text.decode("utf-8", "replace"), hdrs
