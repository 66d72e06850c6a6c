// bench_video.cpp - throughput of the whole video pipeline (decode -> ball
// detector -> core) and the share of each stage, on one core by default.
//
//   bench_video [FILE] [--fps N] [--frames N] [--codec avc1|mjpg|ffv1] [--hue DEG] [--all-cores]
//   bench_video --render-only OUT [--frames N] [--codec C]
//
// --hue DEG gives the detector the ball's colour ([ball] color = fixed); the
// rendered clip's ball has hue 30 and is given so by default (the detector's
// colour learning wants a faster throw than the rendered one); --hue -1 leaves
// the colour to be learned.
// Without FILE it renders a 1080p clip at 60 fps (10 s, a 22 cm ball thrown
// five times at 4 mm/px, H.264 when this FFmpeg can write it) into a temporary
// folder first. By default the process is pinned to one CPU (decoder threads
// included) and OpenCV runs single-threaded: the figure to compare with real
// time. Prints frames/s, the real-time factor against the clip's rate, and the
// time per frame of decode, detection and core. --render-only writes the clip to
// OUT and stops, so that runs can time the same clip without its encode.
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "ball_detector.hpp"
#include "frame_source.hpp"

extern "C" {
#include "gravscale/gravscale.h"
}

namespace {

double now_s()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double cpu_s()
{
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

void draw_disc(cv::Mat &img, double cx, double cy, double r, cv::Vec3b color)
{
    const int ss = 8;
    int x0 = std::max(0, static_cast<int>(cx - r - 1)), x1 = std::min(img.cols - 1, static_cast<int>(cx + r + 2));
    int y0 = std::max(0, static_cast<int>(cy - r - 1)), y1 = std::min(img.rows - 1, static_cast<int>(cy + r + 2));
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            int in = 0;
            for (int j = 0; j < ss; j++)
                for (int i = 0; i < ss; i++) {
                    double px = x + (i + 0.5) / ss - 0.5 - cx, py = y + (j + 0.5) / ss - 0.5 - cy;
                    in += px * px + py * py <= r * r;
                }
            if (!in) continue;
            double a = in / double(ss * ss);
            cv::Vec3b &p = img.at<cv::Vec3b>(y, x);
            for (int c = 0; c < 3; c++) p[c] = cv::saturate_cast<uchar>(a * color[c] + (1 - a) * p[c]);
        }
}

// 1080p, 60 fps: a textured wall, a ball resting and thrown five times
bool render(const std::string &path, const std::string &codec, int n_frames)
{
    const int W = 1920, H = 1080;
    const double fps = 60, q = 0.004, a = 9.81 / q, d = 0.22 / q, flight = 0.9, rest = 1.0;
    int fcc = codec == "mjpg" ? cv::VideoWriter::fourcc('M', 'J', 'P', 'G')
              : codec == "ffv1" ? cv::VideoWriter::fourcc('F', 'F', 'V', '1')
                                : cv::VideoWriter::fourcc('a', 'v', 'c', '1');
    cv::VideoWriter w(path, cv::CAP_FFMPEG, fcc, fps, cv::Size(W, H), true);
    if (!w.isOpened()) return false;
    cv::Mat bg(H, W, CV_8UC3);
    cv::RNG rng(7);
    rng.fill(bg, cv::RNG::NORMAL, cv::Scalar(120, 125, 130), cv::Scalar(12, 12, 12));
    for (int i = 0; i < n_frames; i++) {
        double t = i / fps, cycle = rest + flight;
        int k = static_cast<int>(t / cycle);
        double tc = t - k * cycle, x = 500 + 150.0 * k, y = 900;
        if (tc > rest && k < 5) {
            double tf = tc - rest;
            y = 900 - 0.5 * a * flight * tf + 0.5 * a * tf * tf;
            x += 150.0 * tf / flight;
        }
        cv::Mat f = bg.clone();
        draw_disc(f, x, y, 0.5 * d, cv::Vec3b(0, 130, 255));
        w.write(f);
    }
    return true;
}

void on_event(void *ctx, const gs_event *ev)
{
    if (ev->type == GS_EV_JUMP && ev->u.jump.accepted) ++*static_cast<int *>(ctx);
}

}  // namespace

