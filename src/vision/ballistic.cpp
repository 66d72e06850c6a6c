// ballistic.cpp - see ballistic.hpp.
#include "ballistic.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Dense>

namespace gs {

namespace {

// time origin and scale of a window: tau = (t - t0) / ts lies within [-1, 1]
void time_frame(const TrackPoint *p, size_t n, double *t0, double *ts)
{
    double lo = p[0].t_s, hi = p[0].t_s, sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        lo = std::min(lo, p[i].t_s);
        hi = std::max(hi, p[i].t_s);
        sum += p[i].t_s;
    }
    *t0 = sum / (double)n;
    *ts = std::max(1e-9, std::max(hi - *t0, *t0 - lo));
}

double median_of(std::vector<double> v)
{
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + (long)(v.size() / 2), v.end());
    return v[v.size() / 2];
}

}  // namespace

Parabola fit_parabola(const TrackPoint *p, size_t n)
{
    Parabola r;
    if (n < 3) return r;
    double t0, ts;
    time_frame(p, n, &t0, &ts);
    Eigen::MatrixXd A(n, 3);
    Eigen::MatrixXd b(n, 2);
    for (size_t i = 0; i < n; i++) {
        double w = std::sqrt(std::max(0.0, p[i].w));
        double u = (p[i].t_s - t0) / ts;
        A(i, 0) = w;
        A(i, 1) = w * u;
        A(i, 2) = w * u * u;
        b(i, 0) = w * p[i].x_px;
        b(i, 1) = w * p[i].y_px;
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    if (qr.rank() < 3) return r;
    Eigen::MatrixXd c = qr.solve(b);
    Eigen::MatrixXd res = A * c - b;
    double wsum = 0.0;
    for (size_t i = 0; i < n; i++) wsum += p[i].w;
    if (!(wsum > 0.0)) return r;
    r.ok = true;
    r.n = n;
    r.t0_s = t0;
    r.x0 = c(0, 0);
    r.vx = c(1, 0) / ts;
    r.ax = 2.0 * c(2, 0) / (ts * ts);
    r.y0 = c(0, 1);
    r.vy = c(1, 1) / ts;
    r.ay = 2.0 * c(2, 1) / (ts * ts);
    // residuals in pixels (weights relative: normalised to a mean of 1)
    double wmean = wsum / (double)n;
    if (n > 3) {
        double sx = res.col(0).squaredNorm() / wmean / (double)(n - 3);
        double sy = res.col(1).squaredNorm() / wmean / (double)(n - 3);
        r.rms_px = std::sqrt(0.5 * (sx + sy));
        Eigen::Matrix3d inv = (A.transpose() * A).inverse() * wmean;
        r.ax_se = 2.0 * std::sqrt(sx * inv(2, 2)) / (ts * ts);
        r.ay_se = 2.0 * std::sqrt(sy * inv(2, 2)) / (ts * ts);
    }
    return r;
}

bool FallPrior::admits(const Parabola &f) const
{
    double a = std::hypot(f.ax, f.ay);
    if (!(a >= a_min && a <= a_max)) return false;
    return a > 0.0 ? (f.ax * gx + f.ay * gy) / a >= cos_min : cos_min <= -1.0;
}

Parabola ransac_parabola(const std::vector<TrackPoint> &p, double tol_px, int iters,
                         std::vector<bool> &inlier, unsigned seed, const FallPrior &prior)
{
    size_t n = p.size();
    inlier.assign(n, false);
    Parabola best;
    if (n < 3) return best;
    std::mt19937 rng(seed);
    std::uniform_int_distribution<size_t> pick(0, n - 1);
    size_t best_count = 0;
    double best_sse = 0.0;
    std::vector<bool> cur(n);
    auto score = [&](const Parabola &m, std::vector<bool> &in, double *sse) {
        size_t c = 0;
        *sse = 0.0;
        for (size_t i = 0; i < n; i++) {
            double d = std::hypot(m.x(p[i].t_s) - p[i].x_px, m.y(p[i].t_s) - p[i].y_px);
            in[i] = d <= tol_px;
            if (in[i]) {
                c++;
                *sse += d * d;
            }
        }
        return c;
    };
    // exhaustive for small sets, random triples otherwise
    std::vector<size_t> idx;
    bool exhaustive = n <= 12;
    int budget = exhaustive ? (int)(n * (n - 1) * (n - 2) / 6) : iters;
    size_t a = 0, b = 1, c = 2;
    for (int it = 0; it < budget; it++) {
        size_t i, j, k;
        if (exhaustive) {
            i = a; j = b; k = c;
            if (++c == n) { if (++b == n - 1) { ++a; b = a + 1; } c = b + 1; }
        } else {
            i = pick(rng); j = pick(rng); k = pick(rng);
        }
        if (i == j || j == k || i == k) continue;
        TrackPoint tri[3] = {p[i], p[j], p[k]};
        for (TrackPoint &q : tri) q.w = 1.0;
        if (tri[0].t_s == tri[1].t_s || tri[1].t_s == tri[2].t_s || tri[0].t_s == tri[2].t_s) continue;
        Parabola m = fit_parabola(tri, 3);
        if (!m.ok || !prior.admits(m)) continue;
        double sse;
        size_t cnt = score(m, cur, &sse);
        if (cnt > best_count || (cnt == best_count && sse < best_sse)) {
            best_count = cnt;
            best_sse = sse;
            inlier = cur;
            best = m;
        }
    }
    if (best_count < 3) {
        inlier.assign(n, false);
        return Parabola();
    }
    // refit on the inliers, twice (the set may grow)
    for (int pass = 0; pass < 2; pass++) {
        std::vector<TrackPoint> in;
        for (size_t i = 0; i < n; i++)
            if (inlier[i]) in.push_back(p[i]);
        Parabola m = fit_parabola(in);
        if (!m.ok || !prior.admits(m)) break;
        double sse;
        size_t cnt = score(m, cur, &sse);
        if (cnt < 3) break;
        best = m;
        inlier = cur;
        if (cnt == in.size()) break;
    }
    return best;
}

TrendTest trend_test(const std::vector<double> &t_s, const std::vector<double> &u_px, double t_apex_s)
{
    TrendTest r;
    size_t n = t_s.size();
    if (n < 8 || u_px.size() != n) return r;
    double lo = *std::min_element(t_s.begin(), t_s.end()), hi = *std::max_element(t_s.begin(), t_s.end());
    double t0 = 0.5 * (lo + hi), ts = std::max(1e-9, 0.5 * (hi - lo));
    Eigen::MatrixXd A(n, 5);
    Eigen::VectorXd b(n);
    for (size_t i = 0; i < n; i++) {
        double u = (t_s[i] - t0) / ts, pw = 1.0;
        for (int k = 0; k < 5; k++) {
            A(i, k) = pw;
            pw *= u;
        }
        b(i) = u_px[i];
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> q2(A.leftCols(3)), q4(A);
    if (q2.rank() < 3 || q4.rank() < 5) return r;
    Eigen::VectorXd c2 = q2.solve(b), c4 = q4.solve(b);
    double rss2 = (A.leftCols(3) * c2 - b).squaredNorm(), rss4 = (A * c4 - b).squaredNorm();
    r.ok = true;
    r.n = n;
    r.a_px_s2 = 2.0 * c2(2) / (ts * ts);
    r.rms2_px = std::sqrt(rss2 / (double)(n - 3));
    r.rms4_px = std::sqrt(rss4 / (double)(n - 5));
    double floor = 1e-12 + 1e-6 * rss2;
    r.f_stat = ((rss2 - rss4) / 2.0) / (std::max(rss4, floor) / (double)(n - 5));
    // the change the data show for sure: the quartic's acceleration at the window's
    // extremes less two standard errors of their difference (a quartic's ends are noisy)
    Eigen::MatrixXd cov4 = (A.transpose() * A).inverse() * (rss4 / (double)(n - 5));
    double amin = 1e300, amax = -1e300;
    Eigen::Matrix<double, 5, 1> gmin = Eigen::Matrix<double, 5, 1>::Zero(), gmax = gmin;
    for (int k = 0; k <= 40; k++) {
        double u = -1.0 + k / 20.0;
        Eigen::Matrix<double, 5, 1> gv;
        gv << 0.0, 0.0, 2.0, 6.0 * u, 12.0 * u * u;
        gv /= ts * ts;
        double a = gv.dot(c4);
        if (a < amin) { amin = a; gmin = gv; }
        if (a > amax) { amax = a; gmax = gv; }
    }
    Eigen::Matrix<double, 5, 1> gd = gmax - gmin;
    double se_d = std::sqrt(std::max(0.0, (double)(gd.transpose() * cov4 * gd)));
    double change = std::max(0.0, amax - amin - 2.0 * se_d);
    r.a_change_rel = std::fabs(r.a_px_s2) > 0.0 ? change / std::fabs(r.a_px_s2) : 0.0;
    if (std::isfinite(t_apex_s)) {
        double u = (t_apex_s - t0) / ts;
        if (u >= -1.0 && u <= 1.0) {
            Eigen::Matrix<double, 5, 1> gv;
            gv << 0.0, 0.0, 2.0, 6.0 * u, 12.0 * u * u;
            gv /= ts * ts;
            r.a_apex_px_s2 = gv.dot(c4);
            r.a_apex_se_px_s2 = std::sqrt(std::max(0.0, (double)(gv.transpose() * cov4 * gv)));
        }
    }
    return r;
}

namespace {

// one pass of the size fit over the used detections; false when degenerate.
// Unknowns: (R | P, Q), U (perspective), s (smear), the last two bounded.
bool size_pass(const std::vector<MomentObs> &o, const std::vector<bool> &use, double psf2, double s_max,
               double u_max_rel, bool square, Eigen::VectorXd &theta, Eigen::MatrixXd &cov,
               std::vector<double> &res_obs)
{
    const int kd = square ? 1 : 2, k = kd + 2;  // diagonal unknowns, then U, s
    size_t m = 0;
    for (size_t i = 0; i < o.size(); i++) m += use[i] ? 3 : 0;
    if (m < (size_t)k + 3) return false;
    // U and s are scaled by the typical r^2 and v^2 so that the columns are alike
    double vv = 0.0, rr = 0.0;
    size_t nu = 0;
    for (size_t i = 0; i < o.size(); i++)
        if (use[i]) {
            vv += o[i].vx * o[i].vx + o[i].vy * o[i].vy;
            rr += o[i].rx * o[i].rx + o[i].ry * o[i].ry;
            nu++;
        }
    vv = std::max(1e-9, vv / (double)nu);
    rr = std::max(1e-9, rr / (double)nu);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero((long)m, k);
    Eigen::VectorXd b((long)m);
    long r = 0;
    for (size_t i = 0; i < o.size(); i++) {
        if (!use[i]) continue;
        const MomentObs &q = o[i];
        A(r, 0) = 1.0;
        A(r, kd) = q.rx * q.rx / rr;
        A(r, kd + 1) = q.vx * q.vx / vv;
        b(r++) = q.sxx - psf2;
        A(r, square ? 0 : 1) = 1.0;
        A(r, kd) = q.ry * q.ry / rr;
        A(r, kd + 1) = q.vy * q.vy / vv;
        b(r++) = q.syy - psf2;
        A(r, kd) = q.rx * q.ry / rr;
        A(r, kd + 1) = q.vx * q.vy / vv;
        b(r++) = q.sxy;
    }
    // bounded least squares by fixing what leaves its bounds (at most the two bounded ones)
    bool fixed[2] = {u_max_rel <= 0.0, false};
    double val[2] = {0.0, 0.0};  // U, s in scaled units
    for (int round = 0; round < 3; round++) {
        std::vector<int> cols;
        for (int c = 0; c < kd; c++) cols.push_back(c);
        for (int c = 0; c < 2; c++)
            if (!fixed[c]) cols.push_back(kd + c);
        Eigen::MatrixXd Af((long)m, (long)cols.size());
        Eigen::VectorXd bf = b;
        for (size_t c = 0; c < cols.size(); c++) Af.col((long)c) = A.col(cols[c]);
        for (int c = 0; c < 2; c++)
            if (fixed[c]) bf -= A.col(kd + c) * val[c];
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Af);
        if (qr.rank() < (long)cols.size()) {
            // not separable (no motion, no spread of positions): the first free bounded one is fixed at 0
            bool any = false;
            for (int c = 1; c >= 0 && !any; c--)
                if (!fixed[c]) { fixed[c] = true; val[c] = 0.0; any = true; }
            if (!any) return false;
            continue;
        }
        Eigen::VectorXd t = qr.solve(bf);
        theta = Eigen::VectorXd::Zero(k);
        for (size_t c = 0; c < cols.size(); c++) theta(cols[c]) = t((long)c);
        for (int c = 0; c < 2; c++)
            if (fixed[c]) theta(kd + c) = val[c];
        double dmean = 0.0;
        for (int c = 0; c < kd; c++) dmean += theta(c) / kd;
        double lim[2] = {u_max_rel * std::max(0.0, dmean) * rr, s_max * vv};
        bool again = false;
        for (int c = 0; c < 2; c++) {
            if (fixed[c]) continue;
            double v = theta(kd + c);
            if (v < 0.0 || v > lim[c]) {
                fixed[c] = true;
                val[c] = std::min(std::max(v, 0.0), lim[c]);
                again = true;
            }
        }
        if (!again) break;
        if (round == 2) {
            for (int c = 0; c < 2; c++) theta(kd + c) = fixed[c] ? val[c] : theta(kd + c);
        }
    }
    Eigen::VectorXd res = A * theta - b;
    double dof = std::max(1.0, (double)m - k);
    double s2 = res.squaredNorm() / dof;
    Eigen::MatrixXd AtA = A.transpose() * A;
    AtA.diagonal().array() += 1e-12 * std::max(1.0, AtA.diagonal().maxCoeff());
    cov = AtA.inverse() * s2;
    theta(kd) /= rr;
    theta(kd + 1) /= vv;
    res_obs.assign(o.size(), 0.0);
    const double P = theta(0), Q = square ? theta(0) : theta(1), U = theta(kd), sm = theta(kd + 1);
    for (size_t i = 0; i < o.size(); i++) {
        const MomentObs &q = o[i];
        double e1 = q.sxx - psf2 - P - U * q.rx * q.rx - sm * q.vx * q.vx;
        double e2 = q.syy - psf2 - Q - U * q.ry * q.ry - sm * q.vy * q.vy;
        double e3 = q.sxy - U * q.rx * q.ry - sm * q.vx * q.vy;
        res_obs[i] = std::sqrt((e1 * e1 + e2 * e2 + e3 * e3) / 3.0);
    }
    return true;
}

}  // namespace

SizeFit fit_size(const std::vector<MomentObs> &obs, double psf_sigma_px, double s_max_s2, double u_max_rel)
{
    SizeFit f;
    f.n = obs.size();
    if (obs.size() < 3) return f;
    const double psf2 = psf_sigma_px * psf_sigma_px;
    std::vector<bool> use(obs.size(), true);
    Eigen::VectorXd th;
    Eigen::MatrixXd cov;
    std::vector<double> res;
    // the non-square model decides which detections are outliers (partly hidden, merged)
    for (int pass = 0; pass < 3; pass++) {
        if (!size_pass(obs, use, psf2, s_max_s2, u_max_rel, false, th, cov, res)) return f;
        std::vector<double> ru;
        for (size_t i = 0; i < obs.size(); i++)
            if (use[i]) ru.push_back(res[i]);
        double scale = 1.4826 * median_of(ru);
        double lim = 3.0 * std::max(scale, 0.02 * std::max(th(0), th(1)) + 0.05);
        bool changed = false;
        for (size_t i = 0; i < obs.size(); i++) {
            bool u = res[i] <= lim;
            if (u != use[i]) changed = true;
            use[i] = u;
        }
        size_t nu = (size_t)std::count(use.begin(), use.end(), true);
        if (nu < 3) return f;
        if (!changed) break;
    }
    if (!size_pass(obs, use, psf2, s_max_s2, u_max_rel, false, th, cov, res)) return f;
    double P = th(0), Q = th(1);
    if (!(P > 0.0) || !(Q > 0.0)) return f;
    f.ok = true;
    f.n_used = (size_t)std::count(use.begin(), use.end(), true);
    f.dx_px = 4.0 * std::sqrt(P);
    f.dy_px = 4.0 * std::sqrt(Q);
    f.dx_se = 2.0 * std::sqrt(std::max(0.0, cov(0, 0)) / P);
    f.dy_se = 2.0 * std::sqrt(std::max(0.0, cov(1, 1)) / Q);
    f.s_s2 = th(3);
    f.aspect = std::sqrt(Q / P);
    double g0 = -f.aspect / (2.0 * P), g1 = f.aspect / (2.0 * Q);
    f.aspect_se = std::sqrt(std::max(0.0, g0 * g0 * cov(0, 0) + g1 * g1 * cov(1, 1) + 2.0 * g0 * g1 * cov(0, 1)));
    Eigen::VectorXd ts;
    Eigen::MatrixXd cs;
    if (size_pass(obs, use, psf2, s_max_s2, u_max_rel, true, ts, cs, res) && ts(0) > 0.0) {
        f.d_sq_px = 4.0 * std::sqrt(ts(0));
        f.d_sq_se = 2.0 * std::sqrt(std::max(0.0, cs(0, 0)) / ts(0));
    }
    return f;
}

double size_along(const SizeFit &f, double gx, double gy)
{
    double n = std::hypot(gx, gy);
    if (!(n > 0.0)) return f.dy_px;
    gx /= n;
    gy /= n;
    return std::sqrt(gx * gx * f.dx_px * f.dx_px + gy * gy * f.dy_px * f.dy_px);
}

}  // namespace gs
