// cmd_video.cpp - `gravscale video`: frames (video file or image sequence) ->
// ball detector -> one core pipeline per tracked ball -> JSON Lines / NMEA on
// stdout, the same events as `gravscale replay`; optional trace, overlay
// (video or contact sheet) and plot.
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "camera_motion.hpp"
#include "frame_source.hpp"
#include "overlay.hpp"
#include "pose_blazepose.hpp"
#include "prefetch.hpp"
#include "scene_watch.hpp"
#include "stage_clock.hpp"

#if __has_include("ball_detector.hpp")
#include "ball_detector.hpp"
#include "ball_flights.hpp"
#define GS_HAVE_BALL_DETECTOR 1
#else
#define GS_HAVE_BALL_DETECTOR 0
#endif

extern "C" {
#include "gravscale/gravscale.h"
#include "app_common.h"
#include "gs_out.h"
#include "gs_profile.h"
}

extern "C" int gs_cmd_video(int argc, char **argv);

namespace {

enum { EXIT_OK = GS_EXIT_OK, EXIT_DATA = GS_EXIT_DATA, EXIT_USAGE = GS_EXIT_USAGE, EXIT_IO = GS_EXIT_IO };
constexpr size_t kTraceBufBytes = 1u << 16;

const char kHelp[] =
    "usage: gravscale video FILE [OPTIONS]\n"
    "\n"
    "Detect a ball or a person in a video (any container FFmpeg reads) or an image\n"
    "sequence, follow the free flights and print every flight, the running size and\n"
    "a final summary as JSON Lines (or NMEA sentences), as `gravscale replay` does.\n"
    "For a ball, height_m is its diameter; for a person, the stature.\n"
    "\n"
    "  FILE                 a video file, a folder of images (in name order) or a\n"
    "                       printf pattern such as frames/%05d.png\n"
    "  --detector D         ball (the default) or pose (BlazePose keypoints, one\n"
    "                       person: visits, jumps, stature; warnings when the camera\n"
    "                       moves, the body leaves the frame or moves in depth)\n"
    "  --model M            pose network: lite (default), full or heavy\n"
    "  --models DIR         folder of the converted pose networks (default: models/\n"
    "                       of the source tree, made by tools/fetch_models.sh)\n"
    "  --engine E           pose: the networks' inference engine, openvino (the\n"
    "                       default when built in and its models are there) or\n"
    "                       opencv (OpenCV's DNN, the fallback)\n"
    "  --threads N          threads of the pose networks and of OpenCV (default: half\n"
    "                       the CPUs allowed with --prefetch, else all of them)\n"
    "  --prefetch N         pose: decode and run the networks up to N frames ahead\n"
    "                       of the rest, in two more threads (default 8; 0: all in\n"
    "                       one thread); the output is the same\n"
    "  --stabilize on|off   pose: map keypoints into the first frame's view using the\n"
    "                       background's motion (default on; flights still carry\n"
    "                       camera_moved when the camera moved)\n"
    "  --fps N              the true frame rate: stream times are rescaled to N\n"
    "                       frames per second of real time (slow-motion clips stored\n"
    "                       at a false rate); required for an image sequence.\n"
    "                       Default: the capture rate a phone stored in the\n"
    "                       metadata (com.android.capture.fps), else the stream's\n"
    "  --config FILE        key = value configuration, sections [core], [ball], [pose]\n"
    "  --output-format F    json | nmea (default: json, or [core] format)\n"
    "  --trace FILE         also write every event, trace events included, as JSON\n"
    "                       Lines to FILE\n"
    "  --overlay OUT        draw detections, flight windows, fitted parabolas and\n"
    "                       numbers on the frames: a video (.avi, .mp4, .mov, .mkv)\n"
    "                       or a contact sheet of the key frames (.png, .jpg)\n"
    "  --plot OUT.png       the ball's centre against time with the fits\n"
    "  --help               this text\n"
    "\n"
    "A wrong frame rate scales the acceleration by its square: the start event\n"
    "says which rate was used (fps_source) and where it came from (fps_origin:\n"
    "cli, metadata, container or timestamps).\n"
    "\n"
    "Exit codes: 0 ok, 1 bad input (missing, empty or unreadable file), 2 usage or\n"
    "config error, 3 I/O error writing output.\n";

struct Options {
    std::string input, config, trace, overlay, plot, detector = "ball";
    std::string model, models, engine;
    int threads = -1;              // -1: from the config
    int prefetch = 8;              // pose: frames decoded and posed ahead (0: one thread); 8 keeps both CPUs busy through census frames
    bool stabilize = true;
    double fps = 0.0;
    bool out_format_set = false;
    gs_format out_format = GS_FMT_JSON;
};

int usage_error(const std::string &msg) { return gs_app_usage_error("video", "%s", msg.c_str()); }

// -1 to go on, else an exit code
int parse_args(int argc, char **argv, Options &o)
{
    static const char *const known[] = {"--detector", "--fps",     "--config", "--output-format", "--trace",
                                        "--overlay",  "--plot",    "--model",  "--models",        "--threads",
                                        "--stabilize", "--prefetch", "--engine"};
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "--help" || a == "-h") {
            std::fputs(kHelp, stdout);
            return std::fflush(stdout) == 0 ? EXIT_OK : EXIT_IO;
        }
        if (a.compare(0, 2, "--") != 0 || a == "--") {
            if (!o.input.empty()) return usage_error("unexpected argument '" + a + "' (one FILE only)");
            o.input = a;
            continue;
        }
        char name_buf[32];
        const char *val_c;
        int rc = gs_app_option("video", argc, argv, &i, known, sizeof known / sizeof known[0], name_buf,
                               sizeof name_buf, &val_c);
        if (rc >= 0) return rc;
        const std::string name = name_buf, val = val_c;
        if (name == "--detector") {
            if (val != "ball" && val != "pose") return usage_error("--detector must be ball or pose, not '" + val + "'");
            o.detector = val;
        } else if (name == "--model") {
            if (val != "lite" && val != "full" && val != "heavy")
                return usage_error("--model must be lite, full or heavy, not '" + val + "'");
            o.model = val;
        } else if (name == "--models") {
            o.models = val;
        } else if (name == "--engine") {
            gs::PoseEngine e;
            if (!gs::pose_engine_from_name(val, &e)) return usage_error("--engine must be auto, opencv or openvino, not '" + val + "'");
            if (!gs::pose_engine_built(e))
                return usage_error("--engine openvino: this build has no OpenVINO (tools/fetch_engine.sh installs it)");
            o.engine = val;
        } else if (name == "--threads") {
            double t;
            if (!gs_num_parse(val.c_str(), val.size(), &t) || t != std::floor(t) || t < 0 || t > 64)
                return usage_error("--threads must be a whole number 0..64, not '" + val + "'");
            o.threads = static_cast<int>(t);
        } else if (name == "--prefetch") {
            double t;
            if (!gs_num_parse(val.c_str(), val.size(), &t) || t != std::floor(t) || t < 0 || t > 64)
                return usage_error("--prefetch must be a whole number 0..64, not '" + val + "'");
            o.prefetch = static_cast<int>(t);
        } else if (name == "--stabilize") {
            if (val != "on" && val != "off") return usage_error("--stabilize must be on or off, not '" + val + "'");
            o.stabilize = val == "on";
        } else if (name == "--fps") {
            double f;
            if (!gs_num_parse(val.c_str(), val.size(), &f) || !(f > 0.0) || !(f <= 100000.0))
                return usage_error("--fps must be a positive number of frames per second, not '" + val + "'");
            o.fps = f;
        } else if (name == "--config") {
            o.config = val;
        } else if (name == "--output-format") {
            if (!gs_format_from_name(val.c_str(), val.size(), &o.out_format))
                return usage_error("--output-format must be json or nmea, not '" + val + "'");
            o.out_format_set = true;
        } else if (name == "--trace") {
            o.trace = val;
        } else if (name == "--overlay") {
            o.overlay = val;
        } else {
            o.plot = val;
        }
    }
    if (o.input.empty()) return usage_error("a video file or image sequence is required");
    if (o.detector != "pose" && (!o.model.empty() || !o.models.empty() || !o.engine.empty() || o.threads >= 0))
        return usage_error("--model, --models, --engine and --threads belong to --detector pose");
    return -1;
}

