// ball_flights.cpp - see ball_flights.hpp.
#include "ball_flights.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <Eigen/Dense>

extern "C" {
#include "gravscale/gs_time.h"
}

namespace gs {

namespace {

constexpr size_t kKeepObs = 20000;       // detections kept per track (1000 fps: 20 s)
// Air drag changes a ball's acceleration along gravity by k v^2 (k = rho Cd A / 2m:
// tennis and basket balls 0.02 /m); a flight may show up to this much of it
constexpr double kDragMax_per_m = 0.05;
constexpr double kTrendF = 12.0;         // F(2, n - 5) beyond p ~ 0.001: a trend, not noise
constexpr double kGapF = 30.0;           // a dropped frame: F(1, 2n - 7) at the best place, far beyond noise's
constexpr double kTrendSlack = 0.06;     // and beyond drag by this share of the acceleration
// the camera's blur is assumed known to +-0.6 px^2 in variance, the matte's edge to 0.5 %
constexpr double kPsfVarUnc_px2 = 0.6;
constexpr double kEdgeRel = 0.005;
constexpr double kEdgePx = 0.15;
// the widest lens assumed: a focal length of at least 0.35 x the frame's longer side
constexpr double kFocalMinRel = 0.35;
// the clip's centre noise is estimated from this many windows of four detections on
constexpr size_t kNoiseMinWindows = 8;
// overlapping windows and their median: about this many degrees of freedom each (simulated)
constexpr double kNoiseDofPerWindow = 0.55;
// a parabola's residual beyond the centre noise at this significance
constexpr double kResidualP = 0.001;

double median_of(std::vector<double> v)
{
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Parabola fit_obs(const std::vector<BallObs> &pts)
{
    std::vector<TrackPoint> tp;
    tp.reserve(pts.size());
    for (const BallObs &o : pts) tp.push_back({o.t_s, o.x_px, o.y_px, 1.0});
    return fit_parabola(tp);
}

bool debug() { return std::getenv("GS_BALL_DEBUG") != nullptr; }

// the first and last detections may be contact (release, impact, another ball
// taken for this one): out when they leave the others' parabola
void trim_contact_ends(std::vector<BallObs> &pts, Parabola &fit)
{
    for (int end = 0; end < 2 && pts.size() > 5; end++) {
        std::vector<BallObs> rest(pts.begin() + (end == 0 ? 1 : 0), pts.end() - (end == 1 ? 1 : 0));
        Parabola f2 = fit_obs(rest);
        const BallObs &o = end == 0 ? pts.front() : pts.back();
        double e = std::hypot(f2.x(o.t_s) - o.x_px, f2.y(o.t_s) - o.y_px);
        if (f2.ok && e > std::max(1.0, 4.0 * f2.rms_px)) {
            pts = rest;
            fit = f2;
        }
    }
}

// A phone's encoder may drop frames and still stamp a constant rate: the detections
// after a dropped frame are stamped one frame time early and the parabola through
// them bends. The flight is re-timed where one frame time more between two of its
// detections (three or more on each side) explains the positions far better: an F
// of kGapF for the one parameter at the best of the places tried (noise's maximum
// over a flight's places stays near 2 ln n, about 10), and better than a smooth
// trend does. Only a clock that stamps whole frame times; at most three gaps.
// Returns the number inserted (fit refitted).
// the residual sum of squares (x and y) of a polynomial of degree deg in time
double poly_sse(const std::vector<BallObs> &pts, int deg)
{
    const Eigen::Index n = (Eigen::Index)pts.size();
    double t0 = 0.5 * (pts.front().t_s + pts.back().t_s), ts = std::max(1e-9, 0.5 * (pts.back().t_s - pts.front().t_s));
    Eigen::MatrixXd A(n, deg + 1), b(n, 2);
    for (Eigen::Index i = 0; i < n; i++) {
        double u = (pts[(size_t)i].t_s - t0) / ts, p = 1.0;
        for (int k = 0; k <= deg; k++, p *= u) A(i, k) = p;
        b(i, 0) = pts[(size_t)i].x_px;
        b(i, 1) = pts[(size_t)i].y_px;
    }
    Eigen::MatrixXd r = A * A.colPivHouseholderQr().solve(b) - b;
    return r.squaredNorm();
}

int retime_gaps(std::vector<BallObs> &pts, double dt, Parabola &fit)
{
    const size_t n = pts.size();
    if (n < 8 || n > 400 || !(dt > 0.0) || !fit.ok) return 0;
    for (size_t i = 1; i < n; i++) {
        double k = (pts[i].t_s - pts[i - 1].t_s) / dt;
        if (!(k > 0.5) || std::fabs(k - std::round(k)) > 0.1) return 0;
    }
    const double dof = 2.0 * ((double)n - 3.0);
    std::vector<TrackPoint> tp(n);
    int added = 0;
    for (int g = 0; g < 3; g++) {
        double sse0 = fit.rms_px * fit.rms_px * dof, sse1 = sse0;
        size_t best = 0;
        for (size_t j = 3; j + 3 <= n; j++) {
            for (size_t i = 0; i < n; i++) tp[i] = {pts[i].t_s + (i >= j ? dt : 0.0), pts[i].x_px, pts[i].y_px, 1.0};
            Parabola f = fit_parabola(tp);
            double sse = f.ok ? f.rms_px * f.rms_px * dof : INFINITY;
            if (sse < sse1) { sse1 = sse; best = j; }
        }
        double F = best ? (sse0 - sse1) / (sse1 / (dof - 1.0)) : 0.0;
        // a step, not a smooth trend (a tilted camera, motion in depth): the quartic,
        // with one parameter more per axis, must leave twice the gap's residual
        double sse4 = best ? poly_sse(pts, 4) : 0.0;
        if (debug())
            std::fprintf(stderr, "      gap test: best at %zu of %zu, residual %.3f -> %.3f px (quartic %.3f), F %.1f\n", best,
                         n, std::sqrt(sse0 / dof), std::sqrt(sse1 / dof), std::sqrt(sse4 / (dof - 4.0)), F);
        if (!best || !(F > kGapF) || !(2.0 * sse1 < sse4)) break;
        for (size_t i = best; i < n; i++) pts[i].t_s += dt;
        fit = fit_obs(pts);
        added++;
    }
    return added;
}

// the regularised incomplete beta function I_x(a, b) (continued fraction, modified Lentz)
double inc_beta(double a, double b, double x)
{
    if (!(x > 0.0)) return 0.0;
    if (!(x < 1.0)) return 1.0;
    if (x > (a + 1.0) / (a + b + 2.0)) return 1.0 - inc_beta(b, a, 1.0 - x);
    double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x)) / a;
    const double tiny = 1e-300;
    double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
    d = 1.0 / (std::fabs(d) < tiny ? tiny : d);
    double h = d;
    for (int m = 1; m <= 300; m++) {
        for (int odd = 0; odd < 2; odd++) {
            double num = odd ? -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0))
                             : m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m));
            d = 1.0 + num * d;
            d = 1.0 / (std::fabs(d) < tiny ? tiny : d);
            c = 1.0 + num / c;
            if (std::fabs(c) < tiny) c = tiny;
            h *= c * d;
        }
        if (std::fabs(c * d - 1.0) < 1e-12) break;
    }
    return front * h;
}

