"""Motion-capture recordings filmed by a virtual camera (docs/mocap.md).

Markers (OpenSim TRC: metres, Y up, X forward, Z to the right) become the 3D
positions of BlazePose-33 / COCO-17 keypoints; force plates (OpenSim MOT) give
the flights' truth. Standard library only.
"""

import math

from . import anthro

G = 9.81
AIRBORNE_N = 20.0     # summed vertical force below this: no foot on a plate
GAP_FILL_MAX = 10     # marker gaps up to this many samples are bridged linearly


# ---- files ---------------------------------------------------------------------

class TrcError(ValueError):
    pass


def load_trc(path):
    """-> (times_s list, {marker: [(x, y, z) or None per sample]}, rate_hz)."""
    with open(path) as f:
        lines = f.read().split("\n")
    if len(lines) < 6 or not lines[0].startswith("PathFileType"):
        raise TrcError("%s:1: not a TRC file (no PathFileType header)" % path)
    keys = lines[1].split("\t")
    vals = lines[2].split("\t")
    head = dict(zip(keys, vals))
    try:
        rate = float(head["DataRate"])
    except (KeyError, ValueError):
        raise TrcError("%s:3: field 'DataRate': missing or not a number" % path)
    if head.get("Units", "m").strip() not in ("m", ""):
        raise TrcError("%s:3: field 'Units': %r, only metres are read" % (path, head.get("Units")))
    names = [n.strip() for n in lines[3].split("\t")[2:] if n.strip()]
    times, cols = [], {n: [] for n in names}
    for ln, line in enumerate(lines[5:], start=6):
        if not line.strip():
            continue
        v = line.split("\t")
        try:
            t = float(v[1])
        except (IndexError, ValueError):
            raise TrcError("%s:%d: field 'Time': not a number" % (path, ln))
        if times and not t > times[-1]:
            raise TrcError("%s:%d: field 'Time': %g does not increase" % (path, ln, t))
        times.append(t)
        for k, n in enumerate(names):
            c = v[2 + 3 * k:5 + 3 * k]
            try:
                p = tuple(float(x) for x in c) if len(c) == 3 and all(x.strip() for x in c) else None
            except ValueError:
                raise TrcError("%s:%d: field '%s': not a number" % (path, ln, n))
            if p is not None and not all(math.isfinite(x) for x in p):
                p = None
            cols[n].append(p)
    if not times:
        raise TrcError("%s: no samples" % path)
    for n in names:
        fill_gaps(cols[n])
    return times, cols, rate


def fill_gaps(seq, max_len=GAP_FILL_MAX):
    """Bridge short runs of None linearly (optical markers drop out for a few samples)."""
    i, n = 0, len(seq)
    while i < n:
        if seq[i] is not None:
            i += 1
            continue
        j = i
        while j < n and seq[j] is None:
            j += 1
        if 0 < i and j < n and j - i <= max_len:
            a, b = seq[i - 1], seq[j]
            for k in range(i, j):
                w = (k - i + 1) / (j - i + 1)
                seq[k] = tuple(a[m] + w * (b[m] - a[m]) for m in range(3))
        i = j


def load_mot(path):
    """-> {column: [values]} of an OpenSim MOT/STO table."""
    with open(path) as f:
        lines = f.read().split("\n")
    try:
        end = next(k for k, l in enumerate(lines) if l.strip().lower() == "endheader")
    except StopIteration:
        raise TrcError("%s: no 'endheader' line" % path)
    hdr = lines[end + 1].split("\t")
    cols = {h.strip(): [] for h in hdr}
    for ln, line in enumerate(lines[end + 2:], start=end + 3):
        if not line.strip():
            continue
        v = line.split("\t")
        if len(v) != len(hdr):
            raise TrcError("%s:%d: %d fields, the header has %d" % (path, ln, len(v), len(hdr)))
        for h, x in zip(hdr, v):
            try:
                cols[h.strip()].append(float(x))
            except ValueError:
                raise TrcError("%s:%d: field '%s': not a number" % (path, ln, h.strip()))
    return cols


# ---- force-plate truth -----------------------------------------------------------

def plate_force(mot):
    """Summed vertical ground force per sample (ground_force_*_vy columns)."""
    vy = [k for k in mot if k.startswith("ground_force_") and k.endswith("_vy")]
    if not vy:
        raise TrcError("no ground_force_*_vy column")
    n = len(mot["time"])
    return mot["time"], [sum(mot[k][i] for k in vy) for i in range(n)]