#if GS_HAVE_BALL_DETECTOR


int load_config(const std::string &path, bool person, gs_core_config &cfg, gs::BallConfig &ball,
                gs::PoseConfig &pose)
{
    gs_core_config_default(&cfg);
    if (!person) {  // a ball is small: its size range, unless the file says otherwise
        cfg.size_min_m = 0.02f;
        cfg.size_max_m = 0.5f;
    }
    if (path.empty()) return EXIT_OK;
    size_t n = 0;
    std::unique_ptr<char, decltype(&std::free)> text(gs_profile_read("gravscale", path.c_str(), &n), &std::free);
    if (!text) return EXIT_USAGE;
    // [core], [ball] and [pose]; the other sections of a profile belong to cam (gs_profile.h)
    gs_cfg_section sections[3 + GS_PROFILE_SECTIONS] = {{"core", gs_core_config_set, &cfg},
                                                        {"ball", gs::ball_config_set, &ball},
                                                        {"pose", gs::pose_config_set, &pose}};
    static const char *const own[] = {"core", "ball", "pose"};
    size_t n_sections = 3 + gs_profile_foreign_sections(own, 3, sections + 3, GS_PROFILE_SECTIONS);
    gs_cfg_error e;
    std::memset(&e, 0, sizeof e);
    gs_status st = gs_cfg_parse(text.get(), n, sections, n_sections, &e);
    if (st == GS_OK) {
        std::memset(&e, 0, sizeof e);
        st = gs_core_config_check(&cfg, &e);
    }
    if (st == GS_OK) {
        std::memset(&e, 0, sizeof e);
        st = gs::ball_config_check(ball, e.msg, sizeof e.msg);
        if (st != GS_OK) std::snprintf(e.section, sizeof e.section, "ball");
    }
    if (st != GS_OK) {
        gs_profile_print_error("gravscale", path.c_str(), &e);
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

// ---- the run ------------------------------------------------------------------

struct App {
    gs_format fmt = GS_FMT_JSON;
    gs_out out{};
    gs_out trace{};
    bool trace_on = false;
    uint32_t emit_fail = 0;
    gs::RunRecord rec;
    gs::SceneWatch *watch = nullptr;  // pose: per-flight warnings from the frames
    gs::BallFlights *flights = nullptr;    // ball: sizes along gravity, geometry, flights the core cannot seed
    std::map<uint32_t, uint32_t> flight_index;  // ball: per track, the next flight's number
};

bool is_trace_event(gs_event_type t) { return t == GS_EV_STATE || t == GS_EV_SAMPLE || t == GS_EV_FIT; }

void record_event(App &a, const gs_event *ev)
{
    if (ev->type == GS_EV_JUMP) {
        const gs_ev_jump &j = ev->u.jump;
        gs::JumpRecord r;
        r.track = j.track;
        r.index = j.index;
        r.t_takeoff_s = gs_time_s_of_us(j.t_takeoff_us);  // NaN for GS_T_NONE
        r.t_land_s = gs_time_s_of_us(j.t_land_us);
        r.t_apex_s = gs_time_s_of_us(j.t_apex_us);
        r.a_px_s2 = j.a_px_s2;
        r.g_dir_deg = j.g_dir_deg;
        r.q_m_per_px = j.q_m_per_px;
        r.size_px = j.size_px;
        r.height_m = j.height_m;
        r.accepted = j.accepted;
        r.reason = j.accepted ? "" : gs_reject_reason_name(j.reason);
        a.rec.jumps.push_back(r);
    } else if (ev->type == GS_EV_HEIGHT) {
        // the running aggregate that follows an accepted flight of this track
        for (auto it = a.rec.jumps.rbegin(); it != a.rec.jumps.rend(); ++it) {
            if (it->track == ev->u.height.track) {
                it->running_height_m = ev->u.height.height_m;
                it->running_n = ev->u.height.n_jumps;
                break;
            }
        }
    } else if (ev->type == GS_EV_SUMMARY) {
        gs::SummaryRecord s;
        s.track = ev->u.height.track;
        s.height_m = ev->u.height.height_m;
        s.lo_m = ev->u.height.ci95_lo_m;
        s.hi_m = ev->u.height.ci95_hi_m;
        s.n_jumps = ev->u.height.n_jumps;
        s.n_rejected = ev->u.height.n_rejected;
        a.rec.summaries.push_back(s);
    }
}

void on_event(void *ctx, const gs_event *ev)
{
    App &a = *static_cast<App *>(ctx);
    char buf[GS_EMIT_MAX];
    gs_event marked;
    if (ev->type == GS_EV_JUMP && a.watch) {  // what the frames say about this flight
        marked = *ev;
        gs_ev_jump &j = marked.u.jump;
        // the scene watch counts in the frames' seconds; unknown times are NaN there
        const double tk_s = gs_time_s_of_us(j.t_takeoff_us), tl_s = gs_time_s_of_us(j.t_land_us);
        j.warnings |= a.watch->flight_warnings(tk_s, tl_s, gs_time_s_of_us(j.t_apex_us));
        ev = &marked;
    }
    if (ev->type == GS_EV_JUMP && a.flights) {
        // the core's flights and the front end's (drops) in one count per track
        marked = *ev;
        marked.u.jump.index = a.flight_index[marked.u.jump.track]++;
        ev = &marked;
    }
    // a track other than 0 that never had a flight (a distractor followed for a
    // moment) gets no summary; track 0 always does, with a null size if need be
    if (ev->type == GS_EV_SUMMARY && ev->u.height.track != 0 && ev->u.height.n_jumps == 0 &&
        ev->u.height.n_rejected == 0)
        return;
    record_event(a, ev);
    if (a.trace_on) {
        size_t n = gs_emit_json(ev, buf, sizeof buf);
        if (n > 0)
            gs_out_line(&a.trace, buf, n);
        else
            a.emit_fail++;
    }
    if (is_trace_event(ev->type)) return;
    size_t n = gs_emit(a.fmt, ev, buf, sizeof buf);
    if (n > 0)
        gs_out_line(&a.out, buf, n);
    else
        a.emit_fail++;
}

// The frames' say on a flight before the core reports and aggregates it: something
// else moving right beside the person through much of the flight rejects it.
void judge_jump(void *ctx, gs_ev_jump *j)
{
    App &a = *static_cast<App *>(ctx);
    if (a.flights) {  // a ball: its size along gravity and the flight's geometry
        a.flights->judge(j);
        return;
    }
    if (!a.watch || !j->accepted) return;
    if (a.watch->other_rejects(gs_time_s_of_us(j->t_takeoff_us), gs_time_s_of_us(j->t_land_us),
                               gs_time_s_of_us(j->t_apex_us))) {
        j->accepted = false;
        j->reason = GS_REJ_OTHER_MOTION;
    }
}

// One core pipeline per tracked ball.
struct TrackPipe {
    gs_pipeline p;
    std::vector<double> storage;  // doubles: aligned for the ring
};

class Pipelines {
public:
    Pipelines(const gs_core_config &cfg, gs_layout layout, App &app) : cfg_(cfg), layout_(layout), app_(app) {}
    // nullptr when the pipeline cannot start (reported once)
    gs_pipeline *get(uint32_t track)
    {
        while (pipes_.size() <= track) {
            auto tp = std::make_unique<TrackPipe>();
            size_t bytes = gs_pipeline_storage_bytes(&cfg_);
            tp->storage.assign(bytes / sizeof(double) + 1, 0.0);
            gs_status st = gs_pipeline_init(&tp->p, &cfg_, layout_, tp->storage.data(),
                                            tp->storage.size() * sizeof(double), on_event, &app_);
            if (st != GS_OK) {
                init_error_ = st;
                return nullptr;
            }
            gs_pipeline_set_track(&tp->p, static_cast<uint32_t>(pipes_.size()));
            gs_pipeline_set_trace(&tp->p, app_.trace_on);
            // the judge reads the landing frame's state (the ball's size, the scene's motion)
            gs_pipeline_set_close_whole(&tp->p, true);
            gs_pipeline_set_judge(&tp->p, judge_jump, &app_);
            pipes_.push_back(std::move(tp));
        }
        return &pipes_[track]->p;
    }
    void flush_all()
    {
        if (pipes_.empty()) get(0);  // nothing seen: a summary for track 0 with a null size
        for (auto &tp : pipes_) gs_pipeline_flush(&tp->p);
    }
    // A flight the front end found (the core could not seed it) into the track's
    // output and aggregate, as the core reports its own.
    bool report(const gs_ev_jump &j)
    {
        gs_pipeline *p = get(j.track);
        if (!p) return false;
        gs_event ev;
        std::memset(&ev, 0, sizeof ev);
        ev.type = GS_EV_JUMP;
        ev.u.jump = j;
        on_event(&app_, &ev);
        if (!j.accepted) {
            gs_agg_reject(&p->agg);
            return true;
        }
        gs_agg_add(&p->agg, j.height_m, j.height_se_m);
        std::memset(&ev, 0, sizeof ev);
        ev.type = GS_EV_HEIGHT;
        gs_agg_get(&p->agg, &ev.u.height);
        ev.u.height.track = j.track;
        on_event(&app_, &ev);
        return true;
    }
    gs_status init_error() const { return init_error_; }
    uint64_t refused = 0;
    gs_status first_refusal = GS_OK;

private:
    gs_core_config cfg_;
    gs_layout layout_;
    App &app_;
    std::vector<std::unique_ptr<TrackPipe>> pipes_;
    gs_status init_error_ = GS_OK;
};

int output_status(const App &a)
{
    if (a.out.err) {
        if (a.out.err != EPIPE) std::fprintf(stderr, "gravscale: writing output: %s\n", std::strerror(a.out.err));
        return EXIT_IO;
    }
    if (a.trace_on && a.trace.err) {
        std::fprintf(stderr, "gravscale: writing the trace: %s\n", std::strerror(a.trace.err));
        return EXIT_IO;
    }
    return EXIT_OK;
}

std::string base_name(const std::string &p)
{
    size_t s = p.find_last_of('/');
    return s == std::string::npos ? p : p.substr(s + 1);
}

double now_s()
{
    using clk = std::chrono::steady_clock;
    return std::chrono::duration<double>(clk::now().time_since_epoch()).count();
}

// Second pass for the overlay: decode again and draw what the first pass learnt.
int write_overlay(const Options &o, const gs::FrameSourceOptions &fo, const gs::RunRecord &rec, double play_fps)
{
    std::string err;
    gs::FrameSource::Error kind;
    auto src = gs::FrameSource::open(o.input, fo, err, kind);
    if (!src) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.input.c_str(), err.c_str());
        return EXIT_DATA;
    }
    gs::OverlayWriter w;
    if (!w.open(o.overlay, rec, play_fps, err)) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.overlay.c_str(), err.c_str());
        return EXIT_IO;
    }
    gs::Frame f;
    while (src->next(f) && f.index < static_cast<int64_t>(rec.frame_t.size())) {
        if (!w.wants(f.index)) continue;
        gs::draw_overlay(f.bgr, rec, f.index);
        if (!w.add(f.bgr, f.index, err)) {
            std::fprintf(stderr, "gravscale: %s: %s\n", o.overlay.c_str(), err.c_str());
            return EXIT_IO;
        }
    }
    if (!w.close(err)) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.overlay.c_str(), err.c_str());
        return EXIT_IO;
    }
    return EXIT_OK;
}