// the F(n1, n2) distribution's upper p quantile (bisection on its CDF)
double f_upper_quantile(double p, double n1, double n2)
{
    double lo = 0.0, hi = 1.0;
    auto cdf = [&](double f) { return inc_beta(0.5 * n1, 0.5 * n2, n1 * f / (n1 * f + n2)); };
    while (cdf(hi) < 1.0 - p && hi < 1e12) hi *= 2.0;
    for (int i = 0; i < 100; i++) {
        double mid = 0.5 * (lo + hi);
        (cdf(mid) < 1.0 - p ? lo : hi) = mid;
    }
    return hi;
}

}  // namespace

BallFlights::BallFlights(const BallFlightsOptions &o) : opt_(o) {}

double BallFlights::frame_dt(const std::vector<BallObs> &pts) const
{
    std::vector<double> d;
    for (size_t i = 1; i < pts.size(); i++)
        if (pts[i].frame == pts[i - 1].frame + 1) d.push_back(pts[i].t_s - pts[i - 1].t_s);
    double m = median_of(d);
    return std::isfinite(m) && m > 0 ? m : 1.0 / 30.0;
}

void BallFlights::add(const BallObs &o)
{
    TrackState &ts = tracks_[o.track];
    if (!ts.obs.empty() && !(o.t_s > ts.obs.back().t_s)) return;  // times increase per track
    ts.obs.push_back(o);
    if (ts.obs.size() > kKeepObs) ts.obs.erase(ts.obs.begin(), ts.obs.begin() + (long)(kKeepObs / 4));
    // the open arc: a new detection the arc's parabola does not explain ends it
    Arc &a = ts.arc;
    bool brk = false;
    if (!a.pts.empty()) {
        double gap = o.t_s - a.pts.back().t_s;
        if (gap > opt_.core.max_gap_s) brk = true;
        if (!brk && a.pts.size() >= 4 && a.fit.ok) {
            double e = std::hypot(a.fit.x(o.t_s) - o.x_px, a.fit.y(o.t_s) - o.y_px);
            double d = std::isfinite(o.diameter_px) ? o.diameter_px : 10.0;
            double k = a.pts.size() < 8 ? 1.8 : 1.0;  // a short arc's extrapolation is uncertain
            brk = e > k * std::max({2.0, 4.0 * a.fit.rms_px, 0.15 * d});
        }
    }
    if (brk) {
        ts.breaks.push_back(o.t_s);
        if (ts.breaks.size() > 4096) ts.breaks.erase(ts.breaks.begin(), ts.breaks.begin() + 1024);
        close_arc(o.track, ts);
        a.pts.clear();
        a.fit = Parabola();
    }
    a.pts.push_back(o);
    // the centre's noise: a third divided difference is zero for any parabola, so
    // four consecutive detections of one arc show only their scatter (the arc's
    // first, the one the last parabola did not explain, is often contact: left out)
    if (a.pts.size() >= 5 && a.pts.back().frame == a.pts[a.pts.size() - 4].frame + 3) {
        const BallObs *q = &a.pts[a.pts.size() - 4];
        double dx = 0.0, dy = 0.0, w2 = 0.0, dsum = 0.0;
        int nd = 0;
        for (int i = 0; i < 4; i++) {
            double w = 1.0;
            for (int k = 0; k < 4; k++)
                if (k != i) w /= q[i].t_s - q[k].t_s;
            dx += w * q[i].x_px;
            dy += w * q[i].y_px;
            w2 += w * w;
            if (std::isfinite(q[i].diameter_px)) {
                dsum += q[i].diameter_px;
                nd++;
            }
        }
        // per axis: sigma^2 times an exponential; times the diameter, the edge's noise (size-free)
        double v = 0.5 * (dx * dx + dy * dy) / w2;
        if (nd >= 2 && std::isfinite(v)) centre_noise_.push_back(v * dsum / nd);
        if (centre_noise_.size() > 8192) centre_noise_.erase(centre_noise_.begin(), centre_noise_.begin() + 2048);
    }
    if (a.pts.size() >= 3) {
        // the newest points predict (a bounce far back must not bend the prediction)
        size_t n = std::min<size_t>(a.pts.size(), 30);
        std::vector<BallObs> last(a.pts.end() - (long)n, a.pts.end());
        a.fit = fit_obs(last);
    }
}

