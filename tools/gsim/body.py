"""Forward kinematics of the articulated body (body frame: x right, y forward, z up,
origin at the mid-point of the hip joint centres). All angles in radians."""

import math

KNEE_B = math.radians(70.0)   # thigh forward tilt per unit leg flexion
KNEE_A = math.radians(40.0)   # shank forward tilt per unit leg flexion

# COCO-17 order
COCO = ("nose", "l_eye", "r_eye", "l_ear", "r_ear", "l_sho", "r_sho", "l_elb", "r_elb",
        "l_wri", "r_wri", "l_hip", "r_hip", "l_knee", "r_knee", "l_ank", "r_ank")

# pose channels (see docs/simulator.md); per-side channels end in _L / _R
CHANNELS = ("tp", "tr", "yaw", "lean", "bend", "twist", "hp", "hy",
            "af_L", "af_R", "aa_L", "aa_R", "el_L", "el_R",
            "sw_L", "sw_R", "c_L", "c_R", "ab_L", "ab_R", "ph_L", "ph_R")


def rx(a):
    c, s = math.cos(a), math.sin(a)
    return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))


def ry(a):
    c, s = math.cos(a), math.sin(a)
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))


def rz(a):
    c, s = math.cos(a), math.sin(a)
    return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))


def mm(A, B):
    (a0, a1, a2), (a3, a4, a5), (a6, a7, a8) = A
    (b0, b1, b2), (b3, b4, b5), (b6, b7, b8) = B
    return ((a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8),
            (a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8),
            (a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8))