// BlazePose keypoints that mark the body's top and bottom (for the border test)
constexpr int kBlazeEnds[] = {0, 2, 5, 7, 8, 27, 28, 29, 30, 31, 32};

// The person path's per-frame work: pose, camera motion, stabilised keypoints.
struct PersonFront {
    gs::PoseTracker pose;
    gs::CameraMotion cam;
    gs::SceneWatch watch;
    bool stabilize = true;
    explicit PersonFront(const gs::PoseConfig &pc) : pose(pc) {}

    // one frame and its pose (pose.process, maybe run ahead in another thread) ->
    // keypoints for the core (c = 0 when no body); records the scene facts
    void frame(const cv::Mat &bgr, double t_s, gs_kp *kp, gs::SceneFrame *sf, const gs::PoseOutput *po)
    {
        std::vector<cv::Rect> ex;
        float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
        if (po->present) {
            for (int k = 0; k < gs::kPoseKeypoints; k++) {
                x0 = std::min(x0, po->kp[k].x_px);
                y0 = std::min(y0, po->kp[k].y_px);
                x1 = std::max(x1, po->kp[k].x_px);
                y1 = std::max(y1, po->kp[k].y_px);
            }
            ex.push_back(cv::Rect(cv::Point((int)x0, (int)y0), cv::Point((int)x1 + 1, (int)y1 + 1)));
        }
        gs::CameraMotionFrame cm;
        cam.process(bgr, ex, &cm);
        *sf = gs::SceneFrame();
        sf->t_s = t_s;
        sf->cam_valid = cm.valid;
        sf->cam_dx_px = cm.dx_px;
        sf->cam_dy_px = cm.dy_px;
        sf->other = cm.other;
        sf->present = po->present;
        sf->ground_y_px = NAN;
        sf->size_px = NAN;
        for (int k = 0; k < gs::kPoseKeypoints; k++) {
            kp[k] = po->kp[k];
            if (!po->present) kp[k].c = 0.0f;
        }
        if (!po->present) return;
        sf->size_px = y1 - y0;
        const float mx = 2.0f;  // a point this close to the border is cut by it
        for (int k : kBlazeEnds) {
            const gs_kp &p = po->kp[k];
            bool out = p.x_px < mx || p.y_px < mx || p.x_px > bgr.cols - 1 - mx || p.y_px > bgr.rows - 1 - mx;
            if (out || po->in_frame[k] < 0.5f) sf->at_border = true;
        }
        // the feet's row: the lower of the two heels, when both are seen
        if (po->visibility[29] > 0.5f && po->visibility[30] > 0.5f)
            sf->ground_y_px = std::max(po->kp[29].y_px, po->kp[30].y_px);
        if (stabilize && cm.valid) {
            for (int k = 0; k < gs::kPoseKeypoints; k++) {
                cv::Point2d r = cam.to_reference(cv::Point2d(kp[k].x_px, kp[k].y_px));
                kp[k].x_px = static_cast<float>(r.x);
                kp[k].y_px = static_cast<float>(r.y);
            }
        }
    }
};