// The centroid's variance per axis for a ball d px across: an edge of pi d pixels
// with independent noise moves it by 2 sigma_edge^2 / (pi d), so the clip's measured
// scatter times its diameters, over d (NaN until measured)
double BallFlights::centre_var_px2(double d_px) const
{
    if (!(d_px > 0) || centre_noise_.size() < kNoiseMinWindows) return NAN;
    // an exponential's median is ln 2 of its mean
    return median_of(centre_noise_) / std::log(2.0) / d_px;
}

// The core's limit (a share of the size), or a parabola's residual (per axis, n
// detections, 3 coefficients each) the centre noise explains: their variances' ratio
// is F(2 (n - 3), the noise estimate's degrees of freedom) for a true parabola.
// Never below a hard edge's quantisation noise, 1 / (6 pi d) px^2.
bool BallFlights::residual_ok(double rms_px, size_t n, double d_px) const
{
    if (rms_px <= opt_.core.max_rms_rel * d_px) return true;
    double var = centre_var_px2(d_px);
    if (n < 4 || !std::isfinite(var) || !(rms_px >= 0.0)) return false;
    var = std::max(var, 1.0 / (6.0 * M_PI * d_px));
    double nu = 2.0 * ((double)n - 3.0), nu_noise = kNoiseDofPerWindow * (double)centre_noise_.size();
    double lim = f_upper_quantile(kResidualP, nu, nu_noise);
    if (debug())
        std::fprintf(stderr, "      residual %.3f px, centre noise %.3f px (%zu windows), limit %.3f px\n", rms_px,
                     std::sqrt(var), centre_noise_.size(), std::sqrt(lim * var));
    return rms_px * rms_px <= lim * var;
}

// A closed arc with no apex inside (dropped from rest, entered falling, left
// rising) is kept until the core has had its chance to report it.
void BallFlights::close_arc(int track, TrackState &ts)
{
    Arc a = ts.arc;
    if (a.pts.size() < (size_t)std::max<uint32_t>(opt_.core.min_samples, 4)) return;
    // the last detection before a break is often the contact frame already: the
    // parabola of the others decides
    a.fit = fit_obs(a.pts);
    if (!a.fit.ok) return;
    double amag = std::hypot(a.fit.ax, a.fit.ay);
    if (!(amag > 0)) return;
    double ux = a.fit.ax / amag, uy = a.fit.ay / amag;
    double dt = frame_dt(a.pts);
    double v_down = a.fit.vx * ux + a.fit.vy * uy;
    double t_apex = a.fit.t0_s - v_down / amag;
    double t0 = a.pts.front().t_s, t1 = a.pts.back().t_s;
    bool apex_inside = t_apex > t0 + 1.5 * dt && t_apex < t1 - 1.5 * dt;
    if (debug())
        std::fprintf(stderr, "arc track %d %.3f-%.3f n=%zu a=%.0f apex %.3f %s\n", track, t0, t1, a.pts.size(), amag,
                     t_apex, apex_inside ? "inside (core)" : "outside: pending");
    if (apex_inside) return;
    // a free fall at all (as the core's gate): along gravity within 45 degrees and a
    // size of [size_min / 2, 2 size_max] under g for the arc's diameter
    std::vector<double> ds;
    for (const BallObs &o : a.pts)
        if (std::isfinite(o.diameter_px)) ds.push_back(o.diameter_px);
    double d = median_of(ds);
    if (!(uy > std::cos(M_PI / 4.0)) || !std::isfinite(d)) return;
    double size_m = opt_.g_m_s2 * d / amag;
    if (size_m < 0.5 * opt_.core.size_min_m || size_m > 2.0 * opt_.core.size_max_m) return;
    ts.pending.push_back(a);
}

