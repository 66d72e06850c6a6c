"""Pinhole camera with optional radial distortion; full perspective projection."""

import math

RESOLUTIONS = {"1080p": (1920, 1080), "720p": (1280, 720), "vga": (640, 480)}


class Camera:
    def __init__(self, width, height, hfov_deg, distance_m, height_m, aim_height_m,
                 roll_deg=0.0, k1=0.0, k2=0.0):
        self.width, self.height = width, height
        self.hfov_deg = hfov_deg
        self.f_px = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
        self.cx, self.cy = width / 2.0, height / 2.0
        self.distance_m = distance_m
        self.k1, self.k2 = k1, k2
        self.roll_deg = roll_deg
        # camera on the -y axis looking at a point above the subject's standing position
        self.C = (0.0, -distance_m, height_m)
        fwd = (0.0, distance_m, aim_height_m - height_m)
        n = math.sqrt(sum(v * v for v in fwd))
        z = tuple(v / n for v in fwd)
        up = (0.0, 0.0, 1.0)
        x = (z[1] * up[2] - z[2] * up[1], z[2] * up[0] - z[0] * up[2], z[0] * up[1] - z[1] * up[0])
        n = math.sqrt(sum(v * v for v in x))
        x = tuple(v / n for v in x)
        y = (z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0])
        r = math.radians(roll_deg)
        cr, sr = math.cos(r), math.sin(r)
        # roll turns the image axes about the optical axis
        self.xa = tuple(cr * x[i] + sr * y[i] for i in range(3))
        self.ya = tuple(-sr * x[i] + cr * y[i] for i in range(3))
        self.za = z
        self.pitch_deg = math.degrees(math.atan2(aim_height_m - height_m, distance_m))

    @property
    def q_m_per_px(self):
        return self.distance_m / self.f_px

    def project(self, P):
        """World point (m) -> pixel (u, v); None if behind the camera."""
        d = (P[0] - self.C[0], P[1] - self.C[1], P[2] - self.C[2])
        zc = d[0] * self.za[0] + d[1] * self.za[1] + d[2] * self.za[2]
        if zc <= 1e-6:
            return None
        xn = (d[0] * self.xa[0] + d[1] * self.xa[1] + d[2] * self.xa[2]) / zc
        yn = (d[0] * self.ya[0] + d[1] * self.ya[1] + d[2] * self.ya[2]) / zc
        if self.k1 or self.k2:
            r2 = xn * xn + yn * yn
            k = 1.0 + self.k1 * r2 + self.k2 * r2 * r2
            xn *= k
            yn *= k
        return (self.f_px * xn + self.cx, self.f_px * yn + self.cy)

    def to_dict(self):
        return {"width": self.width, "height": self.height, "hfov_deg": self.hfov_deg,
                "f_px": self.f_px, "cx": self.cx, "cy": self.cy, "position_m": list(self.C),
                "pitch_deg": self.pitch_deg, "roll_deg": self.roll_deg, "k1": self.k1, "k2": self.k2}
