"""Whole-body motion: stance, countermovement jumps, jumping jacks, runs and walks.

How the true COM is made exact (docs/simulator.md, "Kinematics"):
- contact phases: the vertical COM path z(t) is designed (quintic pieces); each instant the
  support legs' flexion s is solved so that the lowest contact point of the support feet is at
  the floor while the whole-body COM is at z(t); the support point is fixed horizontally.
- flight: the pose comes from its tracks, the COM is exactly ballistic (g = 9.81) from the
  take-off state, and the root is placed so the whole-body COM follows it.
- landing happens when a foot reaches the floor (solved in continuous time); the horizontal
  COM velocity is kept continuous by solving the post-impact rates of two channels.
- walks are pose driven: the lowest foot is kept on the floor, the root advances smoothly."""

import math

from . import body
from .track import Track, ZPath

G = 9.81
D2R = math.pi / 180.0
CLAMP_V = 0.25   # m/s: slowest designed vertical COM speed where the reach clamp may act
CLAMP_DZ = 0.02  # m: largest allowed clamp
CLAMP_S = 0.02   # support flexion used while clamped
S_LO, S_HI = 0.0, 1.45   # admissible support-leg flexion (no hyperextension)


class Infeasible(Exception):
    """A drawn motion cannot be realised (the builder redraws it)."""


class Contact:
    __slots__ = ("t0", "t1", "support", "anchor", "walk", "solve", "hx", "hy", "J", "u")

    def __init__(self, t0, support, anchor, solve=("tp", "tr"), walk=False):
        self.t0 = t0
        self.t1 = math.inf
        self.support = support       # "both", "L" or "R"
        self.anchor = anchor         # world xy of the support reference point
        self.walk = walk
        self.solve = solve           # two channels solved to place the COM horizontally
        self.hx = ZPath(G)           # designed COM x - anchor x (world)
        self.hy = ZPath(G)
        self.J = None                # cached Jacobian of the contact solve
        self.u = None                # last solution (s, a, b)


class Flight:
    __slots__ = ("t0", "t1", "c0", "v0")

    def __init__(self, t0, c0, v0):
        self.t0 = t0
        self.t1 = math.inf
        self.c0 = c0
        self.v0 = v0

    def com(self, t):
        tau = t - self.t0
        return (self.c0[0] + self.v0[0] * tau, self.c0[1] + self.v0[1] * tau,
                self.c0[2] + self.v0[2] * tau - 0.5 * G * tau * tau)


def _solve3(A, b):
    """Cramer's rule for a 3x3 system (None if singular)."""
    (a, b1, c), (d, e, f), (g, h, i) = A
    det = a * (e * i - f * h) - b1 * (d * i - f * g) + c * (d * h - e * g)
    if abs(det) < 1e-14:
        return None
    x = (b[0] * (e * i - f * h) - b1 * (b[1] * i - f * b[2]) + c * (b[1] * h - e * b[2])) / det
    y = (a * (b[1] * i - f * b[2]) - b[0] * (d * i - f * g) + c * (d * b[2] - b[1] * g)) / det
    z = (a * (e * b[2] - b[1] * h) - b1 * (d * b[2] - b[1] * g) + b[0] * (d * h - e * g)) / det
    return [x, y, z]


def _support_pts(support):
    if support == "both":
        return ("l_heel", "l_ball", "l_toe", "r_heel", "r_ball", "r_toe"), ("l_ball", "r_ball")
    s = "l_" if support == "L" else "r_"
    return (s + "heel", s + "ball"), (s + "ball",)