FlightSize BallFlights::measure(const std::vector<BallObs> &pts, const Parabola &fit, double a_px_s2)
{
    FlightSize fs;
    fs.n = pts.size();
    if (!fit.ok || pts.size() < 4) return fs;
    double amag = std::hypot(fit.ax, fit.ay);
    double gx = amag > 0 ? fit.ax / amag : 0.0, gy = amag > 0 ? fit.ay / amag : 1.0;
    // ---- size
    double dt = frame_dt(pts);
    // the camera's blur, measured: the 4th moment across the motion tells a
    // Gaussian blur's variance from the disc's (pooled over the clip's detections)
    for (const BallObs &o : pts)
        if (std::isfinite(o.psf_var_px2) && std::isfinite(o.sxx)) psf_seen_.push_back(o.psf_var_px2);
    double psf_sigma = opt_.psf_sigma_px, psf_unc = kPsfVarUnc_px2;
    if (psf_seen_.size() >= 8) {
        double v = median_of(psf_seen_);
        std::vector<double> dev;
        for (double x : psf_seen_) dev.push_back(std::fabs(x - v));
        double spread = 1.4826 * median_of(dev);
        // never below the configured blur: the matte's floor clips the blur's tails,
        // which makes this estimate low where the blur is small
        v = std::min(std::max(v, opt_.psf_sigma_px * opt_.psf_sigma_px), 25.0);
        psf_sigma = std::sqrt(v);
        psf_unc = std::max(0.25, 2.0 * spread / std::sqrt((double)psf_seen_.size()));
    }
    std::vector<MomentObs> mo;
    std::vector<double> widths;
    for (const BallObs &o : pts) {
        if (std::isfinite(o.diameter_px)) widths.push_back(o.diameter_px);
        if (!std::isfinite(o.sxx)) continue;
        MomentObs m;
        // an outline's moments are the sharp disc's: the fit's model adds the blur to them
        const double blur_px2 = o.moments_blur_free ? psf_sigma * psf_sigma : 0.0;
        m.sxx = o.sxx + blur_px2;
        m.syy = o.syy + blur_px2;
        m.sxy = o.sxy;
        // ... and the smear: no motion enters their model
        m.vx = o.moments_blur_free ? 0.0 : fit.vx_at(o.t_s);
        m.vy = o.moments_blur_free ? 0.0 : fit.vy_at(o.t_s);
        m.rx = o.x_px - 0.5 * (opt_.frame_w - 1);
        m.ry = o.y_px - 0.5 * (opt_.frame_h - 1);
        mo.push_back(m);
        if (std::getenv("GS_BALL_DEBUG_MOMENTS"))
            std::fprintf(stderr, "  m t=%.3f v=(%.0f,%.0f) r=(%.0f,%.0f) sxx=%.1f syy=%.1f sxy=%.1f d=%.1f dk=%.2f psf2=%.2f\n", o.t_s, m.vx, m.vy,
                         m.rx, m.ry, m.sxx, m.syy, m.sxy, o.diameter_px, o.diameter_kurt_px, o.psf_var_px2);
    }
    double fmin = kFocalMinRel * std::max(opt_.frame_w, opt_.frame_h);
    SizeFit sf = fit_size(mo, psf_sigma, 1.05 * dt * dt / 12.0, fmin > 0 ? 1.0 / (fmin * fmin) : 0.0);
    if (sf.ok) {
        fs.aspect = sf.aspect;
        fs.aspect_se = sf.aspect_se;
        // the pixels' shape is the camera's: pooled over the flights seen
        double se = std::max(sf.aspect_se, 0.01);
        aspect_w_ += 1.0 / (se * se);
        aspect_sum_ += sf.aspect / (se * se);
        double pooled = aspect_sum_ / aspect_w_, pooled_se = std::sqrt(1.0 / aspect_w_);
        bool square = opt_.square_pixels || std::fabs(pooled - 1.0) <= std::max(0.05, 3.0 * pooled_se);
        double d, d_se;
        if (square && sf.d_sq_px > 0) {
            d = sf.d_sq_px;
            d_se = sf.d_sq_se;
        } else {
            // along gravity: the non-square model's diameter in that direction
            d = size_along(sf, gx, gy);
            d_se = std::sqrt(gx * gx * sf.dx_se * sf.dx_se + gy * gy * sf.dy_se * sf.dy_se);
            fs.along_gravity = true;
        }
        // what the fit cannot see: the camera's blur (known to kPsfVarUnc) and the matte's edge
        double sys_psf = 8.0 * psf_unc / d;
        double sys_edge = kEdgeRel * d + kEdgePx;
        fs.psf_sigma_px = psf_sigma;
        fs.size_px = d;
        fs.size_se_px = std::sqrt(d_se * d_se + sys_psf * sys_psf + sys_edge * sys_edge);
        fs.ok = std::isfinite(d) && d > 0;
    } else if (widths.size() >= 3) {
        // too few clean mattes for the fit: the widths across the motion
        double d = median_of(widths);
        std::vector<double> dev;
        for (double w : widths) dev.push_back(std::fabs(w - d));
        double se = 1.4826 * median_of(dev) * 1.25 / std::sqrt((double)widths.size());
        double sys_psf = 8.0 * psf_unc / d, sys_edge = kEdgeRel * d + kEdgePx;
        fs.size_px = d;
        fs.size_se_px = std::sqrt(se * se + sys_psf * sys_psf + sys_edge * sys_edge + 0.0004 * d * d);
        fs.ok = true;
    }
    // ---- geometry: the positions along gravity, parabola against quartic
    std::vector<double> t, u;
    for (const BallObs &o : pts) {
        t.push_back(o.t_s);
        u.push_back(o.x_px * gx + o.y_px * gy);
    }
    // A rolling shutter shows a ball at y + k v (y - rows/2): its image accelerates
    // by a (1 + 3 k v_down), so the acceleration changes by 3 k dv along the flight
    // and a window whose mean v_down is not 0 is biased by 3 k mean(v_down). k is
    // the detector's estimate (positions already corrected: a quarter of a frame
    // time per frame height left) or, without one, up to a frame time per height.
    double k_bound = (rs_k_ != 0.0 ? 0.25 : 1.0) * dt / std::max(1.0, opt_.frame_h);
    double v0 = fit.vx_at(pts.front().t_s) * gx + fit.vy_at(pts.front().t_s) * gy;
    double v1 = fit.vx_at(pts.back().t_s) * gx + fit.vy_at(pts.back().t_s) * gy;
    double vmean = 0.0;
    for (const BallObs &o : pts) vmean += (fit.vx_at(o.t_s) * gx + fit.vy_at(o.t_s) * gy) / (double)pts.size();
    fs.a_sys_rel = 3.0 * k_bound * std::fabs(vmean);
    double t_apex = amag > 0 ? fit.t0_s - (fit.vx * gx + fit.vy * gy) / amag : NAN;
    TrendTest tt = trend_test(t, u, t_apex);
    if (tt.ok) {
        double s0 = std::pow(std::hypot(fit.vx_at(pts.front().t_s), fit.vy_at(pts.front().t_s)), 2);
        double s1 = std::pow(std::hypot(fit.vx_at(pts.back().t_s), fit.vy_at(pts.back().t_s)), 2);
        double a = a_px_s2 > 0 ? a_px_s2 : amag;
        // drag's share of the acceleration: k v^2 / g with v = v_px g / a, from both ends
        // (the shutter's full bound: an estimate from a few short flights is not sure enough to lean on)
        double k_full = dt / std::max(1.0, opt_.frame_h);
        double allow = kDragMax_per_m * opt_.g_m_s2 * (s0 + s1) / (a * a) + 3.0 * k_full * std::fabs(v1 - v0) +
                       kTrendSlack;
        fs.trend_change = tt.a_change_rel;
        fs.trend_f = tt.f_stat;
        fs.trend_allow = allow;
        fs.not_planar = tt.f_stat > kTrendF && tt.a_change_rel > allow;
        // the camera's geometry is the clip's: once most flights tested showed it
        // (two at least), the later ones are not trusted either, however short
        n_tested_++;
        if (fs.not_planar) n_not_planar_++;
        if (n_not_planar_ >= 2 && 2 * n_not_planar_ >= n_tested_) fs.not_planar = true;
        fs.trend_rms4_px = tt.rms4_px;
        fs.a_apex_px_s2 = tt.a_apex_px_s2;
        fs.a_apex_se_px_s2 = tt.a_apex_se_px_s2;
    }
    if (debug())
        std::fprintf(stderr, "size: psf %.2f px, n=%zu moments=%zu used=%zu dx=%.2f dy=%.2f sq=%.2f (se %.2f) aspect=%.3f+-%.3f s=%.2e -> %s %.2f+-%.2f px; trend %.3f (allow %.3f) F=%.1f%s\n",
                     fs.psf_sigma_px, pts.size(), mo.size(), sf.n_used, sf.dx_px, sf.dy_px, sf.d_sq_px, sf.d_sq_se, sf.aspect,
                     sf.aspect_se, sf.s_s2, fs.along_gravity ? "along g" : "square", fs.size_px, fs.size_se_px,
                     fs.trend_change, fs.trend_allow, fs.trend_f, fs.not_planar ? " NOT PLANAR" : "");
    if (debug())
        std::fprintf(stderr, "      rolling-shutter bias bound on a: %.3f; a at the apex %.1f +- %.1f, quartic rms %.2f\n",
                     fs.a_sys_rel, fs.a_apex_px_s2, fs.a_apex_se_px_s2, fs.trend_rms4_px);
    measured_.push_back(fs);
    return fs;
}