// GS_VIDEO_TIMES=FILE: where the frame loop's time went, one JSON line
// appended to FILE (for tools/bench_pipeline; not part of the output): per
// frame, the wall ms spent in each stage and the CPU ms of the thread that ran
// it (OpenCV's and FFmpeg's helper threads and the census's detector thread
// not counted; the network's time is the pose tracker's own det_ms + lm_ms,
// wall only, the two overlapping at a census); the process's CPU time of the
// setup and of the loop.
struct LoopTimes {
    gs::StageClock decode, pose, network, scene, core, wait;
    double t0_ms = 0.0, loop0_ms = 0.0, cpu0_ms = 0.0, loop_cpu0_ms = 0.0;
    int64_t frames = 0, detector_runs = 0;

    const char *engine = "none";  // the pose networks' engine
    const char *decoder = "none";  // the frame source's decoder

    void write(const char *path, int prefetch, double end_ms, double end_cpu_ms) const
    {
        FILE *f = std::fopen(path, "a");
        if (!f) return;
        auto per = [&](const gs::StageClock &c, const char *name) {  // the network's clock is wall time only
            std::fprintf(f, ",\"%s_ms\":%.3f", name, frames ? c.wall_ms / frames : 0.0);
            if (&c != &network) std::fprintf(f, ",\"%s_cpu_ms\":%.3f", name, frames ? c.cpu_ms / frames : 0.0);
        };
        std::fprintf(f, "{\"engine\":\"%s\",\"decoder\":\"%s\",\"frames\":%lld,\"prefetch\":%d,\"cv_threads\":%d,\"setup_s\":%.4f,\"loop_s\":%.4f,"
                        "\"total_s\":%.4f,\"setup_cpu_s\":%.4f,\"loop_cpu_s\":%.4f,\"detector_runs\":%lld",
                     engine, decoder, static_cast<long long>(frames), prefetch, cv::getNumThreads(), (loop0_ms - t0_ms) / 1e3,
                     (end_ms - loop0_ms) / 1e3, (end_ms - t0_ms) / 1e3, (loop_cpu0_ms - cpu0_ms) / 1e3,
                     (end_cpu_ms - loop_cpu0_ms) / 1e3, static_cast<long long>(detector_runs));
        per(decode, "decode");
        per(pose, "pose");
        per(network, "network");
        per(scene, "scene");
        per(core, "core");
        per(wait, "wait");
        std::fputs("}\n", f);
        std::fclose(f);
    }
};

