"""Trial programmes: stand, countermovement jumps (low/high/funny), jacks, run, walk."""

import math

from . import body
from .motion import Motion, Contact, Flight, Infeasible, G, D2R

A_FREE = -G  # COM acceleration where a contact begins or ends: the ground force is zero there (force plates)

S_STAND = 0.06   # relaxed knees when standing (flexion units, ~6.6 deg at the knee)


class Builder:
    def __init__(self, sub, rng, yaw, x0=0.0, y0=0.0):
        self.sub = sub
        self.rng = rng
        self.m = Motion(sub, rng)
        self.t = 0.0
        self.flights = []
        u = rng.uniform
        self.rest = {
            "yaw": yaw, "lean": u(0, 2) * D2R, "hp": u(-3, 4) * D2R, "hy": u(-5, 5) * D2R,
            "af_L": u(0, 8) * D2R, "af_R": u(0, 8) * D2R, "aa_L": u(4, 12) * D2R,
            "aa_R": u(4, 12) * D2R, "el_L": u(5, 20) * D2R, "el_R": u(5, 20) * D2R,
            "ab_L": u(1, 4) * D2R, "ab_R": u(1, 4) * D2R, "c_L": S_STAND, "c_R": S_STAND,
        }
        self.rest["ab_R"] = self.rest["ab_L"]   # symmetric stance width
        tr = self.m.tracks
        for k, v in self.rest.items():
            tr[k].vs[0] = v
        c = Contact(0.0, "both", (x0, y0))
        self.m.phases.append(c)
        self.z_st, dx, dy = self.natural(self.m.pose(0.0), c, S_STAND)
        self.dbal = (dx, dy)
        self.d = (dx, dy)

    def natural(self, p, ph, s):
        """(COM height, COM x - ref x, COM y - ref y) for pose p with support flexion s."""
        pu, mu, _ = body.upper(self.sub, p)
        return self.m._resid(p, ph, body.rz(p["yaw"]), pu, mu, (s, p[ph.solve[0]], p[ph.solve[1]]))

    # ---- generic pieces ---------------------------------------------------
    def key(self, t, **kv):
        for k, v in kv.items():
            if isinstance(v, tuple):
                self.m.tracks[k].key(t, v[0], v[1], v[2] if len(v) > 2 else None)
            else:
                self.m.tracks[k].key(t, v, 0.0)

    def hpiece(self, ph, t0, t1, d0, v0, d1, v1):
        """Designed horizontal COM offset from the anchor over [t0, t1] (zero end accelerations)."""
        ph.hx.add_quintic(t0, t1, d0[0], v0[0], 0.0, d1[0], v1[0], 0.0)
        ph.hy.add_quintic(t0, t1, d0[1], v0[1], 0.0, d1[1], v1[1], 0.0)

    def stand(self, dur):
        """Quiet standing: small COM sway over the feet, small arm and head movements."""
        t0, t1 = self.t, self.t + dur
        m = self.m
        ph = m.phases[-1]
        m.z.add_const(t0, t1, self.z_st)
        n = max(1, int(dur / 0.8))
        u = self.rng.uniform
        g = self.rng.gauss
        for i in range(1, n + 1):
            tk = t0 + dur * i / n
            kv = {}
            for k in ("af_L", "af_R", "el_L", "el_R", "aa_L", "aa_R", "hp", "hy"):
                kv[k] = self.rest[k] + u(-2.5, 2.5) * D2R
            for k in ("lean", "twist", "bend", "sw_L", "sw_R", "ph_L", "ph_R"):
                kv[k] = self.rest.get(k, 0.0)
            kv["ab_L"], kv["ab_R"] = self.rest["ab_L"], self.rest["ab_R"]
            kv["c_L"] = kv["c_R"] = S_STAND
            self.key(tk, **kv)
            nd = (self.dbal[0] + g(0, 0.004), self.dbal[1] + g(0, 0.004)) if i < n else self.dbal
            self.hpiece(ph, t0 + dur * (i - 1) / n, tk, self.d, (0, 0), nd, (0, 0))
            self.d = nd
        self.t = t1
        self.check(t0, t1, 0.05)

    def check(self, t0, t1, dt=0.1):
        t = t0
        while t <= t1:
            st = self.m.state(t)   # raises Infeasible if the contact solve fails
            ph = self.m.phase_at(t)
            if isinstance(ph, Contact) and ph.support in ("L", "R") and not ph.walk:
                o = "r_" if ph.support == "L" else "l_"
                if min(st[0][o + "heel"][2], st[0][o + "ball"][2]) < -0.0005:
                    raise Infeasible("swing foot below the floor")
            t += dt

    def fly(self, t0, z0, v0z, vxy, flight_keys, support_land, solve_land=("tp", "tr")):
        """Ballistic flight from t0. flight_keys(t0, tau) keys every track over the flight and
        returns the landing flexions (cL, cR). Starts the landing contact; returns it."""
        m = self.m
        ph = m.phases[-1]
        self.pin(t0)
        m.clamped = False
        x0, xr = m.solved_rates(t0)
        if m.clamped:
            raise Infeasible("take-off on a clamped contact")
        c0 = m.state(t0)[1]
        v0 = (vxy[0], vxy[1], v0z)
        ph.t1 = t0
        fl = Flight(t0, c0, v0)
        m.phases.append(fl)
        support_to = ph.support
        tau = 2 * v0z / G

        def bake():
            # the contact unknowns continue smoothly into the flight tracks
            for k, tr in m.tracks.items():
                tr.truncate_after(t0)
            for j, ch in ((1, ph.solve[0]), (2, ph.solve[1])):
                m.tracks[ch].key(t0, x0[j], xr[j])
            s0, sd = x0[0], xr[0]
            for side in ("L", "R"):
                if support_to in ("both", side):
                    tr = m.tracks["c_" + side]
                    tr.key(t0, s0, sd)
                    if sd < 0:
                        # the support legs stop extending right after take-off (lifts the feet)
                        d = min(0.06, max(0.012, 1.5 * s0 / -sd))
                        tr.key(t0 + d, max(0.0, s0 + 0.5 * sd * d), 0.0)
        probe = Contact(0.0, support_land, (0.0, 0.0), solve_land)
        for _ in range(6):
            bake()
            cL, cR = flight_keys(t0, tau)
            p = m.pose(t0 + tau)
            zL = self.natural(p, probe, cL if support_land != "R" else cR)[0]
            disc = v0z * v0z + 2 * G * (z0 - zL)
            if disc <= 0:
                raise Infeasible("landing pose above the apex")
            nt = (v0z + math.sqrt(disc)) / G
            if abs(nt - tau) < 1e-12:
                tau = nt
                break
            tau = nt
        allf = ("l_heel", "l_ball", "r_heel", "r_ball")
        # both feet land on their toes first (a jump); one foot (a running step) on its ball
        toe = support_land == "both"
        names = (("l_heel", "l_ball") + (("l_toe",) if toe else ()) if support_land in ("both", "L") else ()) + \
                (("r_heel", "r_ball") + (("r_toe",) if toe else ()) if support_land in ("both", "R") else ())
        for _ in range(8):
            bake()
            flight_keys(t0, tau)
            # exact touchdown: lowest landing-foot point reaches the floor
            a, b = t0 + tau - 0.03, t0 + tau + 0.03
            fa, fb = m.foot_low(a, names), m.foot_low(b, names)
            if not (fa > 0 > fb):
                raise Infeasible("no clean touchdown")
            for _ in range(100):
                mid = 0.5 * (a + b)
                if m.foot_low(mid, names) > 0:
                    a = mid
                else:
                    b = mid
                if b - a < 1e-14:
                    break
            tL = b
            if abs(tL - (t0 + tau)) < 1e-13:
                break
            tau = tL - t0
        else:
            raise Infeasible("touchdown did not settle")
        tL = t0 + tau
        # no foot may go through the floor during the flight
        n = max(4, int(tau / 0.005))
        for i in range(1, n):
            t = t0 + tau * i / n
            low = m.foot_low(t, allf)
            if low < (-1e-3 if t - t0 < 0.03 else 0.0):
                raise Infeasible("foot below floor in flight (%.4f at %.3f)" % (low, t - t0))
        if support_land != "both":
            o = ("r_heel", "r_ball") if support_land == "L" else ("l_heel", "l_ball")
            if m.foot_low(tL, o) < 0.005:
                raise Infeasible("trailing foot touches down too")
        fl.t1 = tL
        self.pin(tL)
        m.z.add_ballistic(t0, tL, z0, v0z)
        zL = z0 + v0z * tau - 0.5 * G * tau * tau
        vL = v0z - G * tau
        st, C, _, _ = m.state(tL)
        if support_land == "both":
            ax = 0.5 * (st["l_ball"][0] + st["r_ball"][0])
            ay = 0.5 * (st["l_ball"][1] + st["r_ball"][1])
        else:
            q = st[("l_" if support_land == "L" else "r_") + "ball"]
            ax, ay = q[0], q[1]
        self.flights.append({
            "t_takeoff_s": t0, "t_land_s": tL, "flight_time_s": tau,
            "t_apex_s": t0 + v0z / G,
            "jump_height_m": G * tau * tau / 8.0,        # from the flight time, as mats and apps report
            "com_rise_m": v0z * v0z / (2 * G),            # the COM's rise to the apex, as force plates report
            "takeoff_velocity_m_s": v0z,
            "takeoff_velocity_h_m_s": math.hypot(vxy[0], vxy[1]),
        })
        c = Contact(tL, support_land, (ax, ay), solve_land)
        m.phases.append(c)
        self.landing = (tL, (C[0] - ax, C[1] - ay), (vxy[0], vxy[1]), zL, vL)
        return c

    def pin(self, t):
        """Key every track at t with its current value and rate, so later keys cannot
        change the motion before t."""
        for tr in self.m.tracks.values():
            if tr.ts[-1] < t:
                tr.key(t, tr(t), tr.rate_at(t))

    def flight_drift(self, sd):
        g = self.rng.gauss
        return (g(0, sd), g(0, sd))

    # ---- countermovement jump --------------------------------------------
    def cmj(self, kind):
        rng = self.rng
        u = rng.uniform
        g = rng.gauss
        m = self.m
        ph = m.phases[-1]
        ta = self.t
        if kind == "low":
            h, dip = u(0.05, 0.15), u(0.10, 0.22)
        elif kind == "high":
            h, dip = u(0.25, 0.50), u(0.15, 0.35)
        else:
            h, dip = u(0.15, 0.40), u(0.15, 0.32)
        v0 = math.sqrt(2 * G * h)
        t_down = u(0.40, 0.65) * (0.6 + dip / 0.4)
        tb = ta + t_down
        zb = self.z_st - dip
        ab = min(u(0.5, 1.3) * G, 4.0 * dip / t_down ** 2)
        sym = kind != "funny"
        arm_back = -u(35, 75) * D2R
        arm_to = (u(100, 165) if kind != "low" else u(20, 100)) * D2R
        dl = 0.0 if sym else u(-25, 25) * D2R
        s_to = u(0.16, 0.28)  # knees a little bent at toe-off: the plantarflexed foot carries the rest of the reach
        ph_to = u(36, 48) * D2R  # toe-off on a steep foot: the ankle about 0.06 x stature above its flat level, as motion capture shows
        lean_b = u(22, 42) * D2R * (dip / 0.3) ** 0.5
        self.key(tb - 0.04, af_L=arm_back + dl, af_R=arm_back - dl, el_L=u(10, 35) * D2R,
                 el_R=u(10, 35) * D2R, aa_L=self.rest["aa_L"], aa_R=self.rest["aa_R"])
        self.key(tb, lean=lean_b, hp=u(5, 20) * D2R)
        t_heel = u(0.10, 0.16)
        p_to = m.pose(tb)
        for k, v in (("lean", 0.0), ("ph_L", ph_to), ("ph_R", ph_to), ("af_L", arm_to + dl),
                     ("af_R", arm_to - dl), ("el_L", u(5, 30) * D2R), ("el_R", u(5, 30) * D2R),
                     ("tp", 0.0), ("tr", 0.0), ("hp", u(-5, 5) * D2R)):
            p_to[k] = v
        z_to, dx_to, dy_to = self.natural(p_to, ph, s_to)
        tup = 2 * (z_to - zb) / v0 * u(1.0, 1.2)
        t0 = tb + tup
        if t0 - t_heel <= tb + 0.02:
            raise Infeasible("propulsion too short")
        ra = u(2.0, 5.0)
        r_ph = u(7, 13)
        self.key(t0 - t_heel, ph_L=0.0, ph_R=0.0)
        self.key(t0, lean=0.0, hp=p_to["hp"], ph_L=(ph_to, r_ph), ph_R=(ph_to, r_ph),
                 af_L=(arm_to + dl, ra), af_R=(arm_to - dl, ra), el_L=p_to["el_L"], el_R=p_to["el_R"])
        m.z.add_quintic(ta, tb, self.z_st, 0.0, 0.0, zb, 0.0, ab)
        m.z.add_quintic(tb, t0, zb, 0.0, ab, z_to, v0, A_FREE)
        vxy = self.flight_drift(0.06 if sym else 0.12)
        db = (self.d[0] + g(0, 0.01), self.d[1] + g(0, 0.01))
        dto = (self.d[0] + g(0, 0.01), self.d[1] + g(0, 0.01))
        self.hpiece(ph, ta, tb, self.d, (0, 0), db, (0, 0))
        self.hpiece(ph, tb, t0, db, (0, 0), dto, vxy)
        self.check(ta, t0)
        # flight programme
        c_mid = u(0.05, 0.35) if kind != "funny" else u(0.7, 1.25)
        fun = {}
        if kind == "funny":
            fun = {"sw_L": u(10, 60) * D2R, "sw_R": u(10, 60) * D2R, "twist": u(-40, 40) * D2R,
                   "bend": u(-12, 12) * D2R, "aa_L": u(10, 120) * D2R, "aa_R": u(10, 120) * D2R,
                   "dc": u(-0.3, 0.3), "af_L": u(-20, 170) * D2R, "af_R": u(-20, 170) * D2R}
        c_L = u(0.08, 0.22)
        ph_L = u(34, 46) * D2R  # toes first, the heel about as high as at take-off (motion capture)
        af_L = u(20, 80) * D2R
        lean_L = u(3, 12) * D2R
        apex_af = arm_to + u(0, 20) * D2R
        u_dph = u(0.03, 0.06)
        lean_mid = (u(-5, 20) if kind == "funny" else u(-3, 8)) * D2R
        hp_L = u(0, 15) * D2R
        ph_fl = u(30, 50) * D2R

        def keys(t0_, tau):
            tm = t0_ + max(0.07, 0.45 * tau)
            tl = t0_ + tau
            d_ph = min(0.3 * tau, u_dph)
            self.key(t0_ + d_ph, ph_L=ph_to + 0.5 * r_ph * d_ph, ph_R=ph_to + 0.5 * r_ph * d_ph)
            self.key(t0_ + min(0.45 * tau, max(0.1, 0.3 * tau)), ph_L=ph_fl, ph_R=ph_fl)
            if kind == "funny":
                self.key(tm, c_L=c_mid + fun["dc"], c_R=c_mid - fun["dc"], sw_L=fun["sw_L"],
                         sw_R=fun["sw_R"], twist=fun["twist"], bend=fun["bend"],
                         aa_L=fun["aa_L"], aa_R=fun["aa_R"], af_L=fun["af_L"], af_R=fun["af_R"],
                         lean=lean_mid)
            else:
                self.key(tm, c_L=c_mid, c_R=c_mid, af_L=apex_af, af_R=apex_af, lean=lean_mid)
            self.key(tl, c_L=(c_L, -0.5), c_R=(c_L, -0.5), sw_L=0.0, sw_R=0.0, twist=0.0, bend=0.0,
                     ph_L=ph_L, ph_R=ph_L, af_L=af_L, af_R=af_L, lean=lean_L,
                     aa_L=self.rest["aa_L"], aa_R=self.rest["aa_R"], tp=0.0, tr=0.0, hp=hp_L)
            return c_L, c_L
        c = self.fly(t0, z_to, v0, vxy, keys, "both")
        tL, dL, vLxy, zL, vL = self.landing
        # absorption and recovery
        dip2 = u(0.10, 0.30) if kind != "low" else u(0.05, 0.16)
        z_abs = min(zL, self.z_st) - dip2
        t_abs = max(0.12, (zL - z_abs) / abs(vL) * u(1.7, 2.3))
        tc = tL + t_abs
        td = tc + u(0.5, 0.9)
        # bounded so the rise back to standing does not overshoot the standing height
        ac = min(u(0.3, 1.0) * G, 4.0 * (self.z_st - z_abs) / (td - tc) ** 2)
        m.z.add_quintic(tL, tc, zL, vL, A_FREE, z_abs, 0.0, ac)
        m.z.add_quintic(tc, td, z_abs, 0.0, ac, self.z_st, 0.0, 0.0)
        dmid = (self.dbal[0] + g(0, 0.01), self.dbal[1] + g(0, 0.01))
        self.hpiece(c, tL, tc, dL, vLxy, dmid, (0, 0))
        self.hpiece(c, tc, td, dmid, (0, 0), self.dbal, (0, 0))
        self.d = self.dbal
        self.key(tL + t_abs * u(0.5, 0.8), ph_L=0.0, ph_R=0.0)
        self.key(tc, lean=u(15, 35) * D2R, af_L=u(10, 50) * D2R, af_R=u(10, 50) * D2R)
        rest = dict(self.rest)
        rest.update(tp=0.0, tr=0.0, c_L=S_STAND, c_R=S_STAND)
        rest.pop("yaw")
        self.key(td, **rest)
        self.t = td
        self.check(tL, td)

    # ---- jumping jacks ----------------------------------------------------
    def jacks(self, n):
        rng = self.rng
        u = rng.uniform
        g = rng.gauss
        m = self.m
        ph = m.phases[-1]
        ta = self.t
        dip = u(0.05, 0.12)
        tb = ta + u(0.25, 0.4)
        zb = self.z_st - dip
        ab = u(0.5, 1.2) * G
        v0 = math.sqrt(2 * G * u(0.04, 0.12))
        ph_c = u(10, 25) * D2R
        s_to = u(0.08, 0.18)
        p_to = m.pose(tb)
        p_to["ph_L"] = p_to["ph_R"] = ph_c
        z_to = self.natural(p_to, ph, s_to)[0]
        t0 = tb + max(0.12, 2 * (z_to - zb) / v0 * u(1.0, 1.2))
        self.key(tb, ph_L=ph_c * 0.5, ph_R=ph_c * 0.5, lean=u(3, 10) * D2R)
        r_ph = u(5, 9)
        self.key(t0, ph_L=(ph_c, r_ph), ph_R=(ph_c, r_ph), lean=0.0)
        m.z.add_quintic(ta, tb, self.z_st, 0.0, 0.0, zb, 0.0, ab)
        m.z.add_quintic(tb, t0, zb, 0.0, ab, z_to, v0, A_FREE)
        vxy = self.flight_drift(0.04)
        self.hpiece(ph, ta, t0, self.d, (0, 0), self.d, vxy)
        self.check(ta, t0)
        leg_open = u(10, 18) * D2R
        arm_open = u(140, 175) * D2R
        closed_ab, closed_aa = self.rest["ab_L"], self.rest["aa_L"]
        z0, vz = z_to, v0
        for k in range(n):
            opening = (k % 2 == 0)
            last = (k == n - 1)
            abv = leg_open if (opening and not last) else closed_ab
            aav = arm_open if (opening and not last) else closed_aa
            c_fl = u(0.15, 0.3)
            c_land = u(0.08, 0.2)

            def keys(t0_, tau, abv=abv, aav=aav, c_fl=c_fl, c_land=c_land):
                d = min(0.04, 0.2 * tau)
                self.key(t0_ + d, ph_L=ph_c + 0.5 * r_ph * d, ph_R=ph_c + 0.5 * r_ph * d)
                self.key(t0_ + max(0.07, 0.5 * tau), c_L=c_fl, c_R=c_fl)
                self.key(t0_ + tau, c_L=(c_land, -0.3), c_R=(c_land, -0.3), ab_L=abv, ab_R=abv,
                         aa_L=aav, aa_R=aav, tp=0.0, tr=0.0, ph_L=ph_c, ph_R=ph_c)
                return c_land, c_land
            c = self.fly(t0, z0, vz, vxy, keys, "both")
            tL, dL, vLxy, zL, vL = self.landing
            if last:
                break
            tc = u(0.14, 0.26)
            vz = math.sqrt(2 * G * u(0.04, 0.12))
            s_to = u(0.08, 0.18)
            t1 = tL + tc
            self.key(t1, ab_L=abv, ab_R=abv, ph_L=(ph_c, r_ph), ph_R=(ph_c, r_ph), aa_L=aav, aa_R=aav)
            p_to = m.pose(t1)
            z0, dx, dy = self.natural(p_to, c, s_to)
            vxy = self.flight_drift(0.04)
            m.z.add_quintic(tL, t1, zL, vL, A_FREE, z0, vz, A_FREE)
            self.hpiece(c, tL, t1, dL, vLxy, (dx + g(0, 0.005), dy + g(0, 0.005)), vxy)
            self.check(tL, t1)
            t0 = t1
        # final absorption
        dip2 = u(0.05, 0.15)
        z_abs = min(zL, self.z_st) - dip2
        t_abs = max(0.12, (zL - z_abs) / abs(vL) * u(1.7, 2.3))
        tc = tL + t_abs
        td = tc + u(0.4, 0.8)
        # bounded so the rise back to standing does not overshoot the standing height
        ac = min(u(0.3, 1.0) * G, 4.0 * (self.z_st - z_abs) / (td - tc) ** 2)
        m.z.add_quintic(tL, tc, zL, vL, A_FREE, z_abs, 0.0, ac)
        m.z.add_quintic(tc, td, z_abs, 0.0, ac, self.z_st, 0.0, 0.0)
        self.hpiece(c, tL, td, dL, vLxy, self.dbal, (0, 0))
        self.d = self.dbal
        self.key(tL + t_abs * u(0.5, 0.8), ph_L=0.0, ph_R=0.0)
        rest = dict(self.rest)
        rest.update(tp=0.0, tr=0.0, c_L=S_STAND, c_R=S_STAND)
        rest.pop("yaw")
        self.key(td, **rest)
        self.t = td
        self.check(tL, td)

    # ---- walking (never airborne) -------------------------------------------
    def walk(self, dur, across, direction):
        """Pose-driven gait: the lowest foot point is kept on the floor."""
        rng = self.rng
        u = rng.uniform
        m = self.m
        t0 = self.t
        t1 = t0 + dur
        ph = m.phases[-1]
        ph.t1 = t0
        st = m.state(t0)
        root0 = st[0]
        C0 = st[1]
        f_step = u(1.6, 2.0)
        w = math.pi * f_step            # leg cycle angular frequency (2 steps per cycle)
        amp = (u(14, 20) if across else u(2, 6)) * D2R
        c_sw = u(0.35, 0.55) if across else u(0.6, 0.9)
        c_st = u(0.04, 0.10) if across else u(0.12, 0.22)
        speed = 2 * self.sub.L["thigh"] * 2.0 * math.sin(amp) * f_step * 0.5 if across else 0.0
        ramp = 0.6
        yaw = self.rest["yaw"]
        fwd = (-math.sin(yaw), math.cos(yaw))
        pel = (root0["l_hip"][0] + root0["r_hip"][0]) * 0.5, (root0["l_hip"][1] + root0["r_hip"][1]) * 0.5
        rest = dict(self.rest)

        def env(t):
            a = min(1.0, max(0.0, (t - t0) / ramp), max(0.0, (t1 - t) / ramp))
            return a * a * (3 - 2 * a)

        def dist(t):
            # integral of speed * env (numerically exact enough: smoothstep ramps)
            if t <= t0:
                return 0.0
            tt = min(t, t1)
            n = 40
            h = (tt - t0) / n
            acc = 0.5 * (env(t0) + env(tt))
            for i in range(1, n):
                acc += env(t0 + i * h)
            return speed * acc * h

        def path(t):
            d = dist(t)
            return (pel[0] + fwd[0] * d, pel[1] + fwd[1] * d)
        m.path = path
        wk = Contact(t0, "both", None, walk=True)
        m.phases.append(wk)
        # per-channel functions sampled into tracks every 1/20 s
        dt = 0.05
        t = t0 + dt
        while t < t1 + 1e-9:
            e = env(t)
            ph_ = w * (t - t0)
            sL = math.sin(ph_)
            kv = {}
            kv["sw_L"] = (e * amp * math.cos(ph_), -e * amp * w * math.sin(ph_))
            kv["sw_R"] = (-e * amp * math.cos(ph_), e * amp * w * math.sin(ph_))
            kv["c_L"] = S_STAND + e * (c_sw * max(0.0, -sL) ** 2 + c_st * max(0.0, sL))
            kv["c_R"] = S_STAND + e * (c_sw * max(0.0, sL) ** 2 + c_st * max(0.0, -sL))
            kv["ph_L"] = e * (u(12, 18) * D2R * max(0.0, -math.cos(ph_ + 0.6)) if across else 0.0)
            kv["ph_R"] = e * (u(12, 18) * D2R * max(0.0, math.cos(ph_ + 0.6)) if across else 0.0)
            kv["af_L"] = rest["af_L"] - e * 1.5 * amp * math.cos(ph_)
            kv["af_R"] = rest["af_R"] + e * 1.5 * amp * math.cos(ph_)
            kv["el_L"] = rest["el_L"] + e * 0.3
            kv["el_R"] = rest["el_R"] + e * 0.3
            kv["twist"] = e * 0.3 * amp * math.cos(ph_)
            kv["tr"] = e * 0.02 * math.sin(ph_)
            self.key(t, **kv)
            t += dt
        self.key(t1 + 0.3, **{k: v for k, v in rest.items() if k != "yaw"},
                 sw_L=0.0, sw_R=0.0, twist=0.0, tr=0.0, tp=0.0, ph_L=0.0, ph_R=0.0)
        self.t = t1 + 0.3
        wk.t1 = self.t
        st = m.state(self.t)[0]
        ax = 0.5 * (st["l_ball"][0] + st["r_ball"][0])
        ay = 0.5 * (st["l_ball"][1] + st["r_ball"][1])
        m.phases.append(Contact(self.t, "both", (ax, ay)))
        m.z.add_const(t0, self.t, self.z_st)
        self.d = self.dbal
        _ = C0

    # ---- lateral run ------------------------------------------------------
    def run(self, direction, dist):
        """Run across the view: single-leg contacts, flights of 0.10-0.17 s, then stop."""
        rng = self.rng
        u = rng.uniform
        m = self.m
        t1 = self.t
        self.pin(t1)
        prev = m.phases[-1]
        x = m._solve(m.pose(t1), prev, t1)
        m.tracks["tp"].key(t1 + 1e-9, x[1], 0.0)
        m.tracks["tr"].key(t1 + 1e-9, x[2], 0.0)
        X = "L" if rng.random() < 0.5 else "R"
        st, C, _, _ = m.state(t1)
        prev.t1 = t1
        ball = st[("l_" if X == "L" else "r_") + "ball"]
        c = Contact(t1, X, (ball[0], ball[1]), ("sw_" + X, "tr"))
        m.phases.append(c)
        d0 = (C[0] - ball[0], C[1] - ball[1])
        v_run = u(2.2, 3.2)
        lean = u(4, 10) * D2R
        sig_t = u(16, 24) * D2R
        sig_l = u(12, 20) * D2R
        self._sig_l = sig_l
        # start step: the free leg lifts and swings forward, the support leg pushes
        t0 = t1 + u(0.40, 0.55)
        O = "R" if X == "L" else "L"
        tm = 0.5 * (t1 + t0)
        self.key(tm, **{"c_" + O: u(0.7, 1.0), "sw_" + O: u(5, 15) * D2R})
        ph_to = u(20, 32) * D2R
        v1 = u(1.5, 2.0)
        self.key(t0, **{"c_" + O: u(0.4, 0.6), "sw_" + O: u(15, 25) * D2R, "ph_" + X: (ph_to, 6.0),
                        "tp": lean, "af_" + X: 35 * D2R, "af_" + O: -30 * D2R,
                        "el_L": 80 * D2R, "el_R": 80 * D2R})
        z0, vz, vxy = self._run_takeoff(c, X, t1, t0, self.z_st, 0.0, 0.0, d0, (0.0, 0.0), v1,
                                        direction, sig_t, ph_to)
        travelled = 0.0
        k = 0
        while True:
            k += 1
            c_land = self._c_land
            sup_to = X
            X, O = O, X        # the free leg lands

            def keys(t0_, tau, X=X, O=O, c_land=c_land, c_hi=u(0.8, 1.2), s_l=sig_l,
                     s_b=-u(10, 20) * D2R):
                self.key(t0_ + max(0.5 * tau, 0.07), **{"c_" + O: c_hi, "sw_" + O: s_b})
                self.key(t0_ + tau, **{"c_" + X: (c_land, -0.5), "sw_" + X: s_l, "ph_" + X: 0.0,
                                       "tp": lean, "tr": 0.0, "af_" + X: -30 * D2R,
                                       "af_" + O: 35 * D2R})
                return c_land, c_land
            cc = self.fly(t0, z0, vz, vxy, keys, X, ("sw_" + X, "tr"))
            tL, dL, vLxy, zL, vL = self.landing
            if not 0.095 <= tL - t0 <= 0.175:
                raise Infeasible("run flight of %.3f s" % (tL - t0))
            travelled += abs(vxy[0]) * (tL - t0) + 0.6
            if travelled >= dist - 0.8 or k >= 8:
                break
            t0 = tL + u(0.18, 0.26)
            v_next = v_run if travelled < dist - 2.0 else u(1.2, 1.6)
            self.key(0.5 * (tL + t0), **{"c_" + O: u(0.9, 1.2), "sw_" + O: 0.0})
            self.key(t0, **{"c_" + O: u(0.4, 0.6), "sw_" + O: u(15, 25) * D2R,
                            "ph_" + X: (ph_to, 6.0), "af_" + X: 35 * D2R, "af_" + O: -30 * D2R})
            z0, vz, vxy = self._run_takeoff(cc, X, tL, t0, zL, vL, u(1.0, 2.0) * G, dL, vLxy,
                                            v_next, direction, sig_t, ph_to)
        # stop on the support leg, bring the free foot down beside it
        Y, O = X, O
        rest = dict(self.rest)
        rest.pop("yaw")
        rest.update(tp=0.0, tr=0.0, sw_L=0.0, sw_R=0.0, ph_L=0.0, ph_R=0.0)
        p_end = m.pose(tL)
        p_end.update(rest)
        z_end, dxe, dye = self.natural(p_end, cc, S_STAND)
        t_stop = tL + max(0.45, 2.5 * abs(dxe - dL[0]) / max(0.3, abs(vLxy[0])))
        self.key(0.5 * (tL + t_stop), **{"c_" + O: u(0.5, 0.8), "sw_" + O: 0.0})
        self.key(t_stop, **rest)
        m.z.add_quintic(tL, t_stop, zL, vL, u(1.0, 2.0) * G, z_end, 0.0, 0.0)
        self.hpiece(cc, tL, t_stop, dL, vLxy, (dxe, dye), (0.0, 0.0))
        self.check(tL, t_stop)
        cc.t1 = t_stop
        st = m.state(t_stop)[0]
        ax = 0.5 * (st["l_ball"][0] + st["r_ball"][0])
        ay = 0.5 * (st["l_ball"][1] + st["r_ball"][1])
        m.phases.append(Contact(t_stop, "both", (ax, ay)))
        m.z.add_const(t_stop, t_stop + 1e-3, z_end)
        self.z_st = z_end
        self.d = self.dbal
        self.t = t_stop

    def _run_takeoff(self, c, X, ta, t0, za, va, aa, da, vda, v, direction, sig_t, ph_to):
        """Design one support phase on leg X ending in a take-off at t0."""
        m = self.m
        u = self.rng.uniform
        p_to = m.pose(t0)
        p_to["sw_" + X] = -sig_t
        p_to["ph_" + X] = ph_to
        s_to = u(0.10, 0.2)
        z_to, dx, dy = self.natural(p_to, c, s_to)
        # the next landing pose fixes the landing height; pick vz for the drawn flight time
        O = "R" if X == "L" else "L"
        self._c_land = u(0.08, 0.18)
        p_l = dict(p_to)
        p_l.update({"sw_" + O: sig_l_of(self), "ph_" + O: 0.0, "c_" + X: 1.0})
        probe = Contact(0.0, O, (0.0, 0.0), ("sw_" + O, "tr"))
        z_l = self.natural(p_l, probe, self._c_land)[0]
        t_f = u(0.10, 0.17)
        vz = (z_l - z_to) / t_f + G * t_f / 2
        if vz <= 0.05:
            raise Infeasible("run flight too flat")
        vxy = (direction * v, self.rng.gauss(0, 0.03))
        m.z.add_quintic(ta, t0, za, va, aa, z_to, vz, u(-0.6, -0.2) * G)
        self.hpiece(c, ta, t0, da, vda, (dx, dy), vxy)
        self.check(ta, t0, 0.05)
        return z_to, vz, vxy


def sig_l_of(b):
    return b._sig_l