void BallFlights::judge(gs_ev_jump *j)
{
    auto it = tracks_.find((int)j->track);
    if (it == tracks_.end()) return;
    TrackState &ts = it->second;
    double t0 = gs_time_s_of_us(j->t_takeoff_us), t1 = gs_time_s_of_us(j->t_land_us);
    if (!std::isfinite(t0) || !std::isfinite(t1)) return;
    ts.core_windows.emplace_back(t0, t1);
    std::vector<BallObs> in;
    for (const BallObs &o : ts.obs)
        if (o.t_s > t0 && o.t_s < t1) in.push_back(o);
    Parabola fit = fit_obs(in);
    // (the core leaves such detections out of its fit too: its outliers)
    if (j->n_outliers > 0) trim_contact_ends(in, fit);
    if (retime_gaps(in, frame_dt(in), fit) > 0) {
        // the flight's own clock: its acceleration and residual as re-timed
        double a = std::hypot(fit.ax, fit.ay), n = (double)in.size();
        j->a_px_s2 = a;
        j->a_px_se_s2 = std::hypot(fit.ax * fit.ax_se, fit.ay * fit.ay_se) / a;
        j->g_dir_deg = std::atan2(fit.ax, fit.ay) * 180.0 / M_PI;
        j->q_m_per_px = opt_.g_m_s2 / a;
        j->rms_px = fit.rms_px * std::sqrt(2.0 * (n - 3.0) / n);
        j->n_samples = (uint32_t)in.size();
    }
    FlightSize fs = measure(in, fit, j->a_px_s2);
    // The core's residual limit is a share of the size; a small ball's centroid
    // scatters more than that, so the clip's centre noise decides, then the core's
    // later rules (the acceleration sure, along gravity within 45 degrees). The
    // core's RMS is over both axes and its n inliers: per axis, 3 coefficients each.
    double n_core = (double)j->n_samples;
    double rms_axis = n_core > 3 ? j->rms_px * std::sqrt(n_core / (2.0 * (n_core - 3.0))) : NAN;
    if (!j->accepted && j->reason == GS_REJ_LARGE_RESIDUAL && fs.ok && fit.ok && std::isfinite(rms_axis) &&
        residual_ok(rms_axis, j->n_samples, fs.size_px)) {
        double amag = std::hypot(fit.ax, fit.ay);
        bool down = amag > 0 && fit.ay / amag > std::cos(M_PI / 4.0);
        bool a_sure = std::hypot(j->a_px_se_s2 / j->a_px_s2, fs.a_sys_rel) <= opt_.core.max_a_se_rel;
        if (debug()) std::fprintf(stderr, "      within the centre noise: %s\n", down && a_sure ? "stands" : "still out");
        if (down && a_sure) {
            j->accepted = true;
            j->reason = GS_REJ_NONE;
        }
    }
    // One parabola must explain the flight's detections: where the track's own
    // parabola broke inside the window (a hand caught or pushed the ball: a dribble)
    // with detections on both sides, the core's fit joins two motions
    if (j->accepted) {
        for (double tb : ts.breaks) {
            if (!(tb > t0 && tb < t1)) continue;
            size_t before = 0, after = 0;
            for (const BallObs &o : in) (o.t_s < tb ? before : after)++;
            if (before >= 3 && after >= 3) {
                if (debug()) std::fprintf(stderr, "      the track's parabola breaks at %.3f inside the flight\n", tb);
                j->accepted = false;
                j->reason = GS_REJ_LARGE_RESIDUAL;
                break;
            }
        }
    }
    // ... and a contact at an end leaves the others' parabola, the core's fit
    // through it having another acceleration
    if (j->accepted && in.size() >= 6 && fs.ok) {
        std::vector<TrackPoint> tp;
        for (const BallObs &o : in) tp.push_back({o.t_s, o.x_px, o.y_px, 1.0});
        std::vector<bool> inl;
        Parabola r = ransac_parabola(tp, std::max(1.0, 0.06 * fs.size_px), 300, inl, 1);
        size_t n_in = (size_t)std::count(inl.begin(), inl.end(), true);
        double ar = std::hypot(r.ax, r.ay);
        if (r.ok && n_in >= 5 && n_in < in.size() && ar > 0 &&
            std::fabs(ar / j->a_px_s2 - 1.0) > 0.05 + 3.0 * std::hypot(r.ax_se, r.ay_se) / ar) {
            if (debug())
                std::fprintf(stderr, "      the core's a %.0f, its inliers' %.0f (%zu of %zu): not one parabola\n",
                             j->a_px_s2, ar, n_in, in.size());
            j->accepted = false;
            j->reason = GS_REJ_LARGE_RESIDUAL;
        }
    }
    if (fs.ok && std::isfinite(j->q_m_per_px)) {
        j->size_px = fs.size_px;
        j->height_m = fs.size_px * j->q_m_per_px;
        double ra = j->a_px_se_s2 / j->a_px_s2, rs = fs.size_se_px / fs.size_px, rr = fs.a_sys_rel / std::sqrt(3.0);
        j->height_se_m = j->height_m * std::sqrt((std::isfinite(ra) ? ra * ra : 0.0) + rs * rs + rr * rr);
        if (j->accepted && (j->height_m < opt_.core.size_min_m || j->height_m > opt_.core.size_max_m)) {
            j->accepted = false;
            j->reason = GS_REJ_IMPLAUSIBLE_A;
        }
    }
    // The core's residual test assumes a parabola; a long, fast flight of a light
    // ball keeps a smooth trend from air drag (or a rolling shutter) that the test
    // reads as noise. When the quartic follows the positions within the core's
    // limit and the trend is one drag and the shutter can make, the flight stands
    // (its mean acceleration: over an arc about its apex, drag's and the shutter's
    // changes, odd in the vertical velocity, cancel to first order).
    if (!j->accepted && j->reason == GS_REJ_LARGE_RESIDUAL && fs.ok && !fs.not_planar && in.size() >= 10 &&
        fs.trend_rms4_px <= opt_.core.max_rms_rel * fs.size_px && std::isfinite(j->height_m)) {
        j->rms_px = fs.trend_rms4_px;
        bool in_range = j->height_m >= opt_.core.size_min_m && j->height_m <= opt_.core.size_max_m;
        j->accepted = in_range;
        j->reason = in_range ? GS_REJ_NONE : GS_REJ_IMPLAUSIBLE_A;
    }
    if (fs.not_planar && j->accepted) {
        j->accepted = false;
        j->reason = GS_REJ_NOT_PLANAR;
    }
    // a ball moving in depth: its image's acceleration is not g's over its size (the
    // parabola in the image may still fit a short arc)
    if (j->accepted || j->reason == GS_REJ_LARGE_RESIDUAL || j->reason == GS_REJ_NOT_PLANAR) depth_flight(in, j);
}