def mv(A, v):
    return (A[0][0] * v[0] + A[0][1] * v[1] + A[0][2] * v[2],
            A[1][0] * v[0] + A[1][1] * v[1] + A[1][2] * v[2],
            A[2][0] * v[0] + A[2][1] * v[1] + A[2][2] * v[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def axpy(k, a, b):
    """b + k a"""
    return (b[0] + k * a[0], b[1] + k * a[1], b[2] + k * a[2])


def upper(sub, p):
    """Trunk, head and arms: (points dict, mass-weighted COM sum, upper mass)."""
    L = sub.L
    hd = sub.head
    m = sub.mass
    cf = sub.comf
    Rt = mm(mm(rx(-p["lean"]), ry(p["bend"])), rz(p["twist"]))
    c7 = mv(Rt, (0.0, 0.0, L["trunk"]))
    pts = {"c7": c7}
    Rh = mm(Rt, mm(rx(-p["hp"]), rz(p["hy"])))
    vtx = add(c7, mv(Rh, hd["vertex"]))
    pts["vertex"] = vtx
    pts["nose"] = add(c7, mv(Rh, (0.0, hd["nose_y"], hd["nose_z"])))
    pts["l_eye"] = add(c7, mv(Rh, (-hd["eye_x"], hd["eye_y"], hd["eye_z"])))
    pts["r_eye"] = add(c7, mv(Rh, (hd["eye_x"], hd["eye_y"], hd["eye_z"])))
    pts["l_ear"] = add(c7, mv(Rh, (-hd["ear_x"], hd["ear_y"], hd["ear_z"])))
    pts["r_ear"] = add(c7, mv(Rh, (hd["ear_x"], hd["ear_y"], hd["ear_z"])))
    # head+neck COM on the vertex->C7 line; trunk COM on the C7->mid-hip line
    ch = axpy(cf["head"], (c7[0] - vtx[0], c7[1] - vtx[1], c7[2] - vtx[2]), vtx)
    ct = ((1.0 - cf["trunk"]) * c7[0], (1.0 - cf["trunk"]) * c7[1], (1.0 - cf["trunk"]) * c7[2])
    msum = [m["head"] * ch[0] + m["trunk"] * ct[0],
            m["head"] * ch[1] + m["trunk"] * ct[1],
            m["head"] * ch[2] + m["trunk"] * ct[2]]
    segs = [("head", vtx, c7, ch), ("trunk", c7, (0.0, 0.0, 0.0), ct)]
    half = 0.5 * L["sho_w"]
    for side, sg in (("L", -1.0), ("R", 1.0)):
        s = "l_" if side == "L" else "r_"
        sho = mv(Rt, (sg * half, L["sho_fwd"], L["trunk"] - L["sho_drop"]))
        Ra = mm(Rt, mm(ry(-sg * p["aa_" + side]), rx(p["af_" + side])))
        u = mv(Ra, (0.0, 0.0, -1.0))
        e = p["el_" + side]
        f = mv(Ra, (0.0, math.sin(e), -math.cos(e)))
        elb = axpy(L["uarm"], u, sho)
        wri = axpy(L["farm"], f, elb)
        cu = axpy(cf["uarm"] * L["uarm"], u, sho)
        cfa = axpy(cf["farm"] * L["farm"], f, elb)
        chd = axpy(cf["hand"] * L["hand"], f, wri)
        pts[s + "sho"] = sho
        pts[s + "elb"] = elb
        pts[s + "wri"] = wri
        pts[s + "hand_tip"] = axpy(L["hand"], f, wri)
        for k in range(3):
            msum[k] += m["uarm"] * cu[k] + m["farm"] * cfa[k] + m["hand"] * chd[k]
        segs += [("uarm_" + side, sho, elb, cu), ("farm_" + side, elb, wri, cfa),
                 ("hand_" + side, wri, pts[s + "hand_tip"], chd)]
    return pts, msum, segs


def leg(sub, p, side, c):
    """One leg with flexion c: (points dict, mass-weighted COM sum, segments)."""
    L = sub.L
    m = sub.mass
    cf = sub.comf
    sg = -1.0 if side == "L" else 1.0
    s = "l_" if side == "L" else "r_"
    sw = p["sw_" + side]
    b = sw + c * KNEE_B
    a = -sw + c * KNEE_A
    Rab = ry(-sg * p["ab_" + side])
    hip = (sg * 0.5 * L["hip_w"], 0.0, 0.0)
    th = mv(Rab, (0.0, math.sin(b), -math.cos(b)))
    sh = mv(Rab, (0.0, -math.sin(a), -math.cos(a)))
    knee = axpy(L["thigh"], th, hip)
    ank = axpy(L["shank"], sh, knee)
    Rf = mm(rz(-sg * L["toe_out"]), rx(-p["ph_" + side]))
    ha = L["ankle_h"]
    heel = add(ank, mv(Rf, (0.0, -L["heel_back"], -ha)))
    ball = add(ank, mv(Rf, (0.0, L["ball_fwd"], -ha)))
    toe = add(ank, mv(Rf, (0.0, L["toe_fwd"], -ha)))
    flen = L["heel_back"] + L["toe_fwd"]
    cfo = add(ank, mv(Rf, (0.0, -L["heel_back"] + cf["foot"] * flen, -0.6 * ha)))
    cth = axpy(cf["thigh"] * L["thigh"], th, hip)
    csh = axpy(cf["shank"] * L["shank"], sh, knee)
    msum = [m["thigh"] * cth[k] + m["shank"] * csh[k] + m["foot"] * cfo[k] for k in range(3)]
    pts = {s + "hip": hip, s + "knee": knee, s + "ank": ank, s + "heel": heel,
           s + "ball": ball, s + "toe": toe}
    segs = [("thigh_" + side, hip, knee, cth), ("shank_" + side, knee, ank, csh),
            ("foot_" + side, heel, toe, cfo)]
    return pts, msum, segs


def tilt_matrix(p):
    """Whole-body tilt (forward pitch tp, rightward roll tr) about the pelvis."""
    return mm(rx(-p["tp"]), ry(p["tr"]))


def neutral_pose():
    return {k: 0.0 for k in CHANNELS}