def _cross(t, f, i, level):
    """Time between samples i and i+1 where f crosses level (linear)."""
    f0, f1 = f[i], f[i + 1]
    w = (level - f0) / (f1 - f0) if f1 != f0 else 0.5
    return t[i] + w * (t[i + 1] - t[i])


def plate_phases(mot, min_air_s=0.08):
    """Airborne phases between plate contacts: [(t_off_s, t_on_s)], the crossings of
    AIRBORNE_N interpolated between samples; a phase before the first contact (the
    step off a box, whose start the plates cannot see) has t_off_s None."""
    t, f = plate_force(mot)
    air = [x < AIRBORNE_N for x in f]
    out = []
    i = 0
    n = len(t)
    while i < n:
        if not air[i]:
            i += 1
            continue
        j = i
        while j < n and air[j]:
            j += 1
        t_off = _cross(t, f, i - 1, AIRBORNE_N) if i > 0 else None
        t_on = _cross(t, f, j - 1, AIRBORNE_N) if j < n else None
        if t_on is not None and (t_off is None or t_on - t_off >= min_air_s):
            out.append((t_off, t_on))
        i = j
    return out


# ---- keypoints from markers -------------------------------------------------------

def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _mul(k, a):
    return (k * a[0], k * a[1], k * a[2])


def _mid(a, b):
    return None if a is None or b is None else _mul(0.5, _add(a, b))


def _unit(a):
    n = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    return None if n == 0 else _mul(1.0 / n, a)


