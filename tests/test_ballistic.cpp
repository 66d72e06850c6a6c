// test_ballistic.cpp - the ball's fits (src/vision/ballistic.cpp) against batch
// references and simulated truth: the parabola against Eigen's normal equations
// solved in long double, RANSAC over a candidate set with a hand and noise
// blobs, the trend test on a tilted camera's fall (perspective) against air
// drag and a rolling shutter, and the size fit on moments of a sphere with
// motion blur, perspective elongation and non-square pixels.
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Dense>

extern "C" {
#include "unity.h"
}

#include "ballistic.hpp"

void setUp(void) {}
void tearDown(void) {}

namespace {

// the batch reference: normal equations in long double on the raw time
void reference_parabola(const std::vector<gs::TrackPoint> &p, double t0, long double cx[3], long double cy[3])
{
    Eigen::Matrix<long double, 3, 3> M = Eigen::Matrix<long double, 3, 3>::Zero();
    Eigen::Matrix<long double, 3, 1> bx = Eigen::Matrix<long double, 3, 1>::Zero(), by = bx;
    for (const auto &q : p) {
        long double u = (long double)q.t_s - t0;
        Eigen::Matrix<long double, 3, 1> r(1.0L, u, u * u);
        M += (long double)q.w * r * r.transpose();
        bx += (long double)q.w * r * (long double)q.x_px;
        by += (long double)q.w * r * (long double)q.y_px;
    }
    Eigen::Matrix<long double, 3, 1> a = M.ldlt().solve(bx), b = M.ldlt().solve(by);
    for (int i = 0; i < 3; i++) {
        cx[i] = a(i);
        cy[i] = b(i);
    }
}

}  // namespace

// A weighted parabola at 1000 fps over 0.3 s (ill-conditioned on raw times)
void test_parabola_matches_batch_reference(void)
{
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 0.3);
    std::vector<gs::TrackPoint> p;
    for (int i = 0; i < 300; i++) {
        double t = 12.0 + i * 1e-3;
        double u = t - 12.1;
        p.push_back({t, 400.0 + 80.0 * u + n(rng), 200.0 - 900.0 * u + 0.5 * 2500.0 * u * u + n(rng),
                     0.5 + (i % 3)});
    }
    gs::Parabola f = gs::fit_parabola(p);
    TEST_ASSERT_TRUE(f.ok);
    long double cx[3], cy[3];
    reference_parabola(p, f.t0_s, cx, cy);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9 * 400, (double)cx[0], f.x0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-7 * 80, (double)cx[1], f.vx);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6 * 2500, (double)(2 * cy[2]), f.ay);
    TEST_ASSERT_DOUBLE_WITHIN(1e-7 * 900, (double)cy[1], f.vy);
    // the acceleration's SE is the scatter's: the truth within 4 SE, SE near its expected size
    TEST_ASSERT_DOUBLE_WITHIN(4 * f.ay_se, 2500.0, f.ay);
    TEST_ASSERT_TRUE(f.ay_se > 0.0 && f.ay_se < 200.0);
    TEST_ASSERT_DOUBLE_WITHIN(0.05, 0.3, f.rms_px);
}

// A ball's parabola among a hand moving steadily, a still ghost and noise blobs
void test_ransac_finds_the_ball_among_candidates(void)
{
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> ux(0.0, 640.0), uy(0.0, 480.0);
    std::normal_distribution<double> n(0.0, 0.4);
    std::vector<gs::TrackPoint> p;
    std::vector<bool> truth;
    for (int i = 0; i < 15; i++) {
        double t = i / 30.0;
        p.push_back({t, 100.0 + 150.0 * t + n(rng), 300.0 - 400.0 * t + 0.5 * 3000.0 * t * t + n(rng), 1.0});
        truth.push_back(true);
        p.push_back({t, 500.0 - 60.0 * t, 350.0 + 20.0 * t, 1.0});  // a hand
        truth.push_back(false);
        p.push_back({t, 320.0 + n(rng), 100.0 + n(rng), 1.0});  // a ghost
        truth.push_back(false);
        if (i % 2) {
            p.push_back({t, ux(rng), uy(rng), 1.0});
            truth.push_back(false);
        }
    }
    std::vector<bool> in;
    // a free fall of a 1 cm to 1 m ball of 12 px: g D / a within those sizes, pointing down
    gs::FallPrior prior;
    prior.a_min = 9.81 * 12.0 / 1.0;
    prior.a_max = 9.81 * 12.0 / 0.01;
    prior.cos_min = std::cos(40.0 * M_PI / 180.0);
    gs::Parabola f = gs::ransac_parabola(p, 2.0, 400, in, 7, prior);
    TEST_ASSERT_TRUE(f.ok);
    int tp = 0, fp = 0;
    for (size_t i = 0; i < p.size(); i++) {
        if (in[i] && truth[i]) tp++;
        if (in[i] && !truth[i]) fp++;
    }
    std::printf("ransac: %d of 15 ball points, %d others; a = %.0f px/s^2 (truth 3000)\n", tp, fp, f.ay);
    TEST_ASSERT_TRUE(tp >= 14);
    TEST_ASSERT_TRUE(fp <= 1);
    TEST_ASSERT_DOUBLE_WITHIN(150.0, 3000.0, f.ay);
}