int main(int argc, char **argv)
{
    std::string file, codec = "avc1";
    double fps = 0;
    int frames = 600;
    bool all_cores = false;
    std::string render_only;
    double hue = -2;  // -2: 30 for the rendered clip, learned for a FILE
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "--fps" && i + 1 < argc) fps = std::atof(argv[++i]);
        else if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
        else if (a == "--codec" && i + 1 < argc) codec = argv[++i];
        else if (a == "--all-cores") all_cores = true;
        else if (a == "--render-only" && i + 1 < argc) render_only = argv[++i];
        else if (a == "--hue" && i + 1 < argc) hue = std::atof(argv[++i]);
        else if (a[0] != '-') file = a;
        else {
            std::fprintf(stderr, "usage: bench_video [FILE] [--fps N] [--frames N] [--codec avc1|mjpg|ffv1] [--hue DEG] [--all-cores] | --render-only OUT\n");
            return 2;
        }
    }
    if (!render_only.empty()) {
        if (!render(render_only, codec, frames)) {
            std::fprintf(stderr, "bench_video: cannot write %s\n", render_only.c_str());
            return 1;
        }
        return 0;
    }
    std::string dir;
    if (hue == -2) hue = file.empty() ? 30 : -1;
    if (file.empty()) {
        char templ[] = "/tmp/gs_bench_video_XXXXXX";
        if (!mkdtemp(templ)) return 1;
        dir = templ;
        file = dir + "/clip_1080p60." + (codec == "avc1" ? "mp4" : "avi");
        double t0 = now_s();
        if (!render(file, codec, frames) && (codec = "mjpg", file = dir + "/clip_1080p60.avi", !render(file, codec, frames))) {
            std::fprintf(stderr, "bench_video: cannot write a clip\n");
            return 1;
        }
        std::printf("rendered %d frames 1920x1080 60 fps (%s) in %.1f s: %s\n", frames, codec.c_str(), now_s() - t0,
                    file.c_str());
    }
    if (!all_cores) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(sched_getcpu() >= 0 ? sched_getcpu() : 0, &set);
        if (sched_setaffinity(0, sizeof set, &set) != 0) std::perror("sched_setaffinity");
        cv::setNumThreads(1);
    }
    cpu_set_t cur;
    CPU_ZERO(&cur);
    sched_getaffinity(0, sizeof cur, &cur);

    gs::FrameSourceOptions fo;
    fo.fps = fps;
    std::string err;
    gs::FrameSource::Error kind;
    auto src = gs::FrameSource::open(file, fo, err, kind);
    if (!src) {
        std::fprintf(stderr, "bench_video: %s: %s\n", file.c_str(), err.c_str());
        return 1;
    }
    gs_core_config cfg;
    gs_core_config_default(&cfg);
    cfg.size_min_m = 0.02f;
    cfg.size_max_m = 0.5f;
    std::vector<std::vector<double>> stores;
    std::vector<gs_pipeline> pipes(8);
    int accepted = 0;
    for (auto &p : pipes) {
        stores.emplace_back(gs_pipeline_storage_bytes(&cfg) / sizeof(double) + 1);
        gs_pipeline_init(&p, &cfg, GS_LAYOUT_POINT, stores.back().data(), stores.back().size() * sizeof(double),
                         on_event, &accepted);
    }
    gs::BallConfig bc;
    if (hue >= 0) {
        bc.color_auto = false;
        bc.hue_deg = hue;
    }
    gs::BallDetector det(bc);
    std::vector<gs::BallObs> obs;
    gs::Frame f;
    double t_dec = 0, t_det = 0, t_core = 0, w0 = now_s(), c0 = cpu_s();
    int64_t n = 0, n_obs = 0;
    for (;;) {
        double a = now_s();
        bool ok = src->next(f);
        double b = now_s();
        t_dec += b - a;
        if (!ok) break;
        det.process(f.bgr, f.t_s, obs);
        double c = now_s();
        t_det += c - b;
        for (const auto &o : obs)
            if (o.track >= 0 && o.track < 8) {
                gs_pipeline_push_point(&pipes[o.track], f.t_s, float(o.x_px), float(o.y_px), float(o.confidence),
                                       float(o.diameter_px));
                n_obs++;
            }
        t_core += now_s() - c;
        n++;
    }
    double c = now_s();
    for (auto &p : pipes) gs_pipeline_flush(&p);
    t_core += now_s() - c;
    double wall = now_s() - w0, cpu = cpu_s() - c0;
    double clip_fps = src->fps();
    std::printf("%s: %lldx%d x %lld frames at %.2f fps (%s), %d CPU(s) allowed%s\n", file.c_str(),
                (long long)src->size().width, src->size().height, (long long)n, clip_fps, src->fps_origin(),
                CPU_COUNT(&cur), all_cores ? "" : ", OpenCV single-threaded");
    std::printf("whole pipeline: %.1f frames/s wall (%.2f x real time), %.1f frames/s per CPU second\n", n / wall,
                n / wall / clip_fps, n / cpu);
    double tot = t_dec + t_det + t_core;
    std::printf("per frame: decode %.2f ms (%.0f %%), detect %.2f ms (%.0f %%), core %.4f ms (%.2f %%)\n",
                1e3 * t_dec / n, 100 * t_dec / tot, 1e3 * t_det / n, 100 * t_det / tot, 1e3 * t_core / n,
                100 * t_core / tot);
    std::printf("ball colour %s; detections %lld, accepted flights %d, times repaired %lld\n",
                hue >= 0 ? "given" : "learned", (long long)n_obs, accepted, (long long)src->times_repaired());
    if (!dir.empty()) {
        std::remove(file.c_str());
        rmdir(dir.c_str());
    }
    return 0;
}
