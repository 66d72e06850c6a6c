// pose_csv.cpp - BlazePose keypoints of a video as the replay CSV (BlazePose-33:
// t,x0,y0,c0,...,x32,y32,c32), so that `gravscale replay --keypoints` runs the
// core on them; a stop-gap until `gravscale video --detector pose` exists.
//
//   pose_csv VIDEO [--models DIR] [--model lite|full|heavy] [--fps N] [--roi-smoothing]
//
// Times come from the frame source (stream times, repaired; --fps for slow
// motion saved at a false rate). A frame without a pose is an absent row.
// Per-frame extras go to stderr with --verbose: detector runs, presence, ms.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "frame_source.hpp"
#include "pose_blazepose.hpp"

namespace {

int usage()
{
    std::fprintf(stderr, "usage: pose_csv VIDEO [--models DIR] [--model lite|full|heavy] [--fps N] "
                         "[--roi-smoothing] [--verbose]\n");
    return 2;
}

}  // namespace

int main(int argc, char **argv)
{
    std::string path;
    gs::PoseConfig cfg;
    gs::FrameSourceOptions opt;
    bool verbose = false;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "--models" && i + 1 < argc) cfg.models_dir = argv[++i];
        else if (a == "--model" && i + 1 < argc) {
            std::string v = argv[++i];
            char msg[96];
            if (gs::pose_config_set(&cfg, "model", 5, v.data(), v.size(), msg, sizeof msg) != GS_OK) {
                std::fprintf(stderr, "pose_csv: --model: %s\n", msg);
                return 2;
            }
        } else if (a == "--fps" && i + 1 < argc) {
            opt.fps = std::atof(argv[++i]);
            if (!(opt.fps > 0.0)) return usage();
        } else if (a == "--roi-smoothing") cfg.roi_smoothing = true;
        else if (a == "--verbose") verbose = true;
        else if (!a.empty() && a[0] != '-' && path.empty()) path = a;
        else return usage();
    }
    if (path.empty()) return usage();

    gs::PoseTracker tracker(cfg);
    if (!tracker.ok()) {
        std::fprintf(stderr, "pose_csv: %s\n", tracker.error().c_str());
        return 2;
    }
    std::string err;
    gs::FrameSource::Error kind;
    std::unique_ptr<gs::FrameSource> src = gs::FrameSource::open(path, opt, err, kind);
    if (!src) {
        std::fprintf(stderr, "pose_csv: %s: %s\n", path.c_str(), err.c_str());
        return 1;
    }
    std::printf("t");
    for (int k = 0; k < gs::kPoseKeypoints; k++) std::printf(",x%d,y%d,c%d", k, k, k);
    std::printf("\n");
    gs::Frame f;
    gs::PoseOutput o;
    while (src->next(f)) {
        tracker.process(f.bgr, f.t_s, &o);
        if (verbose)
            std::fprintf(stderr, "frame %lld t %.4f present %d detector %d presence %.3f det %.1f ms lm %.1f ms\n",
                         static_cast<long long>(f.index), f.t_s, o.present, o.detector_ran, o.presence, o.det_ms,
                         o.lm_ms);
        if (!o.present) continue;
        std::printf("%.6f", f.t_s);
        for (int k = 0; k < gs::kPoseKeypoints; k++)
            std::printf(",%.2f,%.2f,%.4f", o.kp[k].x_px, o.kp[k].y_px, o.kp[k].c);
        std::printf("\n");
    }
    if (!src->error().empty()) {
        std::fprintf(stderr, "pose_csv: %s: %s\n", path.c_str(), src->error().c_str());
        return 1;
    }
    return 0;
}