namespace {

// a tennis ball dropped 1.2 m in front of a camera pitched down by pitch_deg (the
// fall toward or away from the image plane), image y of the ball's centre; with
// quadratic drag k (1/m) and an optional rolling shutter
std::vector<gs::TrackPoint> fall(double pitch_deg, double k_drag, double fps, double rs_k_rel, double v0_up = 0.0)
{
    const double f = 1400.0, g = 9.81, rows = 1920.0;
    double z = 0.0, vz = v0_up;  // height, up
    double th = pitch_deg * M_PI / 180.0;
    std::vector<gs::TrackPoint> p;
    double t = 0.0, h = 1e-4;
    double next = 0.0;
    while (z > -1.2 && t < 2.0) {
        if (t >= next - 1e-12) {
            // camera at 1.5 m from the fall's line, its axis pitched down by th toward mid-fall
            double Yc = z + 0.6, Zc = 1.5;  // relative to the camera at the fall's middle height
            double yc = -Yc * std::cos(th) + Zc * std::sin(th);
            double zc = Yc * std::sin(th) + Zc * std::cos(th);
            double y = f * yc / zc + 0.5 * rows;
            p.push_back({t, 540.0, y, 1.0});
            next += 1.0 / fps;
        }
        double a = -g - k_drag * std::fabs(vz) * vz;
        vz += a * h;
        z += vz * h;
        t += h;
    }
    if (rs_k_rel != 0.0) {
        // rows read one after another: each position shifted by v k (y - rows/2)
        double k = rs_k_rel / fps / rows;
        std::vector<gs::TrackPoint> q = p;
        for (size_t i = 1; i + 1 < p.size(); i++) {
            double v = (p[i + 1].y_px - p[i - 1].y_px) / (p[i + 1].t_s - p[i - 1].t_s);
            q[i].y_px = p[i].y_px + v * k * (p[i].y_px - 0.5 * rows);
        }
        p = std::vector<gs::TrackPoint>(q.begin() + 1, q.end() - 1);
    }
    return p;
}

gs::TrendTest trend_of(const std::vector<gs::TrackPoint> &p, double noise_px, unsigned seed)
{
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, noise_px);
    std::vector<double> t, u;
    for (const auto &q : p) {
        t.push_back(q.t_s);
        u.push_back(q.y_px + n(rng));
    }
    return gs::trend_test(t, u);
}

}  // namespace

// A camera tilted 30 degrees toward the fall: the image acceleration changes
// along the drop far beyond what drag or a rolling shutter can do
void test_trend_tilted_camera_against_drag_and_shutter(void)
{
    gs::TrendTest level = trend_of(fall(0.0, 0.0, 30.0, 0.0), 0.5, 1);
    gs::TrendTest tilted = trend_of(fall(30.0, 0.0, 30.0, 0.0), 0.5, 1);
    gs::TrendTest drag = trend_of(fall(0.0, 0.02, 30.0, 0.0), 0.5, 1);
    gs::TrendTest shutter = trend_of(fall(0.0, 0.0, 30.0, -0.6), 0.5, 1);
    std::printf("trend: level %.3f (F %.1f), tilted 30 deg %.3f (F %.1f), drag %.3f (F %.1f), shutter %.3f (F %.1f)\n",
                level.a_change_rel, level.f_stat, tilted.a_change_rel, tilted.f_stat, drag.a_change_rel, drag.f_stat,
                shutter.a_change_rel, shutter.f_stat);
    TEST_ASSERT_TRUE(level.ok && tilted.ok && drag.ok && shutter.ok);
    TEST_ASSERT_TRUE(level.f_stat < 12.0);
    TEST_ASSERT_TRUE(tilted.f_stat > 12.0);
    TEST_ASSERT_TRUE(tilted.a_change_rel > 0.3);
    TEST_ASSERT_TRUE(drag.a_change_rel < 0.1);
    TEST_ASSERT_TRUE(tilted.a_change_rel > 2.0 * shutter.a_change_rel);
}

