"""Piecewise Hermite tracks: smooth time functions built from keyframes.

A cubic track is C1 wherever a key's incoming and outgoing rates agree; a key may
carry different rates (an impact at landing). Quintic segments carry accelerations
too and are used for the designed vertical COM path."""


class Track:
    """Cubic Hermite through keys (t, value, rate_in, rate_out); constant outside."""

    __slots__ = ("ts", "vs", "rin", "rout", "_i")

    def __init__(self, value=0.0, t=0.0):
        self.ts = [t]
        self.vs = [float(value)]
        self.rin = [0.0]
        self.rout = [0.0]
        self._i = 0

    def key(self, t, value, rate=0.0, rate_out=None):
        """Append a key; keys must come in increasing time order."""
        if t <= self.ts[-1]:
            if t == self.ts[-1]:
                # replacing the last key (same time) keeps the order intact
                self.vs[-1] = float(value)
                self.rin[-1] = float(rate)
                self.rout[-1] = float(rate if rate_out is None else rate_out)
                return self
            raise ValueError("track keys out of order: %r after %r" % (t, self.ts[-1]))
        self.ts.append(float(t))
        self.vs.append(float(value))
        self.rin.append(float(rate))
        self.rout.append(float(rate if rate_out is None else rate_out))
        return self

    def truncate_after(self, t):
        """Drop keys later than t (redesign of a flight)."""
        while len(self.ts) > 1 and self.ts[-1] > t:
            self.ts.pop()
            self.vs.pop()
            self.rin.pop()
            self.rout.pop()
        self._i = 0

    def rate_at(self, t):
        h = 1e-6
        return (self(t + h) - self(t - h)) / (2 * h)

    def set_rate_out(self, t, rate):
        """Change the outgoing rate of the key at time t (landing impact)."""
        i = self.ts.index(t)
        self.rout[i] = float(rate)

    def last(self):
        return self.ts[-1], self.vs[-1]

    def _seg(self, t):
        ts = self.ts
        i = self._i
        n = len(ts)
        if i >= n - 1 or t < ts[i] or t > ts[i + 1]:
            # binary search: the cached segment did not contain t
            lo, hi = 0, n - 1
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if ts[mid] <= t:
                    lo = mid
                else:
                    hi = mid
            i = lo
            self._i = i
        return i

    def __call__(self, t):
        ts = self.ts
        if t <= ts[0]:
            return self.vs[0] + self.rout[0] * 0.0
        if t >= ts[-1]:
            return self.vs[-1]
        i = self._seg(t)
        t0 = ts[i]
        h = ts[i + 1] - t0
        u = (t - t0) / h
        u2 = u * u
        u3 = u2 * u
        return ((2 * u3 - 3 * u2 + 1) * self.vs[i] + (u3 - 2 * u2 + u) * h * self.rout[i]
                + (-2 * u3 + 3 * u2) * self.vs[i + 1] + (u3 - u2) * h * self.rin[i + 1])


def quintic(t0, t1, p0, v0, a0, p1, v1, a1):
    """Coefficients c0..c5 in tau = t - t0 of the quintic meeting both end states."""
    h = t1 - t0
    c0, c1, c2 = p0, v0, 0.5 * a0
    # solve for c3, c4, c5 from the end conditions (closed form)
    d0 = p1 - (c0 + c1 * h + c2 * h * h)
    d1 = v1 - (c1 + 2 * c2 * h)
    d2 = a1 - 2 * c2
    h2 = h * h
    h3 = h2 * h
    c3 = (10 * d0 - 4 * d1 * h + 0.5 * d2 * h2) / h3
    c4 = (-15 * d0 + 7 * d1 * h - d2 * h2) / (h3 * h)
    c5 = (6 * d0 - 3 * d1 * h + 0.5 * d2 * h2) / (h3 * h2)
    return (c0, c1, c2, c3, c4, c5)


class ZPath:
    """Vertical COM design: a list of pieces, each quintic or ballistic, in time order.

    Pieces: (t0, t1, kind, coeffs). kind 'q' = quintic in tau, 'b' = ballistic
    (z0, v0) with z = z0 + v0 tau - g tau^2 / 2 exactly."""

    def __init__(self, g):
        self.g = g
        self.pieces = []

    def add_quintic(self, t0, t1, p0, v0, a0, p1, v1, a1):
        self.pieces.append((t0, t1, "q", quintic(t0, t1, p0, v0, a0, p1, v1, a1)))

    def add_const(self, t0, t1, z):
        self.pieces.append((t0, t1, "q", (z, 0.0, 0.0, 0.0, 0.0, 0.0)))

    def add_ballistic(self, t0, t1, z0, v0):
        self.pieces.append((t0, t1, "b", (z0, v0)))

    def _find(self, t):
        ps = self.pieces
        lo, hi = 0, len(ps) - 1
        if t <= ps[0][0]:
            return ps[0]
        if t >= ps[-1][0]:
            return ps[-1]
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if ps[mid][0] <= t:
                lo = mid
            else:
                hi = mid
        return ps[lo] if t < ps[hi][0] else ps[hi]

    def eval(self, t, piece=None):
        """(z, vz, az) at t."""
        t0, t1, kind, c = piece if piece is not None else self._find(t)
        tau = t - t0
        if kind == "b":
            return (c[0] + c[1] * tau - 0.5 * self.g * tau * tau, c[1] - self.g * tau, -self.g)
        if tau > t1 - t0:
            tau = t1 - t0
        z = c[0] + tau * (c[1] + tau * (c[2] + tau * (c[3] + tau * (c[4] + tau * c[5]))))
        v = c[1] + tau * (2 * c[2] + tau * (3 * c[3] + tau * (4 * c[4] + tau * 5 * c[5])))
        a = 2 * c[2] + tau * (6 * c[3] + tau * (12 * c[4] + tau * 20 * c[5]))
        return (z, v, a)
