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
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "frame_source.hpp"
#include "overlay.hpp"

#if __has_include("ball_detector.hpp")
#include "ball_detector.hpp"
#define GS_HAVE_BALL_DETECTOR 1
#else
#define GS_HAVE_BALL_DETECTOR 0
#endif

extern "C" {
#include "gravscale/gravscale.h"
#include "gs_out.h"
#include "gs_profile.h"
}

extern "C" int gs_cmd_video(int argc, char **argv);

namespace {

enum { EXIT_OK = 0, EXIT_DATA = 1, EXIT_USAGE = 2, EXIT_IO = 3 };
constexpr size_t kConfigMaxBytes = 1u << 20;
constexpr size_t kTraceBufBytes = 1u << 16;

const char kHelp[] =
    "usage: gravscale video FILE [OPTIONS]\n"
    "\n"
    "Detect a ball in a video (any container FFmpeg reads) or an image sequence,\n"
    "follow its free flights and print every flight, the running size and a final\n"
    "summary per ball as JSON Lines (or NMEA sentences), as `gravscale replay`\n"
    "does. For a ball, height_m is its diameter.\n"
    "\n"
    "  FILE                 a video file, a folder of images (in name order) or a\n"
    "                       printf pattern such as frames/%05d.png\n"
    "  --detector D         ball (the default and, for now, the only one)\n"
    "  --fps N              the true frame rate: stream times are rescaled to N\n"
    "                       frames per second of real time (slow-motion clips stored\n"
    "                       at a false rate); required for an image sequence.\n"
    "                       Default: the capture rate a phone stored in the\n"
    "                       metadata (com.android.capture.fps), else the stream's\n"
    "  --config FILE        key = value configuration, sections [core] and [ball]\n"
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
    double fps = 0.0;
    bool out_format_set = false;
    gs_format out_format = GS_FMT_JSON;
};

int usage_error(const std::string &msg)
{
    std::fprintf(stderr, "gravscale: video: %s (see gravscale video --help)\n", msg.c_str());
    return EXIT_USAGE;
}

// -1 to go on, else an exit code
int parse_args(int argc, char **argv, Options &o)
{
    static const char *const known[] = {"--detector", "--fps",     "--config", "--output-format",
                                        "--trace",    "--overlay", "--plot"};
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
        size_t eq = a.find('=');
        std::string name = a.substr(0, eq), val;
        bool ok = false;
        for (const char *k : known) ok = ok || name == k;
        if (!ok) return usage_error("unknown option '" + name + "'");
        if (eq != std::string::npos) {
            val = a.substr(eq + 1);
        } else {
            if (i + 1 >= argc) return usage_error("option '" + name + "' needs a value");
            val = argv[++i];
        }
        if (name == "--detector") {
            if (val != "ball") return usage_error("--detector must be ball, not '" + val + "'");
            o.detector = val;
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
    return -1;
}

#if GS_HAVE_BALL_DETECTOR

void print_cfg_error(const std::string &path, const gs_cfg_error &e)
{
    std::fprintf(stderr, "gravscale: %s:", path.c_str());
    if (e.line > 0) std::fprintf(stderr, "%u:", static_cast<unsigned>(e.line));
    if (e.section[0]) std::fprintf(stderr, " [%s]", e.section);
    if (e.key[0]) std::fprintf(stderr, " key '%s'", e.key);
    std::fprintf(stderr, "%s %s\n", (e.section[0] || e.key[0]) ? ":" : "", e.msg[0] ? e.msg : "invalid configuration");
}

int load_config(const std::string &path, gs_core_config &cfg, gs::BallConfig &ball)
{
    gs_core_config_default(&cfg);
    // a ball is small: its size range, unless the file says otherwise
    cfg.size_min_m = 0.02f;
    cfg.size_max_m = 0.5f;
    if (path.empty()) return EXIT_OK;
    FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) {
        std::fprintf(stderr, "gravscale: %s: cannot open config: %s\n", path.c_str(), std::strerror(errno));
        return EXIT_USAGE;
    }
    std::string text(kConfigMaxBytes + 1, '\0');
    size_t n = std::fread(&text[0], 1, text.size(), f);
    bool bad = std::ferror(f) != 0;
    std::fclose(f);
    if (bad) {
        std::fprintf(stderr, "gravscale: %s: cannot read config\n", path.c_str());
        return EXIT_USAGE;
    }
    if (n > kConfigMaxBytes) {
        std::fprintf(stderr, "gravscale: %s: config larger than %u bytes\n", path.c_str(),
                     static_cast<unsigned>(kConfigMaxBytes));
        return EXIT_USAGE;
    }
    // [core] and [ball]; the other sections of a profile belong to cam (gs_profile.h)
    gs_cfg_section sections[2 + GS_PROFILE_SECTIONS] = {{"core", gs_core_config_set, &cfg},
                                                        {"ball", gs::ball_config_set, &ball}};
    static const char *const own[] = {"core", "ball"};
    size_t n_sections = 2 + gs_profile_foreign_sections(own, 2, sections + 2, GS_PROFILE_SECTIONS);
    gs_cfg_error e;
    std::memset(&e, 0, sizeof e);
    gs_status st = gs_cfg_parse(text.data(), n, sections, n_sections, &e);
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
        print_cfg_error(path, e);
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
};

