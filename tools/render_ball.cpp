// render_ball.cpp - rendered clips of a tennis ball dropped in front of a static
// camera, with their truth: the held-out set of issue 3 as we understand it.
//
//   render_ball --out CLIP.avi [--key value ...]          one clip
//   render_ball --set N --seed S --outdir DIR [--index I] [--key value ...]
//                                                         a set (or clip I of it)
//
// A set draws each clip's parameters from the seed (clip i: 1080p60 when i is
// even, 720p120 when odd; distance stratified over 1-5 m within each mode); any
// --key given on the command line overrides the drawn value, so `--drag 0` with
// the same seed renders the same clips without air drag.
//
// The scene: a pinhole camera (focal length from the horizontal field of view,
// level unless --pitch-deg), a floor (wooden planks) and a wall (textured
// paint, skirting board, posters, a door frame) with a lighting gradient and
// vignetting, green distractors (a ball on the floor, a plant, a box; one green
// ball rolling slowly behind), and a 6.7 cm optic-yellow ball with Lambert
// shading, a fuzzy (felt) edge and a soft shadow on the floor. The ball hangs at
// rest until --release-s (no hand is drawn), then falls: RK4 at 0.1 ms with
// quadratic drag and bounces of restitution 0.72 on the floor. Its silhouette is
// the exact perspective projection of the sphere (an ellipse off the axis).
// Motion blur averages sub-frames over the exposure (centred on the frame time),
// then optics blur, Gaussian noise, 8 bits and MJPG (OpenCV's own AVI writer at
// the given quality).
//
// --vup-m-s tosses the ball up at release (the apex mid-flight); --pixel-aspect
// stores non-square pixels (rendered square, resampled to --width: the truth's
// x positions and diameters stay in square pixels); --sat 0 with --albedo gives a
// white, grey or black ball; --restitution 0 a single drop; --pitch-deg a
// camera tilted toward the fall.
//
// Writes CLIP.avi, CLIP.json (parameters and per-flight truth) and
// CLIP.frames.csv (per-frame truth). Exit 0 ok, 2 usage error, 3 write error.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace {

const double kG = 9.81;
const double kPi = 3.14159265358979323846;

struct Params {
    int width = 1920, height = 1080;
    double fps = 60.0, duration_s = 3.5;
    double hfov_deg = 65.0;
    double cam_height_m = NAN;    // NaN: put the floor under the ball at floor_frac of the height
    double floor_frac = 0.88;
    double pitch_deg = 0.0;       // camera looking down by this much
    double dist_m = 3.0;          // ball's depth (along the level optical axis) at release
    double x_m = 0.0;             // ball's lateral position at release (right +)
    double drop_m = 1.3;          // ball's bottom above the floor at release
    double vx_m_s = 0.0, vz_m_s = 0.0;  // lateral and depth velocity at release
    double vup_m_s = 0.0;         // upward velocity at release (a toss)
    double pixel_aspect = 1.0;    // a stored pixel's width / height (the frame is rendered square, then resampled)
    double release_s = 0.4;
    int drag = 1;
    double cd = 0.55, rho_kg_m3 = 1.2, mass_kg = 0.058, diam_m = 0.067, restitution = 0.72;
    double fuzz_m = 0.0015;       // felt: the edge fades over this width
    double hue_deg = 70.0, sat = 0.72, albedo = 0.85;
    double exposure_frac = 0.5;   // exposure / frame time
    double noise_sigma = 2.5;     // 8-bit units
    double optics_sigma_px = 0.55;
    int quality = 85;
    double wall_gap_m = 1.0;      // wall depth behind the ball
    int distractors = 1, moving_distractor = 1, shadow = 1;
    int distractor_clear = 1;
    double ambient = 0.45;        // shading: the unlit side's brightness (1: flat)     // keep the static distractors out of the ball's column
    double distractor_hue_deg = 120.0;
    uint64_t seed = 1;
    int preview_frame = -1;       // also write this frame as CLIP.preview.png
};

// ---- parameters: table of --key -> field ---------------------------------------------

struct Key {
    const char *name;
    double Params::*d;
    int Params::*i;
    double lo, hi;
};

const Key kKeys[] = {
    {"width", nullptr, &Params::width, 64, 8192},
    {"height", nullptr, &Params::height, 64, 8192},
    {"fps", &Params::fps, nullptr, 1, 1000},
    {"duration-s", &Params::duration_s, nullptr, 0.1, 60},
    {"hfov-deg", &Params::hfov_deg, nullptr, 10, 150},
    {"cam-height-m", &Params::cam_height_m, nullptr, 0.01, 10},
    {"floor-frac", &Params::floor_frac, nullptr, 0.3, 1.5},
    {"pitch-deg", &Params::pitch_deg, nullptr, -45, 45},
    {"dist-m", &Params::dist_m, nullptr, 0.3, 50},
    {"x-m", &Params::x_m, nullptr, -20, 20},
    {"drop-m", &Params::drop_m, nullptr, 0.05, 10},
    {"vx-m-s", &Params::vx_m_s, nullptr, -20, 20},
    {"vz-m-s", &Params::vz_m_s, nullptr, -20, 20},
    {"vup-m-s", &Params::vup_m_s, nullptr, -20, 20},
    {"pixel-aspect", &Params::pixel_aspect, nullptr, 0.5, 2},
    {"release-s", &Params::release_s, nullptr, 0, 60},
    {"drag", nullptr, &Params::drag, 0, 1},
    {"cd", &Params::cd, nullptr, 0, 5},
    {"rho-kg-m3", &Params::rho_kg_m3, nullptr, 0, 100},
    {"mass-kg", &Params::mass_kg, nullptr, 0.001, 100},
    {"diam-m", &Params::diam_m, nullptr, 0.005, 2},
    {"restitution", &Params::restitution, nullptr, 0, 1},
    {"fuzz-m", &Params::fuzz_m, nullptr, 0, 0.02},
    {"hue-deg", &Params::hue_deg, nullptr, 0, 360},
    {"sat", &Params::sat, nullptr, 0, 1},
    {"albedo", &Params::albedo, nullptr, 0.05, 1},
    {"exposure-frac", &Params::exposure_frac, nullptr, 0.001, 1},
    {"noise-sigma", &Params::noise_sigma, nullptr, 0, 64},
    {"optics-sigma-px", &Params::optics_sigma_px, nullptr, 0, 10},
    {"quality", nullptr, &Params::quality, 1, 100},
    {"wall-gap-m", &Params::wall_gap_m, nullptr, 0.1, 50},
    {"distractors", nullptr, &Params::distractors, 0, 1},
    {"moving-distractor", nullptr, &Params::moving_distractor, 0, 1},
    {"shadow", nullptr, &Params::shadow, 0, 1},
    {"ambient", &Params::ambient, nullptr, 0, 1},
    {"distractor-clear", nullptr, &Params::distractor_clear, 0, 1},
    {"distractor-hue-deg", &Params::distractor_hue_deg, nullptr, 0, 360},
    {"preview-frame", nullptr, &Params::preview_frame, -1, 1e6},
};