class Motion:
    """A trial's motion; state(t) gives world points, the true COM and the segments."""

    def __init__(self, sub, rng):
        self.sub = sub
        self.tracks = {k: Track(0.0) for k in body.CHANNELS}
        self.z = ZPath(G)
        self.phases = []          # Contact / Flight, in time order
        self.path = None          # walk: function t -> (x, y) of the root
        self._s = 0.06
        self.clamped = False

    # ---- pose --------------------------------------------------------------
    def pose(self, t):
        return {k: tr(t) for k, tr in self.tracks.items()}

    def phase_at(self, t):
        ph = self.phases
        lo, hi = 0, len(ph) - 1
        while hi > lo:
            mid = (lo + hi + 1) // 2
            if ph[mid].t0 <= t:
                lo = mid
            else:
                hi = mid - 1
        return ph[lo]

    def _local(self, p, cL, cR):
        sub = self.sub
        pu, mu, su = body.upper(sub, p)
        pl, ml, sl = body.leg(sub, p, "L", cL)
        pr, mr, sr = body.leg(sub, p, "R", cR)
        pts = pu
        pts.update(pl)
        pts.update(pr)
        com = (mu[0] + ml[0] + mr[0], mu[1] + ml[1] + mr[1], mu[2] + ml[2] + mr[2])
        return pts, com, su + sl + sr

    def _resid(self, p, ph, R3base, pu, mu, x):
        """Residual of the contact solve for unknowns x = (s, a, b)."""
        sub = self.sub
        s, a, b = x
        q = dict(p)
        q[ph.solve[0]] = a
        q[ph.solve[1]] = b
        support = ph.support
        names, refs = _support_pts(support)
        R = body.mm(R3base, body.tilt_matrix(q))
        com = list(mu)
        pts = {}
        for side in ("L", "R"):
            c = s if support in ("both", side) else q["c_" + side]
            if side in ph.solve[0] or side in ph.solve[1] or c != q["c_" + side] or True:
                lp, ml, _ = body.leg(sub, q, side, c)
            pts.update(lp)
            com[0] += ml[0]
            com[1] += ml[1]
            com[2] += ml[2]
        if "tp" not in ph.solve or "tr" not in ph.solve:
            # upper body depends on the tilt only through R, which is applied here
            pass
        wc = body.mv(R, com)
        low = math.inf
        for n in names:
            zz = body.mv(R, pts[n])[2]
            if zz < low:
                low = zz
        rx = ry = 0.0
        for n in refs:
            w = body.mv(R, pts[n])
            rx += w[0]
            ry += w[1]
        rx /= len(refs)
        ry /= len(refs)
        return (wc[2] - low, wc[0] - rx, wc[1] - ry)

    def _solve(self, p, ph, t, retry=True, zcap=None):
        """Solve support flexion and the two horizontal channels so the COM is on its design."""
        pu, mu, _ = body.upper(self.sub, p)
        Ry = body.rz(p["yaw"])
        zd, vzd, _ = self.z.eval(t)
        if zcap is not None:
            zd = min(zd, zcap)
        target = (zd, ph.hx.eval(t)[0], ph.hy.eval(t)[0])
        x = list(ph.u) if ph.u is not None else [self._s, p[ph.solve[0]], p[ph.solve[1]]]
        x0 = list(x)

        def F(x):
            r = self._resid(p, ph, Ry, pu, mu, x)
            return [r[0] - target[0], r[1] - target[1], r[2] - target[2]]

        def jac(x, f0):
            J = []
            for j in range(3):
                y = list(x)
                y[j] += 1e-6
                fj = F(y)
                J.append([(fj[i] - f0[i]) / 1e-6 for i in range(3)])
            # columns -> rows
            return [[J[j][i] for j in range(3)] for i in range(3)]
        f = F(x)
        J = ph.J
        fresh = False
        for it in range(40):
            if max(abs(v) for v in f) < 1e-13:
                break
            if J is None:
                J = jac(x, f)
                fresh = True
            dx = _solve3(J, [-v for v in f])
            if dx is None:
                raise Infeasible("singular contact solve")
            xn = [x[i] + dx[i] for i in range(3)]
            fn = F(xn)
            if max(abs(v) for v in fn) > 0.5 * max(abs(v) for v in f) and not fresh:
                J = None          # stale Jacobian: rebuild it and retry from x
                continue
            # Broyden rank-one update keeps the Jacobian current without re-differencing
            df = [fn[i] - f[i] for i in range(3)]
            dd = sum(v * v for v in dx)
            if dd > 0:
                Jdx = [sum(J[i][j] * dx[j] for j in range(3)) for i in range(3)]
                J = [[J[i][j] + (df[i] - Jdx[i]) * dx[j] / dd for j in range(3)] for i in range(3)]
            fresh = False
            x, f = xn, fn
        if (max(abs(v) for v in f) > 1e-9 or not (S_LO <= x[0] <= S_HI)) and retry:
            # Hc(s) peaks at s = 0: restart on the flexed branch
            ph.u = [0.3, x0[1], x0[2]]
            ph.J = None
            try:
                return self._solve(p, ph, t, retry=False, zcap=zcap)
            except Infeasible:
                if zcap is not None or abs(vzd) > CLAMP_V:
                    raise
            # slow phase (quiet standing, late recovery): the design asks for a COM a little
            # higher than straight legs allow; keep the legs straight-ish instead of failing
            cap = zd
            for _ in range(6):
                r = self._resid(p, ph, Ry, pu, mu, (CLAMP_S, x0[1], x0[2]))
                cap = r[0] - 1e-6
                if zd - cap > CLAMP_DZ:
                    raise Infeasible("COM design %.4f m above reach" % (zd - cap))
                ph.u = [CLAMP_S + 0.02, x0[1], x0[2]]
                ph.J = None
                try:
                    x = self._solve(p, ph, t, retry=False, zcap=cap)
                    self.clamped = True
                    return x
                except Infeasible:
                    continue
            raise Infeasible("clamp failed")
        if max(abs(v) for v in f) > 1e-9 or not (S_LO <= x[0] <= S_HI) \
                or abs(x[1]) > 1.2 or abs(x[2]) > 1.2:
            raise Infeasible("contact solve failed at t=%.4f: %r %r" % (t, x, f))
        ph.J = J
        ph.u = x
        self._s = x[0]
        return x

    def state(self, t, want_segs=False):
        """World points (dict), true COM (x, y, z), support flexion (or None), segments."""
        p = self.pose(t)
        ph = self.phase_at(t)
        sub = self.sub
        if isinstance(ph, Flight):
            s = None
            pts, com, segs = self._local(p, p["c_L"], p["c_R"])
            target = ph.com(t)
        elif ph.walk:
            s = None
            pts, com, segs = self._local(p, p["c_L"], p["c_R"])
            target = None
        else:
            s, a, b = self._solve(p, ph, t)
            p[ph.solve[0]] = a
            p[ph.solve[1]] = b
            cL = s if ph.support in ("both", "L") else p["c_L"]
            cR = s if ph.support in ("both", "R") else p["c_R"]
            pts, com, segs = self._local(p, cL, cR)
            target = None
        R = body.mm(body.rz(p["yaw"]), body.tilt_matrix(p))
        mv = body.mv
        wpts = {k: mv(R, v) for k, v in pts.items()}
        wcom = mv(R, com)
        if target is not None:
            root = (target[0] - wcom[0], target[1] - wcom[1], target[2] - wcom[2])
        elif ph.walk:
            low = min(wpts[n][2] for n in ("l_heel", "l_ball", "l_toe", "r_heel", "r_ball", "r_toe"))
            x, y = self.path(t)
            root = (x, y, -low)
        else:
            names, refs = _support_pts(ph.support)
            low = min(wpts[n][2] for n in names)
            rx = sum(wpts[n][0] for n in refs) / len(refs)
            ry = sum(wpts[n][1] for n in refs) / len(refs)
            root = (ph.anchor[0] - rx, ph.anchor[1] - ry, -low)
        out = {k: (v[0] + root[0], v[1] + root[1], v[2] + root[2]) for k, v in wpts.items()}
        C = (wcom[0] + root[0], wcom[1] + root[1], wcom[2] + root[2])
        segw = None
        if want_segs:
            segw = []
            for name, a, b, c in segs:
                ca = mv(R, c)
                segw.append((name, sub.mass[name.split("_")[0]],
                             (ca[0] + root[0], ca[1] + root[1], ca[2] + root[2])))
        return out, C, s, segw

    # ---- helpers used by the builders ---------------------------------------
    def com_vel(self, t, side):
        """Second-order one-sided COM velocity (side=-1: from the left, +1: from the right)."""
        h = 1e-5
        c0 = self.state(t)[1]
        c1 = self.state(t + side * h)[1]
        c2 = self.state(t + side * 2 * h)[1]
        return tuple(side * (-3 * c0[k] + 4 * c1[k] - c2[k]) / (2 * h) for k in range(3))

    def solved_rates(self, t):
        """Values and left rates of the contact unknowns (s, a, b) at t."""
        h = 1e-5
        ph = self.phase_at(t - 1e-9)
        x0 = list(self._solve(self.pose(t), ph, t))
        x1 = list(self._solve(self.pose(t - h), ph, t - h))
        x2 = list(self._solve(self.pose(t - 2 * h), ph, t - 2 * h))
        return x0, [(3 * x0[i] - 4 * x1[i] + x2[i]) / (2 * h) for i in range(3)]

    def support_height(self, p, support, cL, cR):
        """Height of the COM above the lowest support point for a given pose."""
        pts, com, _ = self._local(p, cL, cR)
        R = body.tilt_matrix(p)
        names, _ = _support_pts(support)
        low = min(body.mv(R, pts[n])[2] for n in names)
        return body.mv(R, com)[2] - low

    def foot_low(self, t, names):
        pts = self.state(t)[0]
        return min(pts[n][2] for n in names)