// A ball moving in depth (toward a wall, back from it): its image's position from
// the optical axis and its diameter both scale as 1/Z, so u = (x - cx) / d and
// v = (y - cy) / d are its position in diameters whatever its depth and the focal
// length; in free flight they follow a parabola of acceleration g / D along gravity
// (an offset of the optical axis adds a term in Z, linear in time). Used only where
// the size changes along the flight beyond its noise, and only while gravity lies in
// the image's plane: Z (as 1/d) must not accelerate, else the plane's share of g is
// less than g (a camera tilted toward the fall).
int BallFlights::depth_flight(const std::vector<BallObs> &pts, gs_ev_jump *j) const
{
    const double cx = 0.5 * opt_.frame_w, cy = 0.5 * opt_.frame_h;
    if (!(cx > 0.0 && cy > 0.0)) return 0;
    std::vector<TrackPoint> uv, zz;
    std::vector<double> ds;
    double d_sum = 0.0;
    for (const BallObs &o : pts) {
        if (!(o.diameter_px > 0.0)) continue;
        uv.push_back({o.t_s, (o.x_px - cx) / o.diameter_px, (o.y_px - cy) / o.diameter_px, 1.0});
        ds.push_back(o.diameter_px);
        d_sum += o.diameter_px;
    }
    const size_t n = uv.size();
    if (n < opt_.core.min_samples || n < 7) return 0;
    const double d_mean = d_sum / (double)n;
    // a diameter's tenth: the sizes' scatter (a few per cent) times a few diameters off-axis
    std::vector<bool> inl;
    Parabola r = ransac_parabola(uv, 0.1, 300, inl, 1);
    if (!r.ok) return 0;
    // the inliers, and their relative depth d_mean / d (Z's motion and acceleration)
    std::vector<TrackPoint> in;
    for (size_t i = 0; i < n; i++)
        if (inl[i]) {
            in.push_back(uv[i]);
            zz.push_back({uv[i].t_s, d_mean / ds[i], 0.0, 1.0});
        }
    if (in.size() < 7 || (double)in.size() < 0.75 * (double)n) return 0;
    Parabola f = fit_parabola(in), z = fit_parabola(zz);
    if (!f.ok || !z.ok) return 0;
    double span = in.back().t_s - in.front().t_s;
    double zmin = 1e300, zmax = -1e300;
    for (const TrackPoint &q : zz) { zmin = std::min(zmin, q.x_px); zmax = std::max(zmax, q.x_px); }
    // the depth's change along the flight (5 % or more), its trend eight standard
    // errors clear of the sizes' scatter
    double tm = 0.0, stt = 0.0;
    for (const TrackPoint &q : zz) tm += q.t_s / (double)zz.size();
    for (const TrackPoint &q : zz) stt += (q.t_s - tm) * (q.t_s - tm);
    double dz = std::fabs(z.vx) * span, z_rms = z.rms_px * std::sqrt(2.0);  // (its rms_px pools z with zeros)
    bool in_depth = dz > 0.05 && std::fabs(z.vx) > 8.0 * z_rms / std::sqrt(std::max(stt, 1e-12));
    double a = std::hypot(f.ax, f.ay);
    if (!(a > 0.0)) return 0;
    double a_se = std::hypot(f.ax * f.ax_se, f.ay * f.ay_se) / a;
    // Z's acceleration in diameters: f_px / d_mean times z's, with the longest lens
    // assumed at twice the frame's longer side; its share of g tilts the plane
    double f_max = 2.0 * std::max(opt_.frame_w, opt_.frame_h);
    double a_z = f_max / d_mean * (std::fabs(z.ax) + 2.0 * z.ax_se);
    double tilt_rel = std::sqrt(1.0 + (a_z / a) * (a_z / a)) - 1.0;
    bool down = f.ay / a > std::cos(M_PI / 4.0);
    if (debug())
        std::fprintf(stderr, "      in depth: n=%zu of %zu, z %.3f..%.3f (change %.3f, rms %.4f) a=%.1f+-%.1f D/s^2 -> %.4f m; "
                     "z accel %.3f+-%.3f /s^2 -> tilt bound %.3f\n", in.size(), n, zmin, zmax, dz, z.rms_px, a, a_se,
                     opt_.g_m_s2 / a, z.ax, z.ax_se, tilt_rel);
    if (!in_depth || !down) return 0;
    double size_m = opt_.g_m_s2 / a;
    double se_rel = std::hypot(a_se / a, tilt_rel / std::sqrt(3.0));
    if (!(se_rel <= opt_.core.max_a_se_rel) || tilt_rel > 0.05 || size_m < opt_.core.size_min_m ||
        size_m > opt_.core.size_max_m) {
        // not measurable so; but gravity out of the plane only lowers the acceleration
        // in it, so g / a bounds the size from above: a flight's size beyond it by three
        // combined SEs is wrong
        double rel = std::hypot(a_se / a, j->height_se_m / j->height_m);
        if (j->accepted && j->height_m > size_m * (1.0 + 3.0 * rel)) {
            if (debug()) std::fprintf(stderr, "      %.4f m is beyond the bound %.4f m\n", j->height_m, size_m);
            j->accepted = false;
            j->reason = GS_REJ_NOT_PLANAR;
        }
        return -1;
    }
    j->height_m = size_m;
    j->height_se_m = size_m * se_rel;
    j->size_px = d_mean;
    j->q_m_per_px = size_m / d_mean;
    j->rms_px = f.rms_px * d_mean;
    j->accepted = true;
    j->reason = GS_REJ_NONE;
    return 1;
}