const Key *find_key(const char *name)
{
    for (const Key &k : kKeys)
        if (std::strcmp(k.name, name) == 0) return &k;
    return nullptr;
}

[[noreturn]] void usage_error(const std::string &msg)
{
    std::fprintf(stderr, "render_ball: %s (render_ball --help)\n", msg.c_str());
    std::exit(2);
}

bool parse_double(const char *s, double *out)
{
    char *end = nullptr;
    errno = 0;
    double v = std::strtod(s, &end);
    if (end == s || *end != '\0' || errno != 0 || !std::isfinite(v)) return false;
    *out = v;
    return true;
}

void apply(Params &p, const Key &k, double v)
{
    if (v < k.lo || v > k.hi)
        usage_error(std::string("--") + k.name + ": " + std::to_string(v) + " outside [" + std::to_string(k.lo) +
                    ", " + std::to_string(k.hi) + "]");
    if (k.d) {
        p.*(k.d) = v;
    } else {
        if (v != std::floor(v)) usage_error(std::string("--") + k.name + ": not a whole number");
        p.*(k.i) = static_cast<int>(v);
    }
}

// Clip i of a set drawn from seed: the ranges of the held-out set.
Params draw_set_clip(uint64_t seed, int n, int i)
{
    Params p;
    std::mt19937_64 rng(seed * 1000003ULL + static_cast<uint64_t>(i) * 7919ULL + 17ULL);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    auto U = [&](double a, double b) { return a + (b - a) * u01(rng); };
    bool hd = (i % 2) == 0;
    p.width = hd ? 1920 : 1280;
    p.height = hd ? 1080 : 720;
    p.fps = hd ? 60.0 : 120.0;
    int per_mode = (n + 1) / 2, slot = i / 2;
    p.dist_m = 1.0 + 4.0 * (slot + U(0.0, 1.0)) / per_mode;
    p.drop_m = U(1.0, 1.6);
    p.hfov_deg = U(60.0, 70.0);
    p.floor_frac = U(0.82, 0.92);
    double half_w_m = p.dist_m * std::tan(0.5 * p.hfov_deg * kPi / 180.0);
    p.x_m = U(-0.35, 0.35) * half_w_m;
    p.vx_m_s = U(-0.05, 0.05);
    p.vz_m_s = U(-0.02, 0.02);
    p.release_s = U(0.25, 0.6);
    p.exposure_frac = U(0.5, 1.0);
    p.noise_sigma = U(1.5, 4.0);
    p.optics_sigma_px = U(0.4, 0.8);
    p.quality = static_cast<int>(std::lround(U(70, 92)));
    p.wall_gap_m = U(0.4, 2.0);
    p.hue_deg = U(64.0, 74.0);
    p.sat = U(0.65, 0.8);
    p.moving_distractor = u01(rng) < 0.7 ? 1 : 0;
    p.distractor_hue_deg = U(100.0, 150.0);
    p.seed = seed * 100 + static_cast<uint64_t>(i);
    return p;
}

// ---- geometry ---------------------------------------------------------------------------