int run(const Options &o)
{
    LoopTimes times;
    times.t0_ms = gs::wall_ms_now();
    times.cpu0_ms = gs::process_cpu_ms_now();
    const char *times_path = std::getenv("GS_VIDEO_TIMES");
    if (times_path && !*times_path) times_path = nullptr;
    const bool person = o.detector == "pose";
    gs_core_config cfg;
    gs::BallConfig ball_cfg;
    gs::PoseConfig pose_cfg;
    int rc = load_config(o.config, person, cfg, ball_cfg, pose_cfg);
    if (rc != EXIT_OK) return rc;
    if (!o.model.empty())
        pose_cfg.model = o.model == "full" ? gs::PoseModel::full : o.model == "heavy" ? gs::PoseModel::heavy
                                                                                      : gs::PoseModel::lite;
    if (!o.models.empty()) pose_cfg.models_dir = o.models;
    if (o.threads >= 0) pose_cfg.threads = o.threads;
    // prefetching runs decoding, the networks and the rest side by side: one thread
    // each (half the CPUs allowed) is less CPU per frame than each stage's own pool
    // (lite, 2 CPUs: 27.6 instead of 31.6 ms), the same output
    if (person && o.prefetch > 0 && pose_cfg.threads == 0) pose_cfg.threads = std::max(1, gs::allowed_cpus() / 2);
    if (!o.engine.empty()) gs::pose_engine_from_name(o.engine, &pose_cfg.engine);

    std::signal(SIGPIPE, SIG_IGN);  // a closed pipe shows as EPIPE on write

    std::unique_ptr<PersonFront> front;
    if (person) {
        std::string merr;
        if (!gs::pose_models_present(pose_cfg, merr)) {
            std::fprintf(stderr, "gravscale: %s\n", merr.c_str());
            return EXIT_USAGE;
        }
        front.reset(new PersonFront(pose_cfg));
        if (!front->pose.ok()) {
            std::fprintf(stderr, "gravscale: pose networks: %s\n", front->pose.error().c_str());
            return EXIT_USAGE;
        }
        front->stabilize = o.stabilize;
        times.engine = gs::pose_engine_name(front->pose.engine());
    }

    gs::FrameSourceOptions fo;
    fo.fps = o.fps;
    // prefetching gives decoding a thread of its own: one decoder thread, the least CPU a frame
    if (person && o.prefetch > 0) fo.decode_threads = 1;
    std::string err;
    gs::FrameSource::Error kind;
    std::unique_ptr<gs::FrameSource> src = gs::FrameSource::open(o.input, fo, err, kind);
    if (!src) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.input.c_str(), err.c_str());
        return kind == gs::FrameSource::Error::usage ? EXIT_USAGE : EXIT_DATA;
    }
    times.decoder = src->decoder();

    App app;
    app.fmt = o.out_format_set ? o.out_format : cfg.format;
    if (front) app.watch = &front->watch;
    gs_out_open_fd(&app.out, STDOUT_FILENO, 0);
    if (!o.trace.empty()) {
        if (gs_out_open_path(&app.trace, o.trace.c_str(), kTraceBufBytes) != 0) {
            std::fprintf(stderr, "gravscale: %s: cannot write the trace: %s\n", o.trace.c_str(),
                         std::strerror(app.trace.err ? app.trace.err : errno));
            return EXIT_IO;
        }
        app.trace_on = true;
    }
    app.rec.source = base_name(o.input);
    app.rec.fps = src->fps();
    app.rec.fps_origin = src->fps_origin();
    app.rec.frame_size = src->size();
    app.rec.person = person;

    const gs_layout layout = person ? GS_LAYOUT_BLAZEPOSE33 : GS_LAYOUT_POINT;
    gs_event ev;
    std::memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_START;
    ev.u.start.version = GS_VERSION;
    ev.u.start.config = o.config.empty() ? "default" : o.config.c_str();
    ev.u.start.fps_source = src->fps() > 0.0 ? src->fps() : NAN;
    ev.u.start.fps_origin = src->fps_origin();
    ev.u.start.layout = gs_layout_name(layout);
    on_event(&app, &ev);

    Pipelines pipes(cfg, layout, app);
    std::unique_ptr<gs::BallDetector> det;
    std::unique_ptr<gs::BallFlights> flights;
    // the pixels' shape: a stated aspect ratio other than 1 makes them square here
    // (x scaled); without one (or 1:1, often a default) the ball's shape decides
    const double sar = src->sample_aspect() > 0.0 && std::fabs(src->sample_aspect() - 1.0) > 1e-3
                           ? src->sample_aspect() : 1.0;
    std::vector<gs_ev_jump> fe_jumps;
    if (!person) {
        det.reset(new gs::BallDetector(ball_cfg));
        det->set_backlog(true);  // a ball's flight from its first frame, once it is known to be one
        gs::BallFlightsOptions bo;
        bo.core = cfg;
        bo.g_m_s2 = gs_core_config_g(&cfg);
        bo.psf_sigma_px = ball_cfg.psf_sigma_px;
        bo.square_pixels = sar != 1.0;
        bo.frame_w = src->size().width * sar;
        bo.frame_h = src->size().height;
        flights.reset(new gs::BallFlights(bo));
        app.flights = flights.get();
    }
    std::vector<gs::BallObs> obs;
    gs::Frame f;
    const bool keep = !o.overlay.empty() || !o.plot.empty();
    const bool progress = isatty(STDERR_FILENO) != 0;
    double next_progress = now_s() + 0.25;
    bool shown = false;
    // the frames, and for a person their pose: in this thread, or (--prefetch N)
    // decoded in one thread and posed in another, up to N frames ahead; each
    // stage still takes the frames one by one in order, so the output is the same
    struct Posed {
        gs::Frame f;
        gs::PoseOutput po;
    };
    auto decode = [&](gs::Frame &fr) {
        gs::StageClock::Scope s(times.decode);
        return src->next(fr);
    };
    auto pose = [&](const gs::Frame &fr, gs::PoseOutput &po) {
        {
            gs::StageClock::Scope s(times.pose);
            front->pose.process(fr.bgr, fr.t_s, &po);
        }
        times.network.wall_ms += po.det_ms + po.lm_ms;
        times.detector_runs += po.detector_ran;
    };
    std::unique_ptr<gs::Prefetch<gs::Frame>> decoded;
    std::unique_ptr<gs::Prefetch<Posed>> posed;
    if (person && o.prefetch > 0) {
        const size_t depth = static_cast<size_t>(o.prefetch);
        decoded.reset(new gs::Prefetch<gs::Frame>(decode, depth));
        posed.reset(new gs::Prefetch<Posed>(
            [&](Posed &p) {
                if (!decoded->next(p.f)) return false;
                pose(p.f, p.po);
                return true;
            },
            depth));
    }
    gs::PoseOutput po;
    auto next_frame = [&]() {
        if (!posed) return decode(f) && (!person || (pose(f, po), true));
        gs::StageClock::Scope s(times.wait);  // the time this thread waits for the workers
        Posed p;
        if (!posed->next(p)) return false;
        f = std::move(p.f);
        po = p.po;
        return true;
    };
    times.loop0_ms = gs::wall_ms_now();
    times.loop_cpu0_ms = gs::process_cpu_ms_now();
    while (!app.out.err && next_frame()) {
        times.frames++;
        if (f.bgr.size() != app.rec.frame_size) app.rec.frame_size = f.bgr.size();
        app.rec.frame_t.push_back(f.t_s);
        app.rec.frame_obs.emplace_back();
        if (person) {
            gs_kp kp[gs::kPoseKeypoints];
            gs::SceneFrame sf;
            {
                gs::StageClock::Scope s(times.scene);
                front->frame(f.bgr, f.t_s, kp, &sf, &po);
                front->watch.add(sf);
            }
            if (keep) {
                app.rec.frame_kp.emplace_back();
                if (po.present) {
                    for (int k = 0; k < gs::kPoseKeypoints; k++)
                        app.rec.frame_kp.back().push_back(cv::Point3f(po.kp[k].x_px, po.kp[k].y_px, po.kp[k].c));
                    // the COM drawn where it is in this frame (the core gets it stabilised)
                    gs_com_out c;
                    if (gs_com_compute(GS_LAYOUT_BLAZEPOSE33, cfg.mass_table, cfg.stature, cfg.min_conf, po.kp, &c) ==
                            GS_OK && std::isfinite(c.x_px))
                        app.rec.frame_obs.back().push_back({0, c.x_px, c.y_px, NAN, c.w});
                }
            }
            gs_pipeline *p = pipes.get(0);
            if (!p) {
                std::fprintf(stderr, "gravscale: cannot start the pipeline: %s\n", gs_status_str(pipes.init_error()));
                return EXIT_USAGE;
            }
            gs::StageClock::Scope core_clock(times.core);
            gs_status st = gs_pipeline_push_keypoints(p, f.t_s, kp);
            if (st != GS_OK && pipes.refused++ == 0) pipes.first_refusal = st;
            uint32_t on = front->watch.onsets();
            if (on) {  // guidance: a condition just started
                std::memset(&ev, 0, sizeof ev);
                ev.type = GS_EV_WARNING;
                ev.u.warning.t_us = gs_time_us_of_s(f.t_s);
                ev.u.warning.warnings = on;
                on_event(&app, &ev);
            }
        } else {
            obs.clear();
            det->process(f.bgr, f.t_s, obs);
            for (const gs::BallObs &b : obs) {
                if (b.track < 0 || b.frame < 0 || b.frame >= static_cast<int64_t>(app.rec.frame_obs.size())) continue;
                if (keep)
                    app.rec.frame_obs[static_cast<size_t>(b.frame)].push_back(
                        {b.track, b.x_px, b.y_px, b.diameter_px, b.confidence});
                gs_pipeline *p = pipes.get(static_cast<uint32_t>(b.track));
                if (!p) {
                    std::fprintf(stderr, "gravscale: cannot start the pipeline: %s\n",
                                 gs_status_str(pipes.init_error()));
                    return EXIT_USAGE;
                }
                gs::BallObs sq = b;  // in square pixels
                sq.x_px *= sar;
                sq.sxx *= sar * sar;
                sq.sxy *= sar;
                flights->add(sq);
                gs_status st = gs_pipeline_push_point(p, b.t_s, static_cast<float>(sq.x_px),
                                                      static_cast<float>(b.y_px), static_cast<float>(b.confidence),
                                                      static_cast<float>(b.diameter_px));
                if (st != GS_OK && pipes.refused++ == 0) pipes.first_refusal = st;
            }
            flights->set_rolling_shutter(det->rolling_shutter_s_per_row());
            fe_jumps.clear();
            flights->take_pending(f.t_s + det->clock_shift_s(), false, fe_jumps);
            for (const gs_ev_jump &j : fe_jumps) pipes.report(j);
        }
        if (progress && (f.index & 15) == 0 && now_s() > next_progress) {
            next_progress = now_s() + 0.25;
            if (src->frames_announced() > 0)
                std::fprintf(stderr, "\rgravscale: frame %lld of %lld", static_cast<long long>(f.index + 1),
                             static_cast<long long>(src->frames_announced()));
            else
                std::fprintf(stderr, "\rgravscale: frame %lld", static_cast<long long>(f.index + 1));
            shown = true;
        }
    }
    if (shown) std::fputs("\r                                        \r", stderr);
    posed.reset();  // the workers are done (or stopped: output error)
    decoded.reset();
    if (app.out.err) return output_status(app);
    if (!src->error().empty()) {
        // an image that cannot be decoded: bad input, no summary (as replay)
        gs_out_flush(&app.trace);
        std::fprintf(stderr, "gravscale: %s\n", src->error().c_str());
        rc = output_status(app);
        return rc == EXIT_OK ? EXIT_DATA : rc;
    }
    if (src->frames_read() == 0) {
        gs_out_flush(&app.trace);
        std::fprintf(stderr, "gravscale: %s: no frame could be decoded\n", o.input.c_str());
        rc = output_status(app);
        return rc == EXIT_OK ? EXIT_DATA : rc;
    }
    int64_t announced = src->frames_announced();
    if (!src->is_image_sequence() && announced > 0 && src->frames_read() + 2 < announced)
        std::fprintf(stderr, "gravscale: %s: warning: decoding ended after %lld of the %lld frames the container announces\n",
                     o.input.c_str(), static_cast<long long>(src->frames_read()), static_cast<long long>(announced));
    if (flights) {
        fe_jumps.clear();
        flights->take_pending(0.0, true, fe_jumps);
        for (const gs_ev_jump &j : fe_jumps) pipes.report(j);
    }
    pipes.flush_all();
    if (pipes.refused)
        std::fprintf(stderr, "gravscale: %llu observations refused by the pipeline (first: %s)\n",
                     static_cast<unsigned long long>(pipes.refused), gs_status_str(pipes.first_refusal));
    if (app.emit_fail)
        std::fprintf(stderr, "gravscale: %u events could not be formatted\n", static_cast<unsigned>(app.emit_fail));
    rc = output_status(app);
    if (app.trace_on && gs_out_close(&app.trace) != 0 && rc == EXIT_OK) {
        std::fprintf(stderr, "gravscale: writing the trace: %s\n", std::strerror(app.trace.err));
        rc = EXIT_IO;
    }
    app.trace_on = false;
    gs_out_close(&app.out);
    if (times_path) times.write(times_path, person ? o.prefetch : 0, gs::wall_ms_now(), gs::process_cpu_ms_now());
    if (rc != EXIT_OK) return rc;

    if (keep) gs::fit_jump_curves(app.rec);
    if (!o.plot.empty() && !gs::write_plot(app.rec, o.plot, err)) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.plot.c_str(), err.c_str());
        return EXIT_IO;
    }
    if (!o.overlay.empty()) {
        double play = src->stream_fps() > 0.0 ? src->stream_fps() : src->fps();
        src.reset();
        rc = write_overlay(o, fo, app.rec, play);
        if (rc != EXIT_OK) return rc;
    }
    return EXIT_OK;
}

#endif  // GS_HAVE_BALL_DETECTOR

}  // namespace

extern "C" int gs_cmd_video(int argc, char **argv)
{
    Options o;
    int rc = parse_args(argc, argv, o);
    if (rc >= 0) return rc;
#if GS_HAVE_BALL_DETECTOR
    try {
        return run(o);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.input.c_str(), e.what());
        return EXIT_DATA;
    }
#else
    std::fputs("gravscale: built without the ball detector (src/vision/ball_detector.cpp)\n", stderr);
    return EXIT_USAGE;
#endif
}
