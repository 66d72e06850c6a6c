// bench_pose.cpp - speed of the BlazePose front end with OpenCV's DNN: ms per
// frame of the detector and of the landmark network (lite, full, heavy), on 1
// and 2 threads, on 720p and 1080p frames, and the tracker's frames/s with
// ROI tracking (the detector runs only when tracking is lost).
//
//   bench_pose [CLIP] [--models DIR] [--frames N] [--model lite|full|heavy|all]
//              [--threads 1|2|both] [--res 720|1080|both]
//
// CLIP defaults to $GS_SHARED_DIR (else ../shared) /data/real/jumpvision_jumps/
// cmj_gym_handheld_30fps.mp4 (720 x 1280 portrait, 30 fps, 54 frames). Its frames are decoded once into memory; the
// 1080p frames are the same frames scaled to 1080 x 1920 (the cost of a larger
// frame: letterbox and crop; the networks' inputs stay 224 and 256). Decoding
// is not timed. Times are wall-clock per call, pre- and post-processing
// included. Other processes share the cores here, so the load average is
// printed and each figure also as CPU time of this process per call (all
// threads): with 1 thread, about what the call takes on an idle core.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "bench_args.hpp"
#include "pose_blazepose.hpp"

namespace {

double cpu_ms()  // this process's CPU time, all threads: less sensitive to other load than wall time
{
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double now_ms()
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Stats {
    double mean = 0.0, median = 0.0, p90 = 0.0;
};

Stats stats(std::vector<double> v)
{
    Stats s;
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    double sum = 0.0;
    for (double x : v) sum += x;
    s.mean = sum / v.size();
    s.median = v[v.size() / 2];
    s.p90 = v[std::min(v.size() - 1, static_cast<size_t>(std::ceil(0.9 * v.size())) - 1)];
    return s;
}

int usage()
{
    std::fprintf(stderr,
                 "usage: bench_pose [CLIP] [--models DIR] [--frames N (0: all)] [--model lite|full|heavy|all|lite,full]\n"
                 "                  [--threads 1|2|both] [--res 720|1080|both]\n");
    return 2;
}

}  // namespace

int main(int argc, char **argv)
{
    std::string clip = gs_bench::gym_clip();
    std::string models_dir, model_arg = "all", threads_arg = "both", res_arg = "both", frames_arg = "0";
    if (!gs_bench::parse_options(argc, argv,
                                 {{"--models", &models_dir}, {"--model", &model_arg}, {"--threads", &threads_arg},
                                  {"--res", &res_arg}, {"--frames", &frames_arg}},
                                 &clip))
        return usage();
    int max_frames = 0;  // 0: the whole clip
    std::vector<std::string> model_names;
    std::vector<int> threads, heights;
    if (!gs_bench::to_int(frames_arg, 0, max_frames) ||
        !gs_bench::pick(model_arg, "all", {"lite", "full", "heavy"}, model_names) ||
        !gs_bench::pick_ints(threads_arg, "both", {"1", "2"}, threads) ||
        !gs_bench::pick_ints(res_arg, "both", {"720", "1080"}, heights))
        return usage();
    std::vector<gs::PoseModel> models;
    for (const std::string &m : model_names)
        models.push_back(m == "lite" ? gs::PoseModel::lite : m == "full" ? gs::PoseModel::full : gs::PoseModel::heavy);

    cv::VideoCapture cap(clip);
    if (!cap.isOpened()) {
        std::fprintf(stderr, "bench_pose: %s: cannot open\n", clip.c_str());
        return 1;
    }
    std::vector<cv::Mat> frames;
    cv::Mat f;
    while (cap.read(f) && (max_frames == 0 || static_cast<int>(frames.size()) < max_frames)) frames.push_back(f.clone());
    if (frames.empty()) {
        std::fprintf(stderr, "bench_pose: %s: no frames\n", clip.c_str());
        return 1;
    }
    const int w0 = frames[0].cols, h0 = frames[0].rows;
    double load[3] = {0, 0, 0};
    if (FILE *lf = std::fopen("/proc/loadavg", "r")) {
        if (std::fscanf(lf, "%lf %lf %lf", &load[0], &load[1], &load[2]) != 3) load[0] = NAN;
        std::fclose(lf);
    }
    std::printf("clip %s: %zu frames %dx%d; OpenCV %s; load average %.2f\n", clip.c_str(), frames.size(), w0, h0,
                CV_VERSION, load[0]);
    std::printf("%-6s %3s %9s | %-27s | %-27s | %s\n", "model", "thr", "frame", "detector ms mean/med/p90/cpu",
                "landmark ms mean/med/p90/cpu", "tracker ms/frame wall, cpu;  fps;  detector runs");

    for (int height : heights) {
        // the short side is 720 or 1080 ("720p", "1080p"), portrait or landscape as the clip
        double s = static_cast<double>(height) / std::min(w0, h0);
        std::vector<cv::Mat> in;
        for (const cv::Mat &fr : frames) {
            if (std::fabs(s - 1.0) < 1e-9) in.push_back(fr);
            else {
                cv::Mat r;
                cv::resize(fr, r, cv::Size(), s, s, cv::INTER_LINEAR);
                in.push_back(r);
            }
        }
        char res[32];
        std::snprintf(res, sizeof res, "%dx%d", in[0].cols, in[0].rows);
        for (gs::PoseModel m : models) {
            for (int th : threads) {
                gs::PoseConfig cfg;
                cfg.models_dir = models_dir;
                cfg.model = m;
                cfg.threads = th;
                gs::PoseTracker t(cfg);
                if (!t.ok()) {
                    std::fprintf(stderr, "bench_pose: %s\n", t.error().c_str());
                    return 1;
                }
                cv::setNumThreads(th);
                gs::PoseOutput o;
                // warm-up (first calls allocate)
                t.process(in[0], 0.0, &o);
                t.reset();

                // 1. every frame through the detector and the landmarks of its ROI
                std::vector<double> det, lm;
                double det_cpu = 0.0, lm_cpu = 0.0;
                for (size_t i = 0; i < in.size(); i++) {
                    double t0 = now_ms(), c0 = cpu_ms();
                    std::vector<gs::PoseDetection> d = t.detect(in[i]);
                    det.push_back(now_ms() - t0);
                    det_cpu += cpu_ms() - c0;
                    if (d.empty()) continue;
                    gs::PoseRoi roi = gs::pose_roi_from_alignment(d[0].kp_x[0], d[0].kp_y[0], d[0].kp_x[1], d[0].kp_y[1]);
                    t0 = now_ms();
                    c0 = cpu_ms();
                    t.landmarks(in[i], roi, &o, nullptr);
                    lm.push_back(now_ms() - t0);
                    lm_cpu += cpu_ms() - c0;
                }
                // 2. the tracker as used: detector only when tracking is lost
                t.reset();
                int n_det = 0, n_present = 0;
                double t0 = now_ms(), c0 = cpu_ms();
                for (size_t i = 0; i < in.size(); i++) {
                    t.process(in[i], i / 30.0, &o);
                    n_det += o.detector_ran;
                    n_present += o.present;
                }
                double per = (now_ms() - t0) / in.size(), cpu = (cpu_ms() - c0) / in.size();
                Stats sd = stats(det), sl = stats(lm);
                std::printf("%-6s %3d %9s | %6.1f %6.1f %6.1f %6.1f | %6.1f %6.1f %6.1f %6.1f | %6.1f %6.1f  %5.1f  %d of %zu (pose in %d)\n",
                            gs::pose_model_name(m), th, res, sd.mean, sd.median, sd.p90, det_cpu / det.size(),
                            sl.mean, sl.median, sl.p90, lm.empty() ? 0.0 : lm_cpu / lm.size(), per, cpu, 1000.0 / per,
                            n_det, in.size(), n_present);
                std::fflush(stdout);
            }
        }
    }
    return 0;
}