bool is_trace_event(gs_event_type t) { return t == GS_EV_STATE || t == GS_EV_SAMPLE || t == GS_EV_FIT; }

void record_event(App &a, const gs_event *ev)
{
    if (ev->type == GS_EV_JUMP) {
        const gs_ev_jump &j = ev->u.jump;
        gs::JumpRecord r;
        r.track = j.track;
        r.index = j.index;
        r.t_takeoff_s = j.t_takeoff_s;
        r.t_land_s = j.t_land_s;
        r.t_apex_s = j.t_apex_s;
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

// One core pipeline per tracked ball.
struct TrackPipe {
    gs_pipeline p;
    std::vector<double> storage;  // doubles: aligned for the ring
};

class Pipelines {
public:
    Pipelines(const gs_core_config &cfg, App &app) : cfg_(cfg), app_(app) {}
    // nullptr when the pipeline cannot start (reported once)
    gs_pipeline *get(uint32_t track)
    {
        while (pipes_.size() <= track) {
            auto tp = std::make_unique<TrackPipe>();
            size_t bytes = gs_pipeline_storage_bytes(&cfg_);
            tp->storage.assign(bytes / sizeof(double) + 1, 0.0);
            gs_status st = gs_pipeline_init(&tp->p, &cfg_, GS_LAYOUT_POINT, tp->storage.data(),
                                            tp->storage.size() * sizeof(double), on_event, &app_);
            if (st != GS_OK) {
                init_error_ = st;
                return nullptr;
            }
            gs_pipeline_set_track(&tp->p, static_cast<uint32_t>(pipes_.size()));
            gs_pipeline_set_trace(&tp->p, app_.trace_on);
            pipes_.push_back(std::move(tp));
        }
        return &pipes_[track]->p;
    }
    void flush_all()
    {
        if (pipes_.empty()) get(0);  // nothing seen: a summary for track 0 with a null size
        for (auto &tp : pipes_) gs_pipeline_flush(&tp->p);
    }
    gs_status init_error() const { return init_error_; }
    uint64_t refused = 0;
    gs_status first_refusal = GS_OK;

private:
    gs_core_config cfg_;
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

int run(const Options &o)
{
    gs_core_config cfg;
    gs::BallConfig ball_cfg;
    int rc = load_config(o.config, cfg, ball_cfg);
    if (rc != EXIT_OK) return rc;

    std::signal(SIGPIPE, SIG_IGN);  // a closed pipe shows as EPIPE on write

    gs::FrameSourceOptions fo;
    fo.fps = o.fps;
    std::string err;
    gs::FrameSource::Error kind;
    std::unique_ptr<gs::FrameSource> src = gs::FrameSource::open(o.input, fo, err, kind);
    if (!src) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.input.c_str(), err.c_str());
        return kind == gs::FrameSource::Error::usage ? EXIT_USAGE : EXIT_DATA;
    }

    App app;
    app.fmt = o.out_format_set ? o.out_format : cfg.format;
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

    gs_event ev;
    std::memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_START;
    ev.u.start.version = GS_VERSION;
    ev.u.start.config = o.config.empty() ? "default" : o.config.c_str();
    ev.u.start.fps_source = src->fps() > 0.0 ? src->fps() : NAN;
    ev.u.start.fps_origin = src->fps_origin();
    ev.u.start.layout = gs_layout_name(GS_LAYOUT_POINT);
    on_event(&app, &ev);

    Pipelines pipes(cfg, app);
    gs::BallDetector det(ball_cfg);
    std::vector<gs::BallObs> obs;
    gs::Frame f;
    const bool keep = !o.overlay.empty() || !o.plot.empty();
    const bool progress = isatty(STDERR_FILENO) != 0;
    double next_progress = now_s() + 0.25;
    bool shown = false;
    while (!app.out.err && src->next(f)) {
        if (f.bgr.size() != app.rec.frame_size) app.rec.frame_size = f.bgr.size();
        obs.clear();
        det.process(f.bgr, f.t_s, obs);
        app.rec.frame_t.push_back(f.t_s);
        app.rec.frame_obs.emplace_back();
        for (const gs::BallObs &b : obs) {
            if (b.track < 0) continue;
            if (keep) app.rec.frame_obs.back().push_back({b.track, b.x_px, b.y_px, b.diameter_px, b.confidence});
            gs_pipeline *p = pipes.get(static_cast<uint32_t>(b.track));
            if (!p) {
                std::fprintf(stderr, "gravscale: cannot start the pipeline: %s\n", gs_status_str(pipes.init_error()));
                return EXIT_USAGE;
            }
            gs_status st = gs_pipeline_push_point(p, f.t_s, static_cast<float>(b.x_px), static_cast<float>(b.y_px),
                                                  static_cast<float>(b.confidence),
                                                  static_cast<float>(b.diameter_px));
            if (st != GS_OK && pipes.refused++ == 0) pipes.first_refusal = st;
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