def _cross3(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _axpy(p, *terms):
    for k, v in terms:
        p = _add(p, _mul(k, v))
    return p


# head landmarks: heights as fractions of stature (docs/anthropometry.md; the core
# measures stature from the same ratios), forward of C7 and to the side (m)
HEAD = {"vertex": (1.000, 0.07, 0.0), "eye": (0.936, 0.10, 0.032), "eye_in": (0.936, 0.11, 0.018),
        "eye_out": (0.936, 0.09, 0.048), "ear": (0.927, 0.02, 0.075), "nose": (0.910, 0.14, 0.0),
        "mouth": (0.890, 0.12, 0.025)}
C7_REL = 0.871        # C7's height as a fraction of stature when standing (measured on the shared subject)
KNEE_IN_M = 0.05      # the knee joint centre lies this far medial of the lateral knee marker
ANKLE_IN_M = 0.035    # ... and the ankle's of the lateral malleolus
SHOULDER_DOWN_M = 0.04  # the shoulder joint centre lies below the acromion marker
HAND_M = 0.08         # knuckles ahead of the wrist along the forearm


def body_frame(mk):
    """(up, right, forward) unit vectors of the body from markers mk: up along pelvis -> C7."""
    lh, rh, c7 = mk.get("L_HJC"), mk.get("R_HJC"), mk.get("C7")
    if lh is None or rh is None or c7 is None:
        return None
    pel = _mid(lh, rh)
    up = _unit(_sub(c7, pel))
    right = _unit(_sub(rh, lh))
    fwd = _unit(_cross3(up, right))
    right = _cross3(fwd, up)
    return up, right, fwd


def keypoints3d(mk, stature_m):
    """{name: (x, y, z) or None} of the keypoints both layouts use (and C7, the hand's
    tip) from the markers mk of one instant ({marker: point or None})."""
    fr = body_frame(mk)
    if fr is None:
        return None
    up, right, fwd = fr
    g = mk.get
    c7 = g("C7")
    kp = {"c7": c7}
    for name, (hrel, f_m, s_m) in HEAD.items():
        base = _axpy(c7, ((hrel - C7_REL) * stature_m, up), (f_m, fwd))
        if s_m == 0:
            kp[name] = base
        else:
            kp["l_" + name] = _axpy(base, (-s_m, right))
            kp["r_" + name] = _axpy(base, (s_m, right))
    for side, L, s in (("l", "L", -1.0), ("r", "R", 1.0)):
        lo = "r" if L == "R" else "L"   # the right leg's markers are lower-case r_ in these files
        sho = g(L + "_Shoulder")
        kp[side + "_sho"] = None if sho is None else _axpy(sho, (-SHOULDER_DOWN_M, up))
        kp[side + "_elb"] = _mid(g(L + "_elbow_lat"), g(L + "_elbow_med"))
        kp[side + "_wri"] = _mid(g(L + "_wrist_radius"), g(L + "_wrist_ulna"))
        kp[side + "_hip"] = g(L + "_HJC")
        knee = g(lo + "_knee")
        kp[side + "_kne"] = None if knee is None else _axpy(knee, (-s * KNEE_IN_M, right))
        ank = g(lo + "_ankle")
        kp[side + "_ank"] = None if ank is None else _axpy(ank, (-s * ANKLE_IN_M, right))
        kp[side + "_heel"] = g(lo + "_calc")
        kp[side + "_toe"] = g(lo + "_toe")
        e, w = kp[side + "_elb"], kp[side + "_wri"]
        if e is not None and w is not None:
            d = _unit(_sub(w, e))
            k = _axpy(w, (HAND_M, d))
            kp[side + "_index"] = _axpy(k, (0.02 * -s, right))
            kp[side + "_pinky"] = _axpy(k, (0.02 * s, right))
            kp[side + "_thumb"] = _axpy(w, (0.04, d), (0.03 * -s, right), (0.02, fwd))
            kp[side + "_tip"] = _axpy(w, (0.19, d))
        else:
            for n in ("index", "pinky", "thumb", "tip"):
                kp[side + "_" + n] = None
    return kp


BLAZEPOSE33 = ["nose", "l_eye_in", "l_eye", "l_eye_out", "r_eye_in", "r_eye", "r_eye_out", "l_ear", "r_ear",
               "l_mouth", "r_mouth", "l_sho", "r_sho", "l_elb", "r_elb", "l_wri", "r_wri", "l_pinky", "r_pinky",
               "l_index", "r_index", "l_thumb", "r_thumb", "l_hip", "r_hip", "l_kne", "r_kne", "l_ank", "r_ank",
               "l_heel", "r_heel", "l_toe", "r_toe"]
COCO17 = ["nose", "l_eye", "r_eye", "l_ear", "r_ear", "l_sho", "r_sho", "l_elb", "r_elb", "l_wri", "r_wri",
          "l_hip", "r_hip", "l_kne", "r_kne", "l_ank", "r_ank"]
LAYOUTS = {"blazepose33": BLAZEPOSE33, "coco17": COCO17}


def com3d(kp):
    """Whole-body centre of mass from the 3D keypoints (de Leva 1996, sex-averaged)."""
    mass = {k: 0.5 * (anthro.DELEVA_MASS["m"][k] + anthro.DELEVA_MASS["f"][k]) for k in anthro.DELEVA_MASS["m"]}
    frac = {k: 0.5 * (anthro.DELEVA_COM["m"][k] + anthro.DELEVA_COM["f"][k]) for k in anthro.DELEVA_COM["m"]}
    c7 = kp["c7"]
    segs = [("head", kp["vertex"], c7), ("trunk", c7, _mid(kp["l_hip"], kp["r_hip"]))]
    for s in ("l", "r"):
        segs += [("uarm", kp[s + "_sho"], kp[s + "_elb"]), ("farm", kp[s + "_elb"], kp[s + "_wri"]),
                 ("hand", kp[s + "_wri"], kp[s + "_tip"]), ("thigh", kp[s + "_hip"], kp[s + "_kne"]),
                 ("shank", kp[s + "_kne"], kp[s + "_ank"]), ("foot", kp[s + "_heel"], kp[s + "_toe"])]
    acc, wsum = (0.0, 0.0, 0.0), 0.0
    for name, a, b in segs:
        if a is None or b is None:
            return None
        p = _axpy(a, (frac[name], _sub(b, a)))
        acc = _axpy(acc, (mass[name], p))
        wsum += mass[name]
    return _mul(1.0 / wsum, acc)


def interp_markers(times, m, t):
    """Markers at time t (linear between samples; None outside or across a gap)."""
    if t < times[0] or t > times[-1]:
        return None
    rate = (len(times) - 1) / (times[-1] - times[0])
    k = min(int((t - times[0]) * rate), len(times) - 2)
    while k > 0 and times[k] > t:
        k -= 1
    while k < len(times) - 2 and times[k + 1] < t:
        k += 1
    w = (t - times[k]) / (times[k + 1] - times[k])
    out = {}
    for n, seq in m.items():
        a, b = seq[k], seq[k + 1]
        out[n] = None if a is None or b is None else tuple(a[j] + w * (b[j] - a[j]) for j in range(3))
    return out
