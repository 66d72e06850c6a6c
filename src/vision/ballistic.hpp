// ballistic.hpp - least-squares fits of a ball's image track (Eigen): the
// parabola of free flight over a candidate set, the test for a trend that a
// parabola leaves in the residuals (perspective toward the camera, an
// acceleration that changes along the flight), and the ball's image size
// from the second moments of its matte under motion blur.
#ifndef GS_BALLISTIC_HPP
#define GS_BALLISTIC_HPP

#include <cmath>
#include <cstddef>
#include <vector>

namespace gs {

struct TrackPoint {
    double t_s, x_px, y_px;
    double w = 1.0;  // weight (1 / variance, relative)
};

// x(t) = x0 + vx tau + ax/2 tau^2 with tau = t - t0 (t0 the points' mean time); same for y.
struct Parabola {
    bool ok = false;
    double t0_s = 0.0;
    double x0 = 0, vx = 0, ax = 0, y0 = 0, vy = 0, ay = 0;  // px, px/s, px/s^2
    double rms_px = 0.0;     // residual RMS (both axes pooled, n - 3 dof each)
    double ax_se = 0, ay_se = 0;  // standard errors of the accelerations
    size_t n = 0;

    double x(double t) const { double u = t - t0_s; return x0 + vx * u + 0.5 * ax * u * u; }
    double y(double t) const { double u = t - t0_s; return y0 + vy * u + 0.5 * ay * u * u; }
    double vx_at(double t) const { return vx + ax * (t - t0_s); }
    double vy_at(double t) const { return vy + ay * (t - t0_s); }
};

// Weighted least squares of x(t) and y(t) on 1, tau, tau^2 (at least 3 points;
// the SEs need 4). Pivoted QR on the scaled time: well conditioned at any rate.
Parabola fit_parabola(const TrackPoint *p, size_t n);
inline Parabola fit_parabola(const std::vector<TrackPoint> &p) { return fit_parabola(p.data(), p.size()); }

// What a free fall may be: an acceleration between a_min and a_max (px/s^2)
// pointing within acos(cos_min) of (gx, gy).
struct FallPrior {
    double a_min = 0.0, a_max = 1e300;
    double gx = 0.0, gy = 1.0, cos_min = -1.0;
    bool admits(const Parabola &f) const;
};

// RANSAC over a candidate set: the largest subset a parabola explains within
// tol_px (triples of points as hypotheses, each refitted on its inliers) whose
// acceleration the prior admits. inlier[i] is set for the points of the best
// model. iters hypotheses at most (all triples of a set of 12 or fewer).
Parabola ransac_parabola(const std::vector<TrackPoint> &p, double tol_px, int iters,
                         std::vector<bool> &inlier, unsigned seed = 1, const FallPrior &prior = FallPrior());

// The trend a parabola leaves. u(t), the position along gravity's direction,
// is fitted with degree 2 and degree 4; the acceleration of the quartic over
// the window (its largest minus its smallest value) against the parabola's,
// and the F statistic of the two extra terms.
struct TrendTest {
    bool ok = false;
    double a_px_s2 = 0.0;      // the parabola's acceleration along u
    double a_change_rel = 0.0; // (max - min of the quartic's acceleration over the window, less 2 SE) / |a|
    double f_stat = 0.0;       // F(2, n - 5) of the quartic against the parabola
    double rms2_px = 0.0, rms4_px = 0.0;
    // the quartic's acceleration at t_apex (when given): there the velocity along
    // gravity is 0, so neither air drag nor a rolling shutter changes it
    double a_apex_px_s2 = NAN, a_apex_se_px_s2 = NAN;
    size_t n = 0;
};
TrendTest trend_test(const std::vector<double> &t_s, const std::vector<double> &u_px, double t_apex_s = NAN);

// One detection for the size fit: the matte's second moments (px^2, the
// camera's blur still in), the ball's velocity then (px/s) and its offset from
// the image's centre (px).
struct MomentObs {
    double sxx, syy, sxy;
    double vx, vy;
    double rx = 0.0, ry = 0.0;
};

// Sigma = diag(P, Q) + U r r^T + s v v^T + psf^2 I over a flight's detections:
// P = Dx^2/16, Q = Dy^2/16 a sphere's image with the pixels' aspect; U r r^T its
// perspective elongation off the optical axis (a sphere at an angle theta images
// as an ellipse whose radial axis is 1/cos theta longer: U = P / f^2 for a focal
// length f, 0 <= U <= u_max_rel P); s = exposure^2 / 12 the smear of uniform
// motion (0 <= s <= s_max); or with P = Q (square pixels). P and Q are then
// the sharp ball's tangential widths: the size that q = g / a_px scales.
// Robust: detections whose residual exceeds 3 robust sigmas are dropped and the
// fit is repeated. Diameters (px) with their standard errors from the residuals.
struct SizeFit {
    bool ok = false;
    double dx_px = 0, dy_px = 0;       // non-square model
    double dx_se = 0, dy_se = 0;
    double d_sq_px = 0, d_sq_se = 0;   // square model
    double aspect = 1.0, aspect_se = 0.0;  // dy / dx
    double s_s2 = 0.0;                 // smear coefficient (exposure^2 / 12)
    size_t n = 0, n_used = 0;
};
SizeFit fit_size(const std::vector<MomentObs> &obs, double psf_sigma_px, double s_max_s2,
                 double u_max_rel = 0.0);

// Diameter (px) of the non-square model along the unit direction (gx, gy).
double size_along(const SizeFit &f, double gx, double gy);

}  // namespace gs

#endif