// The acceleration at the apex of a toss with strong drag is g's alone
void test_trend_apex_acceleration_free_of_drag(void)
{
    std::vector<gs::TrackPoint> p = fall(0.0, 0.05, 60.0, 0.0, 4.0);
    p.resize(p.size() * 2 / 3);  // up and most of the way down
    std::vector<double> t, u;
    double t_apex = 0.0, umax = -1e30;
    for (const auto &q : p) {
        t.push_back(q.t_s);
        u.push_back(q.y_px);
        if (-q.y_px > umax) { umax = -q.y_px; t_apex = q.t_s; }
    }
    gs::TrendTest tt = gs::trend_test(t, u, t_apex);
    double a_true = 1400.0 * 9.81 / 1.5;  // f g / Z
    std::printf("apex: parabola a %.0f, quartic at the apex %.0f +- %.1f, truth %.0f px/s^2\n", tt.a_px_s2,
                tt.a_apex_px_s2, tt.a_apex_se_px_s2, a_true);
    TEST_ASSERT_DOUBLE_WITHIN(0.01 * a_true, a_true, tt.a_apex_px_s2);
    TEST_ASSERT_TRUE(std::fabs(tt.a_px_s2 - a_true) > std::fabs(tt.a_apex_px_s2 - a_true));
}

namespace {

// second moments of a ball of diameter d_px (pixels aspect: dy = aspect dx),
// off the axis by r (focal f), blurred by the camera (psf2) and by the motion v
// over an exposure of e seconds
gs::MomentObs moments(double d_px, double aspect, double rx, double ry, double f, double vx, double vy, double e,
                      double psf2)
{
    double P = d_px * d_px / 16.0, Q = aspect * aspect * P, U = P / (f * f), s = e * e / 12.0;
    gs::MomentObs m;
    m.sxx = P + U * rx * rx + s * vx * vx + psf2;
    m.syy = Q + U * ry * ry + s * vy * vy + psf2;
    m.sxy = U * rx * ry + s * vx * vy;
    m.vx = vx;
    m.vy = vy;
    m.rx = rx;
    m.ry = ry;
    return m;
}

}  // namespace

// A bounce's worth of detections: blur along the motion, perspective off the axis,
// 2 % noise, one detection merged with a hand; square and 4:3 pixels
void test_size_fit_recovers_the_sharp_diameter(void)
{
    std::mt19937 rng(11);
    std::normal_distribution<double> n(0.0, 0.01);
    for (double aspect : {1.0, 4.0 / 3.0}) {
        std::vector<gs::MomentObs> mo;
        for (int i = 0; i < 20; i++) {
            double t = (i - 10) / 60.0;
            double vx = 300.0, vy = -2500.0 * t * 2.0;
            double rx = -400.0 + vx * (t + 0.2), ry = 300.0 + 0.5 * 5000.0 * t * t;
            gs::MomentObs m = moments(30.0, aspect, rx, ry, 1500.0, vx, vy, 1.0 / 120.0, 1.0);
            m.sxx *= 1.0 + n(rng);
            m.syy *= 1.0 + n(rng);
            if (i == 4) m.syy *= 1.6;  // merged with a hand
            mo.push_back(m);
        }
        gs::SizeFit f = gs::fit_size(mo, 1.0, 1.05 / (60.0 * 60.0 * 12.0), 1.0 / (500.0 * 500.0));
        std::printf("size fit, aspect %.2f: dx %.2f +- %.2f, dy %.2f +- %.2f (truth 30, %.1f), square %.2f, "
                    "aspect %.3f +- %.3f, %zu of %zu used\n",
                    aspect, f.dx_px, f.dx_se, f.dy_px, f.dy_se, 30.0 * aspect, f.d_sq_px, f.aspect, f.aspect_se,
                    f.n_used, f.n);
        TEST_ASSERT_TRUE(f.ok);
        TEST_ASSERT_DOUBLE_WITHIN(0.3, 30.0, f.dx_px);
        TEST_ASSERT_DOUBLE_WITHIN(0.4, 30.0 * aspect, f.dy_px);
        TEST_ASSERT_DOUBLE_WITHIN(0.4, 30.0 * aspect, gs::size_along(f, 0.0, 1.0));
        TEST_ASSERT_DOUBLE_WITHIN(4.0 * f.aspect_se + 0.01, aspect, f.aspect);
        TEST_ASSERT_TRUE(f.n_used == f.n - 1);
        if (aspect == 1.0) TEST_ASSERT_DOUBLE_WITHIN(0.3, 30.0, f.d_sq_px);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_parabola_matches_batch_reference);
    RUN_TEST(test_ransac_finds_the_ball_among_candidates);
    RUN_TEST(test_trend_tilted_camera_against_drag_and_shutter);
    RUN_TEST(test_trend_apex_acceleration_free_of_drag);
    RUN_TEST(test_size_fit_recovers_the_sharp_diameter);
    return UNITY_END();
}