bool BallFlights::flight_from_arc(int track, const Arc &a0, gs_ev_jump *j)
{
    std::vector<BallObs> pts = a0.pts;
    Parabola fit = fit_obs(pts);
    trim_contact_ends(pts, fit);
    retime_gaps(pts, frame_dt(pts), fit);
    if (!fit.ok) return false;
    double amag = std::hypot(fit.ax, fit.ay);
    if (!(amag > 0)) return false;
    std::memset(j, 0, sizeof *j);
    j->track = (uint32_t)track;
    double dt = frame_dt(pts);
    double t0 = pts.front().t_s, t1 = pts.back().t_s;
    j->t_takeoff_us = gs_time_us_of_s(t0);
    j->t_land_us = gs_time_us_of_s(t1);
    j->flight_time_s = t1 - t0;
    double ux = fit.ax / amag, uy = fit.ay / amag;
    double v_down = fit.vx * ux + fit.vy * uy;
    j->t_apex_us = gs_time_us_of_s(fit.t0_s - v_down / amag);
    j->a_px_s2 = amag;
    j->a_px_se_s2 = std::hypot(fit.ax * fit.ax_se, fit.ay * fit.ay_se) / amag;
    j->g_dir_deg = std::atan2(fit.ax, fit.ay) * 180.0 / M_PI;
    j->q_m_per_px = opt_.g_m_s2 / amag;
    j->jump_height_m = NAN;  // no take-off from the ground: a ball released or entering
    j->takeoff_velocity_m_s = NAN;
    j->com_rise_m = j->contact_time_s = j->rsi = NAN;
    j->n_samples = (uint32_t)pts.size();
    j->n_outliers = (uint32_t)(a0.pts.size() - pts.size());
    j->rms_px = fit.rms_px;
    j->height_m = j->height_se_m = j->size_px = NAN;
    FlightSize fs = measure(pts, fit, amag);
    if (fs.ok) {
        j->size_px = fs.size_px;
        j->height_m = fs.size_px * j->q_m_per_px;
        double ra = j->a_px_se_s2 / amag, rs = fs.size_se_px / fs.size_px, rr = fs.a_sys_rel / std::sqrt(3.0);
        j->height_se_m = j->height_m * std::sqrt(ra * ra + rs * rs + rr * rr);
    }
    // the core's rules, then the geometry
    double max_gap = 0.0;
    for (size_t i = 1; i < pts.size(); i++) max_gap = std::max(max_gap, pts[i].t_s - pts[i - 1].t_s);
    const gs_core_config &c = opt_.core;
    if (pts.size() < c.min_samples || j->flight_time_s < c.min_flight_s)
        j->reason = GS_REJ_FEW_SAMPLES;
    else if (max_gap > c.max_gap_s)
        j->reason = GS_REJ_GAP;
    else if (!fs.ok)
        j->reason = GS_REJ_NO_SIZE;
    else if (!residual_ok(fit.rms_px, pts.size(), fs.size_px))
        j->reason = GS_REJ_LARGE_RESIDUAL;
    else if (!(std::hypot(j->a_px_se_s2 / amag, fs.a_sys_rel) <= c.max_a_se_rel))
        j->reason = GS_REJ_UNCERTAIN_A;
    else if (j->height_m < c.size_min_m || j->height_m > c.size_max_m)
        j->reason = GS_REJ_IMPLAUSIBLE_A;
    else if (fs.not_planar)
        j->reason = GS_REJ_NOT_PLANAR;
    j->accepted = j->reason == GS_REJ_NONE;
    if (j->accepted || j->reason == GS_REJ_LARGE_RESIDUAL || j->reason == GS_REJ_NOT_PLANAR) depth_flight(pts, j);
    if (pts.size() < 2u * c.min_samples) j->warnings |= GS_WARN_FEW_SAMPLES;
    (void)dt;
    return true;
}

void BallFlights::take_pending(double t_now_s, bool flush, std::vector<gs_ev_jump> &out)
{
    const double wait_s = opt_.core.landing_latency_s + 0.3;
    for (auto &kv : tracks_) {
        TrackState &ts = kv.second;
        if (flush && ts.arc.pts.size() >= 2) {
            close_arc(kv.first, ts);
            ts.arc.pts.clear();
        }
        for (size_t i = 0; i < ts.pending.size();) {
            const Arc &a = ts.pending[i];
            double t0 = a.pts.front().t_s, t1 = a.pts.back().t_s;
            if (!flush && t1 > t_now_s - wait_s) {
                i++;
                continue;
            }
            // the core reported it (its flight covers half the arc or more): nothing to add
            bool core_has = false;
            for (const auto &w : ts.core_windows) {
                double ov = std::min(w.second, t1) - std::max(w.first, t0);
                if (ov > 0.5 * (t1 - t0)) core_has = true;
            }
            gs_ev_jump j;
            if (!core_has && flight_from_arc(kv.first, a, &j)) out.push_back(j);
            ts.pending.erase(ts.pending.begin() + (long)i);
        }
    }
}

}  // namespace gs
