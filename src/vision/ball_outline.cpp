// ball_outline.cpp - see ball_outline.hpp and docs/ball.md.
#include "ball_outline.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace gs {

namespace {

constexpr int kRays = 48;
constexpr double kStepPx = 0.25;                       // along a ray
constexpr double kMaxGapRad = 60.0 * CV_PI / 180.0;    // the widest angle without an edge an ellipse may bridge

double median_of(std::vector<double> v)
{
    if (v.empty()) return 0.0;
    size_t h = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + (long)h, v.end());
    return v[h];
}

float sample(const cv::Mat &m, double x, double y)
{
    int x0 = (int)std::floor(x), y0 = (int)std::floor(y);
    float fx = (float)(x - x0), fy = (float)(y - y0);
    const float *r0 = m.ptr<float>(y0), *r1 = m.ptr<float>(y0 + 1);
    return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

cv::Vec3f sample3(const cv::Mat &m, double x, double y)
{
    int x0 = (int)std::floor(x), y0 = (int)std::floor(y);
    float fx = (float)(x - x0), fy = (float)(y - y0);
    const cv::Vec3f *r0 = m.ptr<cv::Vec3f>(y0), *r1 = m.ptr<cv::Vec3f>(y0 + 1);
    return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

struct Edge {
    double theta, r;
};

// the conic a u^2 + b uv + c v^2 + d u + e v = 1 through the points (origin inside)
bool fit_conic(const std::vector<Edge> &e, const std::vector<bool> &in, double scale, double q[5])
{
    int n = (int)std::count(in.begin(), in.end(), true);
    if (n < 8) return false;
    cv::Mat A(n, 5, CV_64F), rhs(n, 1, CV_64F, cv::Scalar(1.0)), sol;
    int k = 0;
    for (size_t i = 0; i < e.size(); i++) {
        if (!in[i]) continue;
        double u = e[i].r * std::cos(e[i].theta) / scale, v = e[i].r * std::sin(e[i].theta) / scale;
        double *a = A.ptr<double>(k++);
        a[0] = u * u; a[1] = u * v; a[2] = v * v; a[3] = u; a[4] = v;
    }
    if (!cv::solve(A, rhs, sol, cv::DECOMP_QR)) return false;
    for (int i = 0; i < 5; i++) q[i] = sol.at<double>(i);
    return 4.0 * q[0] * q[2] - q[1] * q[1] > 0.0 && q[0] > 0.0;  // an ellipse
}

// the conic's radius along a ray from the origin
double conic_r(const double q[5], double scale, double theta)
{
    double c = std::cos(theta), s = std::sin(theta);
    double Q = q[0] * c * c + q[1] * c * s + q[2] * s * s, L = q[3] * c + q[4] * s;
    if (!(Q > 0.0)) return NAN;
    return scale * (-L + std::sqrt(L * L + 4.0 * Q)) / (2.0 * Q);
}

double max_gap(const std::vector<Edge> &e, const std::vector<bool> &in)
{
    std::vector<double> th;
    for (size_t i = 0; i < e.size(); i++)
        if (in[i]) th.push_back(e[i].theta);
    if (th.size() < 2) return 2.0 * CV_PI;
    std::sort(th.begin(), th.end());
    double g = th.front() + 2.0 * CV_PI - th.back();
    for (size_t i = 1; i < th.size(); i++) g = std::max(g, th[i] - th[i - 1]);
    return g;
}

}  // namespace

double ellipse_major(const BallOutline &o)
{
    double tr = o.sxx + o.syy, det = o.sxx * o.syy - o.sxy * o.sxy;
    return tr / 2.0 + std::sqrt(std::max(0.0, tr * tr / 4.0 - det));
}

double ellipse_minor(const BallOutline &o)
{
    double tr = o.sxx + o.syy, det = o.sxx * o.syy - o.sxy * o.sxy;
    return std::max(0.0, tr / 2.0 - std::sqrt(std::max(0.0, tr * tr / 4.0 - det)));
}

BallOutline ball_outline(const cv::Mat &I, const cv::Mat &B, double x0, double y0, double r_guess_px,
                         double ramp_px, double psf_sigma_px)
{
    BallOutline out;
    out.rays = kRays;
    if (I.empty() || I.size() != B.size() || !(r_guess_px > 1.0)) return out;
    // I - B per pixel, and its length: the step's level and the noise are read on the
    // length (any sign of contrast), the edge on I - B along the ball's colour there
    cv::Mat diff(I.size(), CV_32FC3), mag(I.size(), CV_32F);
    const double r_out = 1.35 * r_guess_px + ramp_px + 3.0;
    std::vector<double> far;
    for (int y = 0; y < I.rows; y++) {
        const cv::Vec3b *ir = I.ptr<cv::Vec3b>(y);
        const cv::Vec3f *br = B.ptr<cv::Vec3f>(y);
        cv::Vec3f *dr = diff.ptr<cv::Vec3f>(y);
        float *mr = mag.ptr<float>(y);
        for (int x = 0; x < I.cols; x++) {
            dr[x] = cv::Vec3f(ir[x][0] - br[x][0], ir[x][1] - br[x][1], ir[x][2] - br[x][2]);
            mr[x] = std::sqrt(dr[x].dot(dr[x]));
            if (std::hypot(x - x0, y - y0) > r_out) far.push_back(mr[x]);
        }
    }
    // the background's own difference (sensor noise, compression) beyond the ball
    double noise = far.size() >= 16 ? median_of(far) : 3.0;
    const double hit = noise + std::max(2.5 * noise, 6.0);        // surely some ball
    const double contrast_min = std::max(3.0 * noise, 10.0);      // a step the half level can be read on
    const int ramp_n = (int)std::ceil((ramp_px + 1.0) / kStepPx);
    std::vector<Edge> edges;
    std::vector<float> p;
    std::vector<cv::Vec3f> pv;
    for (int k = 0; k < kRays; k++) {
        const double th = 2.0 * CV_PI * k / kRays, c = std::cos(th), s = std::sin(th);
        p.clear();
        pv.clear();
        for (double r = 0.0; r <= r_out; r += kStepPx) {
            double x = x0 + r * c, y = y0 + r * s;
            // three samples across the ray against the noise
            double xa = x - 0.75 * s, ya = y + 0.75 * c, xb = x + 0.75 * s, yb = y - 0.75 * c;
            if (std::min({xa, xb, x}) < 0.0 || std::min({ya, yb, y}) < 0.0 || std::max({xa, xb, x}) > I.cols - 1.001 ||
                std::max({ya, yb, y}) > I.rows - 1.001)
                break;
            p.push_back((sample(mag, x, y) + sample(mag, xa, ya) + sample(mag, xb, yb)) / 3.0f);
            pv.push_back((sample3(diff, x, y) + sample3(diff, xa, ya) + sample3(diff, xb, yb)) / 3.0f);
        }
        const int n = (int)p.size();
        // the ray must leave the ball inside the ROI
        if (n < 4 || (n - 1) * kStepPx < r_guess_px) continue;
        int i_hit = -1;
        for (int i = n - 1; i >= 0; i--)
            if (p[i] >= hit) { i_hit = i; break; }
        if (i_hit < 0 || i_hit >= n - 2) continue;
        // the step's inner level: the highest just inside, within the edge's ramp
        int i_lvl = i_hit;
        for (int i = std::max(0, i_hit - ramp_n); i <= i_hit; i++)
            if (p[i] > p[i_lvl]) i_lvl = i;
        if (p[i_lvl] - noise < contrast_min) continue;
        // along the ball's own colour there, I - B is alpha (C - B): the half level is the
        // edge; the noise and a compression halo of the other sign outside do not move it
        const cv::Vec3f e = pv[i_lvl] * (1.0f / std::max(1e-3f, (float)cv::norm(pv[i_lvl])));
        const double half = 0.5 * pv[i_lvl].dot(e);
        int j = i_lvl;
        while (j + 1 < n && pv[j + 1].dot(e) >= half) j++;
        if (j + 1 >= n) continue;
        const double qj = pv[j].dot(e), qn = pv[j + 1].dot(e);
        double r = (j + (qj - half) / std::max(1e-6, qj - qn)) * kStepPx;
        // a Gaussian blur moves a disc's half level inward by sigma^2 / 2R
        r += psf_sigma_px * psf_sigma_px / (2.0 * std::max(r, 1.0));
        edges.push_back({th, r});
    }
    out.rays_contrast = (int)edges.size();
    if (2 * out.rays_contrast < kRays) return out;
    std::vector<bool> in(edges.size(), true);
    // a shadow or a hand beside the ball moves some rays' edges outward: a robust circle first
    auto rays_in = [&](const std::vector<double> &res, double floor_px) {
        std::vector<double> a;
        for (double v : res) a.push_back(std::fabs(v));
        double sig = 1.4826 * median_of(a);
        double lim = std::max(floor_px, 3.0 * sig);
        for (size_t i = 0; i < res.size(); i++) in[i] = std::fabs(res[i]) <= lim;
    };
    std::vector<double> res(edges.size());
    {
        std::vector<double> rs;
        for (const Edge &e : edges) rs.push_back(e.r);
        double r_med = median_of(rs);
        for (size_t i = 0; i < edges.size(); i++) res[i] = edges[i].r - r_med;
        rays_in(res, std::max(1.0, 0.1 * r_med));
    }
    const double scale = r_guess_px;
    double q[5];
    for (int it = 0; it < 3; it++) {
        if (!fit_conic(edges, in, scale, q)) return out;
        for (size_t i = 0; i < edges.size(); i++) res[i] = edges[i].r - conic_r(q, scale, edges[i].theta);
        if (it < 2) rays_in(res, 0.75);
    }
    int n_in = (int)std::count(in.begin(), in.end(), true);
    if (2 * n_in < kRays || max_gap(edges, in) > kMaxGapRad) return out;
    double ss = 0.0;
    for (size_t i = 0; i < edges.size(); i++)
        if (in[i]) ss += res[i] * res[i];
    out.rms_px = std::sqrt(ss / n_in);
    // centre and shape: (p - c)^T A (p - c) = kq; a uniform ellipse's covariance is kq A^-1 / 4
    const double a = q[0], b = 0.5 * q[1], c = q[2], det = a * c - b * b;
    const double uc = -(c * q[3] - b * q[4]) / (2.0 * det), vc = -(a * q[4] - b * q[3]) / (2.0 * det);
    const double kq = 1.0 + a * uc * uc + 2.0 * b * uc * vc + c * vc * vc;
    if (!(kq > 0.0)) return out;
    const double f = kq * scale * scale / (4.0 * det);
    out.cx = x0 + uc * scale;
    out.cy = y0 + vc * scale;
    out.sxx = f * c;
    out.syy = f * a;
    out.sxy = -f * b;
    out.ok = std::isfinite(out.sxx) && std::isfinite(out.syy) && out.sxx > 0.0 && out.syy > 0.0;
    return out;
}

}  // namespace gs
