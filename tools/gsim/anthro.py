"""Subjects: segment lengths, head landmarks and segment masses (see docs/simulator.md)."""

import math

# Segment mass fractions in percent of body mass, de Leva (1996) Table 4
# (adjusted Zatsiorsky-Seluyanov), male / female.
DELEVA_MASS = {
    "m": {"head": 6.94, "trunk": 43.46, "uarm": 2.71, "farm": 1.62, "hand": 0.61,
          "thigh": 14.16, "shank": 4.33, "foot": 1.37},
    "f": {"head": 6.68, "trunk": 42.57, "uarm": 2.55, "farm": 1.38, "hand": 0.56,
          "thigh": 14.78, "shank": 4.81, "foot": 1.29},
}
# Segment COM position as a fraction of the segment from its proximal end
# (head: vertex->C7; trunk: C7->mid-hip; hand: wrist->fingertip; foot: heel->toe tip).
DELEVA_COM = {
    "m": {"head": 0.5002, "trunk": 0.4486, "uarm": 0.5772, "farm": 0.4574, "hand": 0.3624,
          "thigh": 0.4095, "shank": 0.4459, "foot": 0.4415},
    "f": {"head": 0.4841, "trunk": 0.4964, "uarm": 0.5754, "farm": 0.4559, "hand": 0.3427,
          "thigh": 0.3612, "shank": 0.4416, "foot": 0.4014},
}

# Nominal fractions of stature (Drillis & Contini / Winter 2009, joint centres).
NOMINAL = {
    "ankle_h": 0.039,     # ankle joint centre above the floor
    "shank": 0.246,       # knee - ankle
    "thigh": 0.235,       # hip joint centre - knee
    "trunk": 0.340,       # mid-hip - C7
    "head_v": 0.140,      # C7 - vertex (vertical)
    "uarm": 0.172,        # shoulder joint centre - elbow
    "farm": 0.146,        # elbow - wrist
    "hand": 0.108,        # wrist - fingertip
    "hip_w": 0.105,       # distance between hip joint centres
    "sho_w": 0.225,       # distance between shoulder joint centres
    "sho_drop": 0.058,    # C7 height minus shoulder joint height
    "sho_fwd": 0.035,     # shoulder joint centre ahead of the C7 spinous process
    "heel_back": 0.045,   # heel behind the ankle
    "ball_fwd": 0.075,    # ball of foot (metatarsal heads) ahead of the ankle
    "toe_fwd": 0.107,     # toe tip ahead of the ankle
}
SEGMENT_SD = 0.04        # per-person relative sd of each segment length
HEAD_SD = 0.0025         # absolute sd (fraction of stature) of head landmark heights


class Subject:
    """All lengths in metres, all masses as fractions of body mass (sum 1)."""

    def __init__(self, sid, stature_m, sex, L, head, mass, comf):
        self.sid = sid
        self.stature_m = stature_m
        self.sex = sex
        self.L = L
        self.head = head
        self.mass = mass
        self.comf = comf

    def to_dict(self):
        return {"subject": self.sid, "stature_m": self.stature_m, "sex": self.sex,
                "lengths_m": self.L, "head_m": self.head, "mass_frac": self.mass,
                "com_frac": self.comf}


def _clipped_gauss(rng, mu, sd, k=2.0):
    x = rng.gauss(0.0, 1.0)
    x = max(-k, min(k, x))
    return mu + sd * x


def make_subject(rng, sid, stature_m, sex=None):
    """Draw one person of the given stature; the neutral-pose vertex is exactly at stature."""
    if sex is None:
        sex = "m" if rng.random() < 0.5 else "f"
    H = stature_m
    f = {k: v * _clipped_gauss(rng, 1.0, SEGMENT_SD) for k, v in NOMINAL.items()}
    f["ankle_h"] = min(0.045, max(0.035, f["ankle_h"]))
    # renormalise the vertical chain so that the standing vertex is exactly at stature
    chain = ("ankle_h", "shank", "thigh", "trunk", "head_v")
    s = sum(f[k] for k in chain)
    for k in chain:
        f[k] /= s
    L = {k: v * H for k, v in f.items()}
    # head landmarks: heights as fractions of stature, measured from the floor when standing
    eye = _clipped_gauss(rng, 0.9355, HEAD_SD)
    tragion = min(eye - 0.004, _clipped_gauss(rng, 0.930, HEAD_SD))
    nose = _clipped_gauss(rng, 0.9075, HEAD_SD)
    c7 = 1.0 - f["head_v"]
    head = {
        # offsets from C7 in the head frame (x right, y forward, z up), metres
        "vertex": (0.0, 0.025 * H, (1.0 - c7) * H),
        "eye_z": (eye - c7) * H, "eye_y": 0.0,
        "eye_x": _clipped_gauss(rng, 0.0180, 0.0012) * H,
        "ear_z": (tragion - c7) * H, "ear_y": _clipped_gauss(rng, 0.025, 0.003) * H,
        "ear_x": _clipped_gauss(rng, 0.041, 0.002) * H,
        "nose_z": (nose - c7) * H, "nose_y": 0.0,
        "fractions": {"eye": eye, "tragion": tragion, "nose_tip": nose},
    }
    # eyes ~4 % of stature ahead of the tragion; the nose tip ~1.2 % ahead of the eyes
    head["eye_y"] = head["ear_y"] + _clipped_gauss(rng, 0.042, 0.003) * H
    head["nose_y"] = head["eye_y"] + _clipped_gauss(rng, 0.012, 0.0015) * H
    base_m = DELEVA_MASS[sex]
    pert = {k: v * max(0.6, rng.gauss(1.0, 0.10)) for k, v in base_m.items()}
    paired = ("uarm", "farm", "hand", "thigh", "shank", "foot")
    tot = sum(pert[k] * (2 if k in paired else 1) for k in pert)
    mass = {k: v / tot for k, v in pert.items()}
    comf = dict(DELEVA_COM[sex])
    L["toe_out"] = math.radians(rng.uniform(3.0, 12.0))  # foot progression angle, same L/R
    return Subject(sid, H, sex, L, head, mass, comf)


def statures(n, lo, hi, rng):
    """n statures spread over [lo, hi] (stratified so a small set still spans the range)."""
    out = []
    for i in range(n):
        u = (i + rng.random()) / n
        out.append(round(lo + (hi - lo) * u, 3))
    rng.shuffle(out)
    return out

