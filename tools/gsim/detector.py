"""Keypoint detector error model (see docs/simulator.md, "Detector")."""

import math

NOISE_K = {"low": 0.002, "medium": 0.003, "high": 0.004}
RATES = {  # outliers per keypoint, L/R swaps per frame, misses per keypoint, dropped frames
    "low": (0.01, 0.008, 0.008, 0.008),
    "medium": (0.015, 0.01, 0.01, 0.01),
    "high": (0.02, 0.015, 0.015, 0.015),
}
RHO = 0.3          # AR(1) coefficient of the jitter between consecutive frames
BLUR = 0.08        # extra jitter sd per pixel of image motion within one frame
# nominal confidence range per keypoint (face high, wrists lowest)
CONF = [(0.80, 0.99)] * 5 + [(0.75, 0.97)] * 2 + [(0.65, 0.95)] * 2 + [(0.50, 0.90)] * 2 + \
       [(0.70, 0.96)] * 2 + [(0.70, 0.97)] * 2 + [(0.60, 0.95)] * 2
PAIRS = [(1, 2), (3, 4), (5, 6), (7, 8), (9, 10), (11, 12), (13, 14), (15, 16)]
LIMBS = [((5, 6), (7, 8), (9, 10)), ((11, 12), (13, 14), (15, 16)), ((7, 8), (9, 10)),
         ((13, 14), (15, 16)), ((1, 2), (3, 4))]


def detect(rng, frames_px, fps, body_px, noise, width, height):
    """frames_px: list of 17 (u, v) true projections per frame (None = not projectable).
    Returns (list of per-frame detections or None for dropped frames, stats)."""
    sig = NOISE_K[noise] * body_px
    r_out, r_swap, r_miss, r_drop = RATES[noise]
    prev = [[0.0, 0.0] for _ in range(17)]
    out = []
    stats = {"sigma_px": sig, "outliers": 0, "swaps": 0, "missed": 0, "dropped": 0,
             "keypoints": 0}
    innov = math.sqrt(1 - RHO * RHO)
    for fi, kp in enumerate(frames_px):
        # jitter evolves every frame, including dropped ones
        for j in range(17):
            for a in range(2):
                prev[j][a] = RHO * prev[j][a] + innov * rng.gauss(0.0, sig)
        if rng.random() < r_drop:
            out.append(None)
            stats["dropped"] += 1
            continue
        det = []
        for j in range(17):
            p = kp[j]
            if p is None:
                det.append(None)
                continue
            lo, hi = CONF[j]
            c = rng.uniform(lo, hi)
            speed = 0.0
            if fi > 0 and frames_px[fi - 1][j] is not None:
                q = frames_px[fi - 1][j]
                speed = math.hypot(p[0] - q[0], p[1] - q[1])   # px per frame
            sb = BLUR * speed
            x = p[0] + prev[j][0] + (rng.gauss(0, sb) if sb > 0 else 0.0)
            y = p[1] + prev[j][1] + (rng.gauss(0, sb) if sb > 0 else 0.0)
            c *= 1.0 / (1.0 + 0.02 * speed)    # blurred parts are detected less confidently
            if rng.random() < r_out:
                ang = rng.uniform(0, 2 * math.pi)
                mag = rng.uniform(0.05, 0.30) * body_px
                x += mag * math.cos(ang)
                y += mag * math.sin(ang)
                c = rng.uniform(0.6, 0.9) if rng.random() < 0.5 else rng.uniform(0.05, 0.45)
                stats["outliers"] += 1
            if rng.random() < r_miss:
                det.append(None)
                stats["missed"] += 1
                continue
            if not (0.0 <= x < width and 0.0 <= y < height):
                det.append(None)
                continue
            det.append((x, y, max(0.01, min(0.999, c))))
            stats["keypoints"] += 1
        if rng.random() < r_swap:
            limb = LIMBS[rng.randrange(len(LIMBS))]
            for a, b in limb:
                det[a], det[b] = det[b], det[a]
            stats["swaps"] += 1
        out.append(det)
    return out, stats