struct V3 {
    double x, y, z;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double norm(V3 a) { return std::sqrt(dot(a, a)); }

// World: x right, y up, z forward (horizontal), floor y = 0, camera at (0, h, 0).
// Camera: x right, y down, z along the optical axis, pitched down by pitch.
struct Camera {
    double f, cx, cy, h_m, pitch;
    int w, hgt;
    V3 to_cam(V3 pw) const
    {
        V3 d = pw - V3{0, h_m, 0};
        double s = std::sin(pitch), c = std::cos(pitch);
        return {d.x, -d.y * c - d.z * s, -d.y * s + d.z * c};
    }
    V3 dir_to_world(V3 dc) const
    {
        double s = std::sin(pitch), c = std::cos(pitch);
        return {dc.x, -dc.y * c - dc.z * s, -dc.y * s + dc.z * c};
    }
    bool project(V3 pw, double *u, double *v) const
    {
        V3 pc = to_cam(pw);
        if (pc.z <= 1e-6) return false;
        *u = cx + f * pc.x / pc.z;
        *v = cy + f * pc.y / pc.z;
        return true;
    }
};

// The image of a sphere (centre pc in camera coordinates, radius r): an ellipse.
struct Ellipse {
    double u, v;          // centre, px
    double minor_px;      // full axes, px
    double major_px;
    double ru, rv;        // unit radial direction in the image
};

Ellipse sphere_image(const Camera &cam, V3 pc, double r)
{
    double d = norm(pc);
    double sa = std::min(r / d, 0.999), ca = std::sqrt(1.0 - sa * sa);
    double ct = pc.z / d, st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
    double den = ct * ct - sa * sa;
    Ellipse e;
    double rho = cam.f * st * ct / den;
    double l = std::hypot(pc.x, pc.y);
    e.ru = l > 1e-12 ? pc.x / l : 1.0;
    e.rv = l > 1e-12 ? pc.y / l : 0.0;
    e.u = cam.cx + rho * e.ru;
    e.v = cam.cy + rho * e.rv;
    e.minor_px = 2.0 * cam.f * sa / std::sqrt(den);
    e.major_px = 2.0 * cam.f * sa * ca / den;
    return e;
}

// ---- physics ----------------------------------------------------------------------------

struct State {
    V3 p, v;
};

struct Trajectory {
    double dt = 1e-4;
    double t0 = 0;
    std::vector<V3> pos;           // ball centre, world, every dt from t0
    std::vector<double> bounce_t;  // times of floor impacts
    double rest_t = NAN;           // time it came to rest on the floor
};

V3 accel(const Params &p, V3 v)
{
    double k = p.drag ? 0.5 * p.rho_kg_m3 * p.cd * kPi * 0.25 * p.diam_m * p.diam_m / p.mass_kg : 0.0;
    double s = norm(v);
    return V3{0, -kG, 0} - (k * s) * v;
}

State rk4(const Params &p, State s, double h)
{
    V3 k1v = accel(p, s.v), k1p = s.v;
    V3 k2v = accel(p, s.v + (0.5 * h) * k1v), k2p = s.v + (0.5 * h) * k1v;
    V3 k3v = accel(p, s.v + (0.5 * h) * k2v), k3p = s.v + (0.5 * h) * k2v;
    V3 k4v = accel(p, s.v + h * k3v), k4p = s.v + h * k3v;
    State o;
    o.v = s.v + (h / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    o.p = s.p + (h / 6.0) * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
    return o;
}

Trajectory simulate(const Params &p, double t_end)
{
    Trajectory tr;
    double r = 0.5 * p.diam_m;
    State s{{p.x_m, p.drop_m + r, p.dist_m}, {0, 0, 0}};
    bool resting = false;
    int n = static_cast<int>(std::ceil(t_end / tr.dt)) + 2;
    tr.pos.reserve(n);
    for (int i = 0; i < n; i++) {
        double t = i * tr.dt;
        tr.pos.push_back(s.p);
        if (t + 0.5 * tr.dt < p.release_s) continue;        // held still
        if (t < p.release_s + tr.dt && s.v.x == 0 && s.v.y == 0 && !resting) s.v = {p.vx_m_s, p.vup_m_s, p.vz_m_s};
        if (resting) {  // rolling on the floor, slowing down
            s.v.x *= 1.0 - 0.5 * tr.dt;
            s.v.z *= 1.0 - 0.5 * tr.dt;
            s.p = s.p + tr.dt * s.v;
            continue;
        }
        State nx = rk4(p, s, tr.dt);
        if (nx.p.y < r && nx.v.y < 0) {
            // integrate exactly up to the contact (bisection on the step), reflect, go on
            double lo = 0, hi = tr.dt;
            for (int it = 0; it < 40; it++) {
                double mid = 0.5 * (lo + hi);
                if (rk4(p, s, mid).p.y < r) hi = mid; else lo = mid;
            }
            State c = rk4(p, s, lo);
            tr.bounce_t.push_back(t + lo);
            c.p.y = r;
            c.v.y = -p.restitution * c.v.y;
            c.v.x *= 0.9;  // floor friction: a little of the horizontal speed goes into spin
            c.v.z *= 0.9;
            if (c.v.y < 0.12) {  // bounces below 0.7 mm: at rest
                c.v.y = 0;
                resting = true;
                tr.rest_t = t + lo;
                c.p = c.p + (tr.dt - lo) * c.v;
                s = c;
            } else {
                s = rk4(p, c, tr.dt - lo);
            }
        } else {
            s = nx;
        }
    }
    return tr;
}

V3 traj_at(const Trajectory &tr, double t)
{
    double x = (t - tr.t0) / tr.dt;
    if (x <= 0) return tr.pos.front();
    size_t i = static_cast<size_t>(x);
    if (i + 1 >= tr.pos.size()) return tr.pos.back();
    double a = x - static_cast<double>(i);
    return (1.0 - a) * tr.pos[i] + a * tr.pos[i + 1];
}

// ---- textures ---------------------------------------------------------------------------

double hash2(int64_t x, int64_t y, uint64_t seed)
{
    uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ULL ^ static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4FULL ^
                 seed * 0x165667B19E3779F9ULL;
    h ^= h >> 33;
    h *= 0xFF51AFD7ED558CCDULL;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ULL;
    h ^= h >> 33;
    return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

double vnoise(double x, double y, uint64_t seed)
{
    double fx = std::floor(x), fy = std::floor(y);
    int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
    double ax = x - fx, ay = y - fy;
    ax = ax * ax * (3 - 2 * ax);
    ay = ay * ay * (3 - 2 * ay);
    double a = hash2(ix, iy, seed), b = hash2(ix + 1, iy, seed);
    double c = hash2(ix, iy + 1, seed), d = hash2(ix + 1, iy + 1, seed);
    return (a + (b - a) * ax) * (1 - ay) + (c + (d - c) * ax) * ay;
}

double fbm(double x, double y, uint64_t seed)
{
    double s = 0, amp = 0.5;
    for (int o = 0; o < 4; o++) {
        s += amp * vnoise(x, y, seed + static_cast<uint64_t>(o));
        x *= 2.03;
        y *= 2.03;
        amp *= 0.5;
    }
    return s / 0.9375;
}

// HSV (hue in degrees, s, v in 0-1) to BGR in 0-255
cv::Vec3f hsv_bgr(double hue, double s, double v)
{
    double c = v * s, hp = std::fmod(hue, 360.0) / 60.0, x = c * (1 - std::fabs(std::fmod(hp, 2.0) - 1));
    double r = 0, g = 0, b = 0;
    if (hp < 1) { r = c; g = x; }
    else if (hp < 2) { r = x; g = c; }
    else if (hp < 3) { g = c; b = x; }
    else if (hp < 4) { g = x; b = c; }
    else if (hp < 5) { r = x; b = c; }
    else { r = c; b = x; }
    double m = v - c;
    return cv::Vec3f(static_cast<float>(255 * (b + m)), static_cast<float>(255 * (g + m)), static_cast<float>(255 * (r + m)));
}

struct Rect3 {  // a rectangle on the wall, world x and y
    double x0, x1, y0, y1;
    cv::Vec3f col;
};

struct Scene {
    Camera cam;
    double wall_z;
    cv::Mat bg;          // CV_32FC3, 0-255, static, sharp
    cv::Mat floor_xz;    // CV_32FC2, world (x, z) of floor pixels, NaN elsewhere
    V3 light;            // unit vector towards the light, camera coordinates
};

// ---- the sphere painter -----------------------------------------------------------------

struct Sphere {
    V3 pc;         // centre, camera coordinates
    double r;      // radius, m
    cv::Vec3f col; // albedo colour, 0-255
};

// Adds (with weight w) the sphere's coverage and shaded colour into acc (alpha in
// channel 3), over the pixels it may touch. Returns false when off screen.
void splat_sphere(const Scene &sc, const Sphere &s, double fuzz_m, double w, cv::Mat &acc, double ambient = 0.45)
{
    const Camera &cam = sc.cam;
    if (s.pc.z <= s.r * 1.5) return;
    Ellipse e = sphere_image(cam, s.pc, s.r);
    double d = norm(s.pc);
    double alpha = std::asin(std::min(s.r / d, 0.999));
    double px_per_rad = 0.5 * e.minor_px / alpha;  // ~ f / cos(theta) across the edge
    double fuzz_px = fuzz_m * px_per_rad / d;
    double ramp_px = std::sqrt(1.0 + fuzz_px * fuzz_px);
    double reach = 0.5 * e.major_px + ramp_px + 2.0;
    int x0 = std::max(0, static_cast<int>(std::floor(e.u - reach)));
    int x1 = std::min(cam.w - 1, static_cast<int>(std::ceil(e.u + reach)));
    int y0 = std::max(0, static_cast<int>(std::floor(e.v - reach)));
    int y1 = std::min(cam.hgt - 1, static_cast<int>(std::ceil(e.v + reach)));
    if (x0 > x1 || y0 > y1) return;
    V3 chat = (1.0 / d) * s.pc;
    for (int y = y0; y <= y1; y++) {
        cv::Vec4f *row = acc.ptr<cv::Vec4f>(y);
        for (int x = x0; x <= x1; x++) {
            V3 ray{(x - cam.cx) / cam.f, (y - cam.cy) / cam.f, 1.0};
            ray = (1.0 / norm(ray)) * ray;
            double cpsi = dot(ray, chat);
            V3 cr{ray.y * chat.z - ray.z * chat.y, ray.z * chat.x - ray.x * chat.z, ray.x * chat.y - ray.y * chat.x};
            double psi = std::atan2(norm(cr), cpsi);
            double sd_px = (psi - alpha) * px_per_rad;
            double a = 0.5 - sd_px / ramp_px;
            if (a <= 0) continue;
            if (a > 1) a = 1;
            // the visible surface point (at the limb for the fringe)
            double dperp = std::min(d * std::sin(psi), s.r);
            double t = d * std::cos(psi) - std::sqrt(std::max(0.0, s.r * s.r - dperp * dperp));
            V3 n = (1.0 / s.r) * (t * ray - s.pc);
            double lam = std::max(0.0, dot(n, sc.light));
            double shade = ambient + (1.1 - ambient) * lam;  // indoor: much fill light
            // felt: a little darker towards the limb
            shade *= 0.9 + 0.1 * std::max(0.0, -dot(n, ray));
            float wa = static_cast<float>(w * a);
            cv::Vec4f &o = row[x];
            o[0] += wa * s.col[0] * static_cast<float>(shade);
            o[1] += wa * s.col[1] * static_cast<float>(shade);
            o[2] += wa * s.col[2] * static_cast<float>(shade);
            o[3] += wa;
        }
    }
}

void composite(cv::Mat &img, const cv::Mat &acc, cv::Rect roi)
{
    for (int y = roi.y; y < roi.y + roi.height; y++) {
        cv::Vec3f *ir = img.ptr<cv::Vec3f>(y);
        const cv::Vec4f *ar = acc.ptr<cv::Vec4f>(y);
        for (int x = roi.x; x < roi.x + roi.width; x++) {
            float a = std::min(1.0f, ar[x][3]);
            if (a <= 0) continue;
            ir[x] = ir[x] * (1.0f - a) + cv::Vec3f(ar[x][0], ar[x][1], ar[x][2]);
        }
    }
}

// ---- background -------------------------------------------------------------------------

struct Distractor {
    V3 p;          // world centre
    double r;
    cv::Vec3f col;
};

Scene build_scene(const Params &p, std::mt19937_64 &rng, std::vector<Distractor> *statics)
{
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    auto U = [&](double a, double b) { return a + (b - a) * u01(rng); };
    Scene sc;
    Camera &cam = sc.cam;
    cam.w = p.width;
    cam.hgt = p.height;
    cam.cx = 0.5 * p.width;
    cam.cy = 0.5 * p.height;
    cam.f = 0.5 * p.width / std::tan(0.5 * p.hfov_deg * kPi / 180.0);
    cam.pitch = p.pitch_deg * kPi / 180.0;
    if (std::isnan(p.cam_height_m)) {
        // the floor under the ball at floor_frac of the image height (level camera: exact)
        double beta = std::atan((p.floor_frac * p.height - cam.cy) / cam.f);
        cam.h_m = std::max(0.05, p.dist_m * std::tan(beta + cam.pitch));
        cam.h_m = std::min(cam.h_m, 1.6);
    } else {
        cam.h_m = p.cam_height_m;
    }
    sc.wall_z = p.dist_m + p.wall_gap_m;
    V3 lw{-0.35, 0.85, -0.4};  // light from above, left, behind the camera
    lw = (1.0 / norm(lw)) * lw;
    {
        double s = std::sin(cam.pitch), c = std::cos(cam.pitch);
        // world direction to camera coordinates (rotation only)
        sc.light = {lw.x, -lw.y * c - lw.z * s, -lw.y * s + lw.z * c};
    }
    uint64_t ts = p.seed * 31 + 7;
    // wall paint, posters, door frame
    cv::Vec3f wall_col = hsv_bgr(U(20, 50), U(0.05, 0.2), U(0.72, 0.86));
    if (u01(rng) < 0.3) wall_col = hsv_bgr(U(190, 230), U(0.05, 0.15), U(0.7, 0.85));
    cv::Vec3f floor_col = hsv_bgr(U(20, 35), U(0.35, 0.55), U(0.45, 0.65));
    double half_w = sc.wall_z * std::tan(0.5 * p.hfov_deg * kPi / 180.0);
    std::vector<Rect3> rects;
    for (int k = 0; k < 3; k++) {
        double w = U(0.3, 0.8), hh = U(0.3, 0.7);
        double x = U(-half_w, half_w), y = U(0.6, 1.8);
        double hue = U(0, 360);
        if (hue > 40 && hue < 170) hue += 140;  // posters stay out of the ball's and the distractors' hues
        rects.push_back({x, x + w, y, y + hh, hsv_bgr(hue, U(0.2, 0.7), U(0.3, 0.9))});
    }
    double door_x = U(-half_w, half_w);
    rects.push_back({door_x, door_x + 0.07, 0, 2.1, hsv_bgr(30, 0.1, 0.95)});
    rects.push_back({door_x + 0.9, door_x + 0.97, 0, 2.1, hsv_bgr(30, 0.1, 0.95)});
    double plank_w = U(0.12, 0.2);

    sc.bg.create(p.height, p.width, CV_32FC3);
    sc.floor_xz.create(p.height, p.width, CV_32FC2);
    for (int y = 0; y < p.height; y++) {
        cv::Vec3f *row = sc.bg.ptr<cv::Vec3f>(y);
        cv::Vec2f *fr = sc.floor_xz.ptr<cv::Vec2f>(y);
        for (int x = 0; x < p.width; x++) {
            V3 dc{(x - cam.cx) / cam.f, (y - cam.cy) / cam.f, 1.0};
            V3 dw = cam.dir_to_world(dc);
            cv::Vec3f col;
            fr[x] = cv::Vec2f(NAN, NAN);
            double tf = dw.y < 0 ? cam.h_m / -dw.y : 1e30;
            double fz = tf * dw.z;
            if (dw.y < 0 && fz < sc.wall_z) {
                double fx = tf * dw.x;
                fr[x] = cv::Vec2f(static_cast<float>(fx), static_cast<float>(fz));
                double plank = std::floor(fx / plank_w);
                double pv = hash2(static_cast<int64_t>(plank), 3, ts);
                double seam = std::fabs(fx / plank_w - plank - 0.5) > 0.48 ? 0.6 : 1.0;
                double grain = 0.85 + 0.3 * fbm(fx * 40.0, fz * 3.0 + plank * 13.0, ts + 11);
                col = floor_col * static_cast<float>((0.85 + 0.3 * pv) * grain * seam);
                // the corner where the floor meets the wall is darker
                double dz = sc.wall_z - fz;
                if (dz < 0.08) col *= static_cast<float>(0.55 + 0.45 * dz / 0.08);
            } else {
                double tw = sc.wall_z / std::max(dw.z, 1e-9);
                double wx = tw * dw.x, wy = cam.h_m + tw * dw.y;
                double tex = 0.88 + 0.16 * fbm(wx * 3.0, wy * 3.0, ts + 1) + 0.05 * fbm(wx * 60.0, wy * 60.0, ts + 2);
                col = wall_col * static_cast<float>(tex);
                if (wy < 0.09) col = hsv_bgr(30, 0.05, 0.93) * static_cast<float>(tex);  // skirting board
                for (const Rect3 &r : rects)
                    if (wx >= r.x0 && wx < r.x1 && wy >= r.y0 && wy < r.y1) {
                        double tx = fbm(wx * 8.0, wy * 8.0, ts + 5);
                        col = r.col * static_cast<float>(0.8 + 0.4 * tx);
                    }
                if (wy < 0.01) col *= 0.5f;
            }
            // lighting: brighter at the top left, vignetting
            double nx = (x - cam.cx) / cam.cx, ny = (y - cam.cy) / cam.cy;
            double light = (1.05 - 0.12 * ny - 0.08 * nx) * (1.0 - 0.18 * (nx * nx + ny * ny) / 2.0);
            row[x] = col * static_cast<float>(light);
        }
    }
    // static green distractors: a ball on the floor, a plant, a box (all behind the ball)
    if (p.distractors) {
        cv::Mat acc(p.height, p.width, CV_32FC4, cv::Scalar::all(0));
        // the image columns the ball sweeps (drifting at vx for the clip), with a margin
        double d_px = cam.f * p.diam_m / p.dist_m;
        double xa = p.x_m, xe = p.x_m + p.vx_m_s * p.duration_s;
        double col0 = cam.cx + cam.f * std::min(xa, xe) / p.dist_m - 2.0 * d_px;
        double col1 = cam.cx + cam.f * std::max(xa, xe) / p.dist_m + 2.0 * d_px;
        // draws x at depth z (fraction of the half width in [-lim, lim]) whose image
        // [x - half_m, x + half_m] keeps out of [col0, col1] when asked
        auto place = [&](double z, double lim, double half_m) {
            double hw = z * std::tan(0.5 * p.hfov_deg * kPi / 180.0), x = 0;
            for (int k = 0; k < 60; k++) {
                x = U(-lim, lim) * hw;
                double u0 = cam.cx + cam.f * (x - half_m) / z, u1 = cam.cx + cam.f * (x + half_m) / z;
                if (!p.distractor_clear || u1 < col0 || u0 > col1) break;
            }
            return x;
        };
        double zr = U(p.dist_m + 0.15, sc.wall_z - 0.1);
        double rr = U(0.03, 0.06);
        double xr = place(zr, 0.6, rr);
        Distractor gb{{xr, rr, zr}, rr, hsv_bgr(p.distractor_hue_deg, U(0.6, 0.85), U(0.6, 0.8))};
        statics->push_back(gb);
        splat_sphere(sc, {cam.to_cam(gb.p), gb.r, gb.col}, 0.001, 1.0, acc);
        composite(sc.bg, acc, cv::Rect(0, 0, p.width, p.height));
        // plant: leaves (ellipses) around a stem, standing on the floor near the wall
        double zp = sc.wall_z - 0.15, xp = place(zp, 0.7, 0.3);
        double u, v, u2, v2;
        if (cam.project({xp, 0.0, zp}, &u, &v) && cam.project({xp, 0.6, zp}, &u2, &v2)) {
            double pxm = (v - v2) / 0.6;
            cv::Scalar pot = cv::Scalar(40, 60, 110);
            cv::rectangle(sc.bg, cv::Point2d(u - 0.1 * pxm, v - 0.22 * pxm), cv::Point2d(u + 0.1 * pxm, v), pot, cv::FILLED,
                          cv::LINE_AA);
            for (int k = 0; k < 14; k++) {
                double ang = U(-160, -20) * kPi / 180.0, len = U(0.12, 0.25) * pxm;
                double hue = p.distractor_hue_deg + U(-12, 12);
                cv::Vec3f c = hsv_bgr(hue, U(0.5, 0.85), U(0.35, 0.7));
                cv::Point2d base(u, v - 0.2 * pxm - U(0, 0.3) * pxm);
                cv::ellipse(sc.bg, base + cv::Point2d(std::cos(ang), std::sin(ang)) * (0.5 * len),
                            cv::Size2d(0.5 * len, 0.14 * len), ang * 180.0 / kPi, 0, 360, cv::Scalar(c[0], c[1], c[2]),
                            cv::FILLED, cv::LINE_AA);
            }
        }
        // a green box on the floor against the wall
        double xb = place(sc.wall_z - 0.05, 0.7, 0.3) - 0.15;
        if (cam.project({xb, 0.0, sc.wall_z - 0.05}, &u, &v) && cam.project({xb + 0.3, 0.22, sc.wall_z - 0.05}, &u2, &v2)) {
            cv::Vec3f c = hsv_bgr(p.distractor_hue_deg - 10, 0.7, 0.55);
            cv::rectangle(sc.bg, cv::Point2d(u, v2), cv::Point2d(u2, v), cv::Scalar(c[0], c[1], c[2]), cv::FILLED,
                          cv::LINE_AA);
        }
    }
    return sc;
}

// ---- output -----------------------------------------------------------------------------

struct FrameTruth {
    int frame;
    double t_s;
    double u, v;          // exposure-mean centre of the ball's image (ellipse centre), px
    double minor_px, major_px;
    double z_cam_m;       // depth along the optical axis at the frame time
    double bottom_m;      // ball's bottom above the floor
    int in_frame;         // the whole ellipse (and its smear) inside the image
    int flight;           // index of the free flight the whole exposure lies in, -1 otherwise
};

std::string jnum(double v, int prec = 9)
{
    if (!std::isfinite(v)) return "null";
    char b[64];
    std::snprintf(b, sizeof b, "%.*g", prec, v);
    return b;
}

// least-squares quadratic y = a0 + a1 t + 0.5 acc t^2; returns acc
double fit_acc(const std::vector<double> &t, const std::vector<double> &y)
{
    size_t n = t.size();
    if (n < 4) return NAN;
    double tm = 0;
    for (double x : t) tm += x;
    tm /= static_cast<double>(n);
    double S[3][3] = {{0}}, b[3] = {0};
    for (size_t i = 0; i < n; i++) {
        double x = t[i] - tm, ph[3] = {1, x, x * x};
        for (int r = 0; r < 3; r++) {
            b[r] += ph[r] * y[i];
            for (int c = 0; c < 3; c++) S[r][c] += ph[r] * ph[c];
        }
    }
    cv::Matx33d A(S[0][0], S[0][1], S[0][2], S[1][0], S[1][1], S[1][2], S[2][0], S[2][1], S[2][2]);
    cv::Vec3d sol;
    if (!cv::solve(A, cv::Vec3d(b[0], b[1], b[2]), sol, cv::DECOMP_SVD)) return NAN;
    return 2.0 * sol[2];
}

int render(const Params &p_stored, const std::string &out)
{
    // non-square pixels: the scene is rendered with square ones, p.width of them,
    // and every frame resampled to the stored width
    Params p = p_stored;
    const int out_w = p_stored.width;
    p.width = static_cast<int>(std::lround(p_stored.width * p_stored.pixel_aspect));
    std::string base = out;
    if (base.size() > 4 && base.compare(base.size() - 4, 4, ".avi") == 0) base.resize(base.size() - 4);
    std::mt19937_64 rng(p.seed);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::vector<Distractor> statics;
    Scene sc = build_scene(p, rng, &statics);
    const Camera &cam = sc.cam;
    const double r = 0.5 * p.diam_m;
    const double frame_dt = 1.0 / p.fps, expo = p.exposure_frac * frame_dt;
    int nframes = static_cast<int>(std::floor(p.duration_s * p.fps));
    Trajectory tr = simulate(p, p.duration_s + frame_dt + 0.01);
    cv::Vec3f ball_col = hsv_bgr(p.hue_deg, p.sat, p.albedo);

    // flights: release -> first impact -> ... (times)
    std::vector<double> edges{p.release_s};
    for (double t : tr.bounce_t) edges.push_back(t);

    // the moving distractor: a green ball rolling slowly across, behind the dropped one
    bool moving = p.moving_distractor != 0;
    double mz = p.dist_m + std::min(0.5 * p.wall_gap_m, 0.4 + 0.3 * u01(rng));
    double mr = 0.03 + 0.02 * u01(rng);
    double mspeed = (u01(rng) < 0.5 ? -1 : 1) * (0.08 + 0.15 * u01(rng));
    double mhalf = mz * std::tan(0.5 * p.hfov_deg * kPi / 180.0);
    double mx0 = -mspeed / std::fabs(mspeed) * mhalf * (0.4 + 0.5 * u01(rng));
    cv::Vec3f mcol = hsv_bgr(p.distractor_hue_deg + 10, 0.75, 0.7);

    cv::VideoWriter wr;
    int fourcc = cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
    if (!wr.open(out, cv::CAP_OPENCV_MJPEG, fourcc, p.fps, cv::Size(out_w, p.height), true)) {
        std::fprintf(stderr, "render_ball: %s: cannot open for writing\n", out.c_str());
        return 3;
    }
    wr.set(cv::VIDEOWRITER_PROP_QUALITY, p.quality);

    cv::RNG nrng(static_cast<uint64_t>(p.seed) * 2654435761ULL + 1);
    cv::Mat acc(p.height, p.width, CV_32FC4, cv::Scalar::all(0));
    cv::Mat img, noise(p.height, p.width, CV_32FC3), u8;
    std::vector<FrameTruth> truth;
    for (int fi = 0; fi < nframes; fi++) {
        double t = fi * frame_dt;
        img = sc.bg.clone();
        V3 bc = traj_at(tr, t);
        // soft shadow of the ball on the floor, under the light from above
        if (p.shadow) {
            double hgt = bc.y - r;
            double sg = r * (0.7 + 0.8 * hgt), s0 = 0.5 / (1.0 + 3.0 * hgt);
            double uu[4], vv[4];
            bool ok = true;
            for (int k = 0; k < 4; k++)
                ok = ok && cam.project({bc.x + (k & 1 ? 3 : -3) * sg, 0, bc.z + (k & 2 ? 3 : -3) * sg}, &uu[k], &vv[k]);
            if (ok) {
                int x0 = std::max(0, static_cast<int>(*std::min_element(uu, uu + 4)));
                int x1 = std::min(p.width - 1, static_cast<int>(*std::max_element(uu, uu + 4)) + 1);
                int y0 = std::max(0, static_cast<int>(*std::min_element(vv, vv + 4)));
                int y1 = std::min(p.height - 1, static_cast<int>(*std::max_element(vv, vv + 4)) + 1);
                for (int y = y0; y <= y1; y++)
                    for (int x = x0; x <= x1; x++) {
                        cv::Vec2f fxz = sc.floor_xz.at<cv::Vec2f>(y, x);
                        if (std::isnan(fxz[0])) continue;
                        double dx = fxz[0] - bc.x, dz = fxz[1] - bc.z;
                        double k = 1.0 - s0 * std::exp(-(dx * dx + dz * dz) / (2 * sg * sg));
                        img.at<cv::Vec3f>(y, x) *= static_cast<float>(k);
                    }
            }
        }
        // sub-frames: enough that the ball moves at most ~0.4 px between two
        double ua, va, ub, vb;
        int nsub = 8;
        {
            double len = 0;
            V3 prev = traj_at(tr, t - 0.5 * expo);
            for (int k = 1; k <= 8; k++) {
                V3 cur = traj_at(tr, t - 0.5 * expo + expo * k / 8.0);
                if (cam.project(prev, &ua, &va) && cam.project(cur, &ub, &vb)) len += std::hypot(ub - ua, vb - va);
                prev = cur;
            }
            nsub = std::clamp(static_cast<int>(std::ceil(len / 0.4)), 8, 600);
        }
        cv::Rect dirty(0, 0, 0, 0);
        double su = 0, sv = 0;
        bool inside = true;
        auto mark = [&](double cu, double cv_, double reach) {
            cv::Rect rr(static_cast<int>(cu - reach), static_cast<int>(cv_ - reach), static_cast<int>(2 * reach + 2),
                        static_cast<int>(2 * reach + 2));
            rr &= cv::Rect(0, 0, p.width, p.height);
            dirty = dirty.area() ? (dirty | rr) : rr;
        };
        if (moving) {
            for (int k = 0; k < 4; k++) {
                double ts = t - 0.5 * expo + expo * (k + 0.5) / 4;
                V3 mp{mx0 + mspeed * ts, mr, mz};
                Sphere s{cam.to_cam(mp), mr, mcol};
                splat_sphere(sc, s, 0.001, 0.25, acc);
                Ellipse e = sphere_image(cam, s.pc, mr);
                mark(e.u, e.v, 0.5 * e.major_px + 4);
            }
        }
        for (int k = 0; k < nsub; k++) {
            double ts = t - 0.5 * expo + expo * (k + 0.5) / nsub;
            Sphere s{cam.to_cam(traj_at(tr, ts)), r, ball_col};
            splat_sphere(sc, s, p.fuzz_m, 1.0 / nsub, acc, p.ambient);
            Ellipse e = sphere_image(cam, s.pc, r);
            su += e.u / nsub;
            sv += e.v / nsub;
            double reach = 0.5 * e.major_px + 3;
            if (e.u - reach < 0 || e.v - reach < 0 || e.u + reach > p.width || e.v + reach > p.height) inside = false;
            mark(e.u, e.v, reach + 2);
        }
        if (dirty.area()) {
            if (fi == p.preview_frame && !moving) {  // the painter's coverage against the ellipse's area
                Ellipse ep = sphere_image(cam, cam.to_cam(traj_at(tr, t)), r);
                std::fprintf(stderr, "render_ball: frame %d: ball coverage %.1f px^2 (ellipse %.1f)\n", fi,
                             cv::sum(acc(dirty))[3], 0.25 * kPi * ep.minor_px * ep.major_px);
            }
            composite(img, acc, dirty);
            acc(dirty).setTo(cv::Scalar::all(0));
        }
        if (p.optics_sigma_px > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), p.optics_sigma_px);
        if (p.noise_sigma > 0) {
            nrng.fill(noise, cv::RNG::NORMAL, 0.0, p.noise_sigma);
            img += noise;
        }
        img.convertTo(u8, CV_8UC3);
        if (out_w != p.width) cv::resize(u8, u8, cv::Size(out_w, p.height), 0, 0, cv::INTER_AREA);
        wr.write(u8);
        if (fi == p.preview_frame) {
            std::vector<uchar> jpg;  // as the MJPG stream stores it
            cv::imencode(".jpg", u8, jpg, {cv::IMWRITE_JPEG_QUALITY, p.quality});
            cv::imwrite(base + ".preview.png", cv::imdecode(jpg, cv::IMREAD_COLOR));
        }

        Ellipse em = sphere_image(cam, cam.to_cam(bc), r);
        FrameTruth ft;
        ft.frame = fi;
        ft.t_s = t;
        ft.u = su;
        ft.v = sv;
        ft.minor_px = em.minor_px;
        ft.major_px = em.major_px;
        ft.z_cam_m = cam.to_cam(bc).z;
        ft.bottom_m = bc.y - r;
        ft.in_frame = inside ? 1 : 0;
        ft.flight = -1;
        for (size_t k = 0; k < edges.size(); k++) {
            double end = k + 1 < edges.size() ? edges[k + 1] : (std::isnan(tr.rest_t) ? 1e30 : -1e30);
            if (t - 0.5 * expo > edges[k] && t + 0.5 * expo < end) ft.flight = static_cast<int>(k);
        }
        truth.push_back(ft);
    }
    wr.release();

    // per-frame truth
    std::string csv = base + ".frames.csv";
    FILE *fc = std::fopen(csv.c_str(), "w");
    if (!fc) {
        std::fprintf(stderr, "render_ball: %s: cannot write\n", csv.c_str());
        return 3;
    }
    std::fprintf(fc, "frame,t_s,u_px,v_px,minor_px,major_px,z_cam_m,q_m_per_px,bottom_m,in_frame,flight\n");
    for (const FrameTruth &ft : truth)
        std::fprintf(fc, "%d,%.6f,%.4f,%.4f,%.4f,%.4f,%.6f,%.8g,%.5f,%d,%d\n", ft.frame, ft.t_s, ft.u, ft.v,
                     ft.minor_px, ft.major_px, ft.z_cam_m, ft.z_cam_m / cam.f, ft.bottom_m, ft.in_frame, ft.flight);
    std::fclose(fc);

    // per-flight truth: what a perfect detector would give (q from a parabola fitted
    // to the true centres, the true minor axis)
    std::string js = base + ".json";
    FILE *fj = std::fopen(js.c_str(), "w");
    if (!fj) {
        std::fprintf(stderr, "render_ball: %s: cannot write\n", js.c_str());
        return 3;
    }
    std::fprintf(fj, "{\n  \"clip\": \"%s\",\n", out.substr(out.find_last_of('/') + 1).c_str());
    std::fprintf(fj, "  \"diameter_m\": %s,\n", jnum(p.diam_m).c_str());
    std::fprintf(fj, "  \"pixel_aspect\": %s, \"vup_m_s\": %s,\n", jnum(p.pixel_aspect).c_str(), jnum(p.vup_m_s).c_str());
    std::fprintf(fj, "  \"width\": %d, \"height\": %d, \"fps\": %s, \"frames\": %d,\n", out_w, p.height,
                 jnum(p.fps).c_str(), nframes);
    std::fprintf(fj, "  \"exposure_s\": %s, \"exposure_frac\": %s,\n", jnum(expo).c_str(), jnum(p.exposure_frac).c_str());
    std::fprintf(fj, "  \"camera\": {\"f_px\": %s, \"hfov_deg\": %s, \"cx\": %s, \"cy\": %s, \"height_m\": %s, \"pitch_deg\": %s},\n",
                 jnum(cam.f).c_str(), jnum(p.hfov_deg).c_str(), jnum(cam.cx).c_str(), jnum(cam.cy).c_str(),
                 jnum(cam.h_m).c_str(), jnum(p.pitch_deg).c_str());
    std::fprintf(fj, "  \"distance_m\": %s, \"x_m\": %s, \"drop_m\": %s, \"release_s\": %s, \"v0_m_s\": [%s, 0, %s],\n",
                 jnum(p.dist_m).c_str(), jnum(p.x_m).c_str(), jnum(p.drop_m).c_str(), jnum(p.release_s).c_str(),
                 jnum(p.vx_m_s).c_str(), jnum(p.vz_m_s).c_str());
    std::fprintf(fj, "  \"q_release_m_per_px\": %s, \"diameter_px_release\": %s,\n",
                 jnum(cam.to_cam(traj_at(tr, 0)).z / cam.f).c_str(),
                 jnum(sphere_image(cam, cam.to_cam(traj_at(tr, 0)), r).minor_px).c_str());
    std::fprintf(fj, "  \"physics\": {\"drag\": %s, \"cd\": %s, \"rho_kg_m3\": %s, \"mass_kg\": %s, \"restitution\": %s, \"dt_s\": 0.0001},\n",
                 p.drag ? "true" : "false", jnum(p.cd).c_str(), jnum(p.rho_kg_m3).c_str(), jnum(p.mass_kg).c_str(),
                 jnum(p.restitution).c_str());
    std::fprintf(fj, "  \"render\": {\"noise_sigma\": %s, \"optics_sigma_px\": %s, \"mjpg_quality\": %d, \"hue_deg\": %s, \"sat\": %s, \"fuzz_m\": %s, \"distractor_hue_deg\": %s, \"moving_distractor\": %s, \"wall_gap_m\": %s, \"seed\": %llu},\n",
                 jnum(p.noise_sigma).c_str(), jnum(p.optics_sigma_px).c_str(), p.quality, jnum(p.hue_deg).c_str(),
                 jnum(p.sat).c_str(), jnum(p.fuzz_m).c_str(), jnum(p.distractor_hue_deg).c_str(),
                 p.moving_distractor ? "true" : "false", jnum(p.wall_gap_m).c_str(),
                 static_cast<unsigned long long>(p.seed));
    std::fprintf(fj, "  \"bounces_s\": [");
    for (size_t k = 0; k < tr.bounce_t.size(); k++) std::fprintf(fj, "%s%.5f", k ? ", " : "", tr.bounce_t[k]);
    std::fprintf(fj, "],\n  \"rest_s\": %s,\n  \"flights\": [\n", jnum(tr.rest_t).c_str());
    bool first = true;
    for (size_t k = 0; k < edges.size(); k++) {
        std::vector<double> tt, uu, vv, qq, dd;
        for (const FrameTruth &ft : truth)
            if (ft.flight == static_cast<int>(k) && ft.in_frame) {
                tt.push_back(ft.t_s);
                uu.push_back(ft.u);
                vv.push_back(ft.v);
                qq.push_back(ft.z_cam_m / cam.f);
                dd.push_back(ft.minor_px);
            }
        if (tt.size() < 5) continue;
        double t_end = k + 1 < edges.size() ? edges[k + 1] : NAN;
        double au = fit_acc(tt, uu), av = fit_acc(tt, vv);
        double a = std::hypot(au, av);
        double qm = 0, dm = 0;
        for (size_t i = 0; i < tt.size(); i++) { qm += qq[i]; dm += dd[i]; }
        qm /= static_cast<double>(tt.size());
        dm /= static_cast<double>(tt.size());
        double apex = 0;
        for (double x = edges[k]; x < (std::isnan(t_end) ? p.duration_s : t_end); x += 1e-3)
            apex = std::max(apex, traj_at(tr, x).y - r);
        std::fprintf(fj, "%s    {\"index\": %zu, \"kind\": \"%s\", \"t_start_s\": %.5f, \"t_end_s\": %s, \"apex_bottom_m\": %.4f, \"n_frames\": %zu, \"t_first_s\": %.5f, \"t_last_s\": %.5f, \"q_true_m_per_px\": %s, \"diameter_px_true\": %s, \"a_px_s2_fit_true\": %s, \"q_fit_true_m_per_px\": %s, \"diameter_ideal_m\": %s}",
                     first ? "" : ",\n", k, k == 0 ? "drop" : "bounce", edges[k], jnum(t_end, 7).c_str(), apex,
                     tt.size(), tt.front(), tt.back(), jnum(qm).c_str(), jnum(dm).c_str(), jnum(a).c_str(),
                     jnum(kG / a).c_str(), jnum(dm * kG / a).c_str());
        first = false;
    }
    std::fprintf(fj, "\n  ]\n}\n");
    if (std::fclose(fj) != 0) return 3;
    return 0;
}

void help()
{
    std::printf(
        "usage: render_ball --out CLIP.avi [--KEY VALUE ...]\n"
        "       render_ball --set N --seed S --outdir DIR [--index I] [--KEY VALUE ...]\n\n"
        "Renders a tennis ball dropped in front of a static camera (MJPG .avi) with its\n"
        "truth (CLIP.json, CLIP.frames.csv). In set mode clip i is DIR/clip_II.avi and its\n"
        "parameters are drawn from the seed; keys given override them. Keys (default):\n");
    Params d;
    for (const Key &k : kKeys) {
        double v = k.d ? d.*(k.d) : d.*(k.i);
        std::printf("  --%-20s %g   [%g, %g]\n", k.name, v, k.lo, k.hi);
    }
    std::printf("  --seed                 scene/noise seed (set mode: the set's seed)\n");
}

}  // namespace

int main(int argc, char **argv)
{
    std::string out, outdir;
    int set_n = 0, index = -1;
    uint64_t seed = 1;
    bool seed_given = false;
    std::vector<std::pair<const Key *, double>> overrides;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "--help" || a == "-h") {
            help();
            return 0;
        }
        if (a.rfind("--", 0) != 0) usage_error("unexpected argument '" + a + "'");
        if (i + 1 >= argc) usage_error(a + ": missing value");
        const char *val = argv[++i];
        double v;
        if (a == "--out") { out = val; continue; }
        if (a == "--outdir") { outdir = val; continue; }
        if (!parse_double(val, &v)) usage_error(a + ": '" + val + "' is not a number");
        if (a == "--set") {
            if (v < 1 || v > 10000 || v != std::floor(v)) usage_error("--set: a whole number 1-10000");
            set_n = static_cast<int>(v);
        } else if (a == "--index") {
            if (v < 0 || v != std::floor(v)) usage_error("--index: a whole number >= 0");
            index = static_cast<int>(v);
        } else if (a == "--seed") {
            if (v < 0 || v != std::floor(v) || v > 1e15) usage_error("--seed: a whole number >= 0");
            seed = static_cast<uint64_t>(v);
            seed_given = true;
        } else {
            const Key *k = find_key(a.c_str() + 2);
            if (!k) usage_error("unknown option " + a);
            overrides.push_back({k, v});
        }
    }
    if (set_n > 0) {
        if (outdir.empty()) usage_error("--set needs --outdir");
        if (index >= set_n) usage_error("--index beyond the set");
        for (int i = 0; i < set_n; i++) {
            if (index >= 0 && i != index) continue;
            Params p = draw_set_clip(seed, set_n, i);
            for (auto &o : overrides) apply(p, *o.first, o.second);
            char name[64];
            std::snprintf(name, sizeof name, "/clip_%02d.avi", i);
            int rc = render(p, outdir + name);
            if (rc) return rc;
        }
        return 0;
    }
    if (out.empty()) usage_error("--out CLIP.avi (or --set N --outdir DIR) is required");
    Params p;
    if (seed_given) p.seed = seed;
    for (auto &o : overrides) apply(p, *o.first, o.second);
    return render(p, out);
}
