// cmd_cam.cpp - `gravscale cam`: the device daemon. One thread, one poll loop:
// capture a frame (V4L2, libcamera, GStreamer, a file; or a keypoint CSV for
// soak runs), run the detector, push into one core pipeline per tracked
// object, emit every event to every sink, poll the sinks, and write a status
// line every [status] interval_s. SIGINT/SIGTERM end it cleanly: open flights
// and summaries are flushed and the sinks drained with a bounded wait.
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <chrono>
#include <thread>
#include <vector>

#include <unistd.h>

#include "capture.hpp"
#include "detector.hpp"
#if defined(GS_HAVE_KIOSK)
#include "kiosk.hpp"
#endif

extern "C" {
#include "gravscale/gravscale.h"
#include "app_common.h"
#include "gs_kpread.h"
#include "gs_profile.h"
#include "gs_sink_config.h"
}

extern "C" int gs_cmd_cam(int argc, char **argv);

namespace {

enum { EXIT_OK = GS_EXIT_OK, EXIT_SOURCE = GS_EXIT_DATA, EXIT_USAGE = GS_EXIT_USAGE, EXIT_IO = GS_EXIT_IO };
constexpr int kStepMs = 10;  // the loop's longest wait for a frame: sinks are polled at least this often

const char kHelp[] =
    "usage: gravscale cam --config PROFILE [OPTIONS]\n"
    "\n"
    "The device daemon: captures live frames, runs the detector and the core, and\n"
    "writes every event as a line (JSON Lines or NMEA) to the profile's sinks\n"
    "(stdout, file, serial, TCP server, TCP client, UDP, MQTT), with a status line\n"
    "every [status] interval_s. Runs until the source ends or SIGINT/SIGTERM, then\n"
    "flushes open flights and summaries and drains the sinks. docs/cam.md.\n"
    "With [kiosk] it also serves the results page, athletes' history and its API\n"
    "(docs/kiosk.md); then a source that ends leaves the page up until a signal.\n"
    "\n"
    "  --config FILE          the profile: [cam] [core] [ball] [pose] [sink.*] [status] [kiosk]\n"
    "options override the profile's [cam] keys:\n"
    "  --backend B            v4l2 | libcamera | gstreamer | file | keypoints\n"
    "  --device D             /dev/videoN; a libcamera index or id; a GStreamer\n"
    "                         pipeline ending in appsink; a video file; a CSV\n"
    "  --size WxH             requested frame size (the driver may give another)\n"
    "  --fps N                requested frame rate\n"
    "  --pixel-format F       auto | mjpeg | yuyv (V4L2, libcamera)\n"
    "  --detector D           ball | pose (BlazePose, one person)\n"
    "  --output-format F      json | nmea (default: [core] format)\n"
    "  --status-interval S    seconds between status lines, 0 none ([status] interval_s)\n"
    "  --as-fast-as-possible  file/keypoints: do not wait for the frames' times\n"
    "  --drain-s S            at the end, wait at most S s for queued lines (default 2)\n"
    "  --kiosk-port N         the kiosk page's port ([kiosk] port; 0: a free one)\n"
    "  --kiosk-db FILE        the kiosk's SQLite history ([kiosk] db)\n"
    "  --wait-for-athlete     file/keypoints: start the video once an athlete is named\n"
    "  --help                 this text\n"
    "\n"
    "A TCP server sink with port = 0 gets a free port, printed on stderr as\n"
    "\"gravscale: cam: tcp sink listening on ADDRESS:PORT\"; the kiosk prints\n"
    "\"gravscale: cam: kiosk page on http://ADDRESS:PORT/\".\n"
    "\n"
    "Exit codes: 0 the source ended or a signal stopped it (events flushed);\n"
    "1 the source failed while running (device gone, bad data; events flushed);\n"
    "2 usage or configuration error, or the source or a sink cannot be opened\n"
    "(missing device, no camera, port in use); 3 a stdout/file sink failed.\n";

// ---- configuration ---------------------------------------------------------------

struct CamConfig {
    gs::CaptureConfig cap;
    std::string detector = "ball";
    double drain_s = 2.0;
};

bool is_word(const char *v, size_t n, const char *w) { return std::strlen(w) == n && std::strncmp(v, w, n) == 0; }

gs_status set_msg(char *msg, size_t cap, const char *text, gs_status st)
{
    if (msg && cap) std::snprintf(msg, cap, "%s", text);
    return st;
}

gs_status cam_config_set(void *ctx, const char *key, size_t kl, const char *v, size_t vl, char *msg, size_t cap)
{
    CamConfig &c = *static_cast<CamConfig *>(ctx);
    std::string k(key, kl), val(v, vl);
    double d;
    if (k == "backend") {
        if (val != "v4l2" && val != "libcamera" && val != "gstreamer" && val != "file" && val != "keypoints")
            return set_msg(msg, cap, "expected v4l2, libcamera, gstreamer, file or keypoints", GS_EINVAL);
        c.cap.backend = val;
    } else if (k == "device") {
        if (val.empty()) return set_msg(msg, cap, "empty device", GS_EINVAL);
        c.cap.device = val;
    } else if (k == "width" || k == "height") {
        if (!gs_num_parse(v, vl, &d) || d != std::floor(d)) return set_msg(msg, cap, "expected a whole number of pixels", GS_EINVAL);
        if (d < 16 || d > 8192) return set_msg(msg, cap, "out of range 16 .. 8192", GS_ERANGE);
        (k == "width" ? c.cap.width : c.cap.height) = static_cast<int>(d);
    } else if (k == "fps") {
        if (!gs_num_parse(v, vl, &d)) return set_msg(msg, cap, "expected a number", GS_EINVAL);
        if (!(d >= 1 && d <= 1000)) return set_msg(msg, cap, "out of range 1 .. 1000", GS_ERANGE);
        c.cap.fps = d;
    } else if (k == "pixel_format") {
        if (!is_word(v, vl, "auto") && !is_word(v, vl, "mjpeg") && !is_word(v, vl, "yuyv"))
            return set_msg(msg, cap, "expected auto, mjpeg or yuyv", GS_EINVAL);
        c.cap.pixel_format = val;
    } else if (k == "buffers") {
        if (!gs_num_parse(v, vl, &d) || d != std::floor(d)) return set_msg(msg, cap, "expected a whole number", GS_EINVAL);
        if (d < 2 || d > 32) return set_msg(msg, cap, "out of range 2 .. 32", GS_ERANGE);
        c.cap.buffers = static_cast<unsigned>(d);
    } else if (k == "detector") {
        if (!gs::detector_known(val) && val != "pose") return set_msg(msg, cap, "expected ball or pose", GS_EINVAL);
        c.detector = val;
    } else if (k == "realtime") {
        if (is_word(v, vl, "yes") || is_word(v, vl, "true") || is_word(v, vl, "on") || is_word(v, vl, "1"))
            c.cap.realtime = true;
        else if (is_word(v, vl, "no") || is_word(v, vl, "false") || is_word(v, vl, "off") || is_word(v, vl, "0"))
            c.cap.realtime = false;
        else
            return set_msg(msg, cap, "expected yes or no", GS_EINVAL);
    } else if (k == "gst_timestamps") {
        if (!is_word(v, vl, "count") && !is_word(v, vl, "position"))
            return set_msg(msg, cap, "expected count or position", GS_EINVAL);
        c.cap.gst_time = val;
    } else if (k == "drain_s") {
        if (!gs_num_parse(v, vl, &d)) return set_msg(msg, cap, "expected a number", GS_EINVAL);
        if (!(d >= 0 && d <= 60)) return set_msg(msg, cap, "out of range 0 .. 60", GS_ERANGE);
        c.drain_s = d;
    } else {
        return GS_ENOKEY;
    }
    return GS_OK;
}

struct Options {
    std::string config, backend, device, pixel_format, detector, kiosk_db;
    int width = 0, height = 0, kiosk_port = -1;
    bool wait_for_athlete = false;
    double fps = 0.0, status_interval_s = -1.0, drain_s = -1.0;
    bool fast = false, out_format_set = false, check = false;
    gs_format out_format = GS_FMT_JSON;
};

int usage_error(const std::string &msg) { return gs_app_usage_error("cam", "%s", msg.c_str()); }

bool parse_num(const std::string &s, double lo, double hi, double &out)
{
    double d;
    if (!gs_num_parse(s.c_str(), s.size(), &d) || !(d >= lo && d <= hi)) return false;
    out = d;
    return true;
}

int parse_args(int argc, char **argv, Options &o)
{
    static const char *const with_value[] = {"--config",       "--backend", "--device",          "--size",
                                             "--fps",          "--pixel-format", "--detector",   "--output-format",
                                             "--status-interval", "--drain-s", "--kiosk-port", "--kiosk-db"};
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "--help" || a == "-h") {
            std::fputs(kHelp, stdout);
            return std::fflush(stdout) == 0 ? EXIT_OK : EXIT_IO;
        }
        if (a == "--as-fast-as-possible") {
            o.fast = true;
            continue;
        }
        if (a == "--check") {
            o.check = true;
            continue;
        }
        if (a == "--wait-for-athlete") {
            o.wait_for_athlete = true;
            continue;
        }
        char name_buf[32];
        const char *val_c;
        int rc = gs_app_option("cam", argc, argv, &i, with_value, sizeof with_value / sizeof with_value[0],
                               name_buf, sizeof name_buf, &val_c);
        if (rc >= 0) return rc;
        const std::string name = name_buf, val = val_c;
        double d;
        if (name == "--config") {
            o.config = val;
        } else if (name == "--backend") {
            o.backend = val;
        } else if (name == "--device") {
            if (val.empty()) return usage_error("--device needs a value");
            o.device = val;
        } else if (name == "--size") {
            int w = 0, h = 0;
            char tail = 0;
            if (std::sscanf(val.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 16 || h < 16 || w > 8192 || h > 8192)
                return usage_error("--size must be WxH (16 .. 8192), not '" + val + "'");
            o.width = w;
            o.height = h;
        } else if (name == "--fps") {
            if (!parse_num(val, 1, 1000, d)) return usage_error("--fps must be 1 .. 1000, not '" + val + "'");
            o.fps = d;
        } else if (name == "--pixel-format") {
            if (val != "auto" && val != "mjpeg" && val != "yuyv")
                return usage_error("--pixel-format must be auto, mjpeg or yuyv, not '" + val + "'");
            o.pixel_format = val;
        } else if (name == "--detector") {
            if (!gs::detector_known(val) && val != "pose")
                return usage_error("--detector must be ball or pose, not '" + val + "'");
            o.detector = val;
        } else if (name == "--output-format") {
            if (!gs_format_from_name(val.c_str(), val.size(), &o.out_format))
                return usage_error("--output-format must be json or nmea, not '" + val + "'");
            o.out_format_set = true;
        } else if (name == "--kiosk-port") {
            if (!parse_num(val, 0, 65535, d) || d != std::floor(d))
                return usage_error("--kiosk-port must be 0 .. 65535, not '" + val + "'");
            o.kiosk_port = static_cast<int>(d);
        } else if (name == "--kiosk-db") {
            if (val.empty()) return usage_error("--kiosk-db needs a file");
            o.kiosk_db = val;
        } else if (name == "--status-interval") {
            if (!parse_num(val, 0, 3600, d)) return usage_error("--status-interval must be 0 .. 3600 s, not '" + val + "'");
            o.status_interval_s = d;
        } else {
            if (!parse_num(val, 0, 60, d)) return usage_error("--drain-s must be 0 .. 60 s, not '" + val + "'");
            o.drain_s = d;
        }
    }
    if (o.config.empty()) return usage_error("--config PROFILE is required");
    if (!o.backend.empty() && o.backend != "v4l2" && o.backend != "libcamera" && o.backend != "gstreamer" &&
        o.backend != "file" && o.backend != "keypoints")
        return usage_error("--backend must be v4l2, libcamera, gstreamer, file or keypoints, not '" + o.backend + "'");
    return -1;
}


#if defined(GS_HAVE_KIOSK)
using KioskConfig = gs::kiosk::Config;
gs_cfg_section kiosk_section(KioskConfig &k) { return gs::kiosk::config_section(k); }
gs_status kiosk_check(const KioskConfig &k, gs_cfg_error &e) { return gs::kiosk::config_check(k, e); }
#else
struct KioskConfig {
    bool on() const { return false; }
};
gs_status kiosk_refuse(void *, const char *, size_t, const char *, size_t, char *msg, size_t cap)
{
    return set_msg(msg, cap, "this gravscale was built without the kiosk (civetweb, SQLite, nlohmann-json: "
                   "tools/bootstrap.sh installs them)", GS_EINVAL);
}
gs_cfg_section kiosk_section(KioskConfig &k) { return gs_cfg_section{"kiosk", kiosk_refuse, &k}; }
gs_status kiosk_check(const KioskConfig &, gs_cfg_error &) { return GS_OK; }
#endif

struct Profile {
    gs_core_config core;
    CamConfig cam;
    gs::DetectorConfigs det;
    gs_sinks_config sinks;
    KioskConfig kiosk;
};

gs_status parse_profile(const std::string &text, Profile &p, bool small_object, gs_cfg_error &e)
{
    gs_core_config_default(&p.core);
    if (small_object) {  // a ball: its size range unless the file says otherwise (as `gravscale video`)
        p.core.size_min_m = 0.02f;
        p.core.size_max_m = 0.5f;
    }
    p.cam = CamConfig();
    p.det = gs::DetectorConfigs();
    gs_sinks_config_default(&p.sinks);
    p.kiosk = KioskConfig();
    std::vector<gs_cfg_section> sec = {{"core", gs_core_config_set, &p.core}, {"cam", cam_config_set, &p.cam},
                                       kiosk_section(p.kiosk)};
    gs::detector_config_sections(p.det, sec);
    gs_cfg_section sink_sec[GS_SINKS_CONFIG_SECTIONS];
    size_t ns = gs_sinks_config_sections(&p.sinks, sink_sec, GS_SINKS_CONFIG_SECTIONS);
    sec.insert(sec.end(), sink_sec, sink_sec + ns);
    // sections of the profile no layer here reads (a detector not built in) are skipped
    std::vector<const char *> own;
    for (const gs_cfg_section &x : sec) own.push_back(x.name);
    gs_cfg_section foreign[GS_PROFILE_SECTIONS];
    size_t nf = gs_profile_foreign_sections(own.data(), own.size(), foreign, GS_PROFILE_SECTIONS);
    sec.insert(sec.end(), foreign, foreign + nf);
    std::memset(&e, 0, sizeof e);
    gs_status st = gs_cfg_parse(text.data(), text.size(), sec.data(), sec.size(), &e);
    if (st != GS_OK) return st;
    std::memset(&e, 0, sizeof e);
    if ((st = gs_core_config_check(&p.core, &e)) != GS_OK) return st;
    std::memset(&e, 0, sizeof e);
    if ((st = gs_sinks_config_check(&p.sinks, &e)) != GS_OK) return st;
    std::memset(&e, 0, sizeof e);
    if ((st = kiosk_check(p.kiosk, e)) != GS_OK) return st;
    std::memset(&e, 0, sizeof e);
    if (!gs::detector_config_check(p.det, e)) return GS_EINVAL;
    return GS_OK;
}

int load_profile(const Options &o, Profile &p)
{
    size_t n = 0;
    char *raw = gs_profile_read("gravscale", o.config.c_str(), &n);
    if (!raw) return EXIT_USAGE;
    std::string text(raw, n);
    std::free(raw);
    gs_cfg_error e;
    // first pass: which detector (it sets the default size range), and every error
    if (parse_profile(text, p, false, e) != GS_OK) {
        gs_profile_print_error("gravscale", o.config.c_str(), &e);
        return EXIT_USAGE;
    }
    const std::string det = o.detector.empty() ? p.cam.detector : o.detector;
    const std::string backend = o.backend.empty() ? p.cam.cap.backend : o.backend;
    // keypoints come without a detector: the size range stays a person's
    if (backend != "keypoints" && gs::detector_is_small_object(det) && parse_profile(text, p, true, e) != GS_OK) {
        gs_profile_print_error("gravscale", o.config.c_str(), &e);
        return EXIT_USAGE;
    }
    // the command line wins
    CamConfig &c = p.cam;
    if (!o.backend.empty()) c.cap.backend = o.backend;
    if (!o.device.empty()) c.cap.device = o.device;
    if (o.width) c.cap.width = o.width, c.cap.height = o.height;
    if (o.fps > 0.0) c.cap.fps = o.fps;
    if (!o.pixel_format.empty()) c.cap.pixel_format = o.pixel_format;
    if (!o.detector.empty()) c.detector = o.detector;
    if (o.fast) c.cap.realtime = false;
    if (o.drain_s >= 0.0) c.drain_s = o.drain_s;
    if (o.status_interval_s >= 0.0) p.sinks.status_interval_s = o.status_interval_s;
    if (o.out_format_set) p.core.format = o.out_format;
#if defined(GS_HAVE_KIOSK)
    if (o.kiosk_port >= 0) p.kiosk.port = static_cast<uint16_t>(o.kiosk_port);
    if (!o.kiosk_db.empty()) p.kiosk.db = o.kiosk_db;
    if (o.wait_for_athlete) p.kiosk.wait_for_athlete = true;
#endif
#if defined(GS_HAVE_KIOSK)
    if (p.kiosk.on() && p.kiosk.wait_for_athlete && c.cap.backend != "file" && c.cap.backend != "keypoints") {
        std::fprintf(stderr, "gravscale: %s: [kiosk] wait_for_athlete holds a recorded source (file, keypoints), "
                     "not %s\n", o.config.c_str(), c.cap.backend.c_str());
        return EXIT_USAGE;
    }
#endif
    if ((o.kiosk_port >= 0 || !o.kiosk_db.empty() || o.wait_for_athlete) && !p.kiosk.on()) {
        std::fprintf(stderr, "gravscale: %s: --kiosk-port, --kiosk-db and --wait-for-athlete need a [kiosk] section%s\n",
                     o.config.c_str(),
#if defined(GS_HAVE_KIOSK)
                     ""
#else
                     " (and a gravscale built with the kiosk)"
#endif
        );
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

// ---- signals ----------------------------------------------------------------------

volatile sig_atomic_t g_stop = 0;
void on_stop_signal(int sig) { g_stop = sig; }

void install_signals()
{
    gs_sink_ignore_sigpipe();
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // no SA_RESTART: a blocking wait returns at once
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

// ---- the keypoint source (soak runs, recorded detector output) -----------------

class KeypointFeed {
public:
    ~KeypointFeed()
    {
        if (r_) gs_kpread_close(r_);
    }
    bool open(const std::string &path, bool realtime, std::string &err)
    {
        gs_kpread_opts o;
        gs_kpread_opts_default(&o);
        gs_kpread_error e;
        r_ = gs_kpread_open(path.c_str(), &o, &e);
        if (!r_) {
            err = e.text;
            return false;
        }
        realtime_ = realtime;
        return true;
    }
    gs_layout layout() const { return gs_kpread_layout(r_); }
    // frame / timeout / end / error, as a capture
    gs::ReadResult read(gs_kpframe &f, int timeout_ms, std::string &err)
    {
        if (!have_) {
            gs_kpread_error e;
            gs_kpr_status st = gs_kpread_next(r_, &next_, &e);
            if (st == GS_KPR_EOF) return gs::ReadResult::end;
            if (st != GS_KPR_FRAME) {
                err = e.text;
                return gs::ReadResult::error;
            }
            have_ = true;
        }
        if (realtime_) {
            double now = gs_sink_now_s();
            if (!started_) started_ = true, wall0_ = now, t0_ = next_.t_s;
            double due = wall0_ + (next_.t_s - t0_);
            if (due > now) {
                double wait = std::min(due - now, timeout_ms * 1e-3);
                std::this_thread::sleep_for(std::chrono::duration<double>(wait));
                if (gs_sink_now_s() < due) return gs::ReadResult::timeout;
            }
        }
        f = next_;
        have_ = false;
        frames_++;
        return gs::ReadResult::frame;
    }
    int64_t frames() const { return frames_; }

private:
    gs_kpread *r_ = nullptr;
    gs_kpframe next_;
    bool have_ = false, realtime_ = false, started_ = false;
    double wall0_ = 0.0, t0_ = 0.0;
    int64_t frames_ = 0;
};

// ---- events to sinks ------------------------------------------------------------------

struct Daemon {
    gs_sinkset sinks;
    gs_format fmt = GS_FMT_JSON;
    bool json_sinks = false;  // NMEA to the sinks, and JSON too for those that take only JSON (MQTT)
#if defined(GS_HAVE_KIOSK)
    std::unique_ptr<gs::kiosk::Kiosk> kiosk;  // every event as JSON, trace included
#endif
    bool kiosk_on() const
    {
#if defined(GS_HAVE_KIOSK)
        return kiosk != nullptr;
#else
        return false;
#endif
    }
    // one line to the sinks (json: its JSON form when the sinks' format is NMEA, or NULL) and the kiosk
    void write(const char *line, size_t n, const char *json, size_t jn)
    {
        if (line && n) gs_sinkset_write_pair(&sinks, line, n, json_sinks ? json : nullptr, jn);
#if defined(GS_HAVE_KIOSK)
        if (kiosk) {
            if (fmt == GS_FMT_JSON && line && n)
                kiosk->on_line(line, n);
            else if (json && jn)
                kiosk->on_line(json, jn);
        }
#endif
    }
    uint64_t jumps = 0, accepted = 0, summaries = 0, emit_fail = 0;
};

bool is_trace_event(gs_event_type t) { return t == GS_EV_STATE || t == GS_EV_SAMPLE || t == GS_EV_FIT; }

void on_event(void *ctx, const gs_event *ev)
{
    Daemon &d = *static_cast<Daemon *>(ctx);
    if (is_trace_event(ev->type)) {  // never to the sinks; the kiosk draws the track from them
        if (!d.kiosk_on()) return;
        char tb[GS_EMIT_MAX];
        size_t tn = gs_emit(GS_FMT_JSON, ev, tb, sizeof tb);
        if (tn) d.write(nullptr, 0, tb, tn);
        return;
    }
    // a track other than 0 that never had a flight (a distractor) gets no summary
    if (ev->type == GS_EV_SUMMARY && ev->u.height.track != 0 && ev->u.height.n_jumps == 0 &&
        ev->u.height.n_rejected == 0)
        return;
    if (ev->type == GS_EV_JUMP) {
        d.jumps++;
        d.accepted += ev->u.jump.accepted ? 1u : 0u;
    } else if (ev->type == GS_EV_SUMMARY) {
        d.summaries++;
    }
    char buf[GS_EMIT_MAX], jbuf[GS_EMIT_MAX];
    size_t n = gs_emit(d.fmt, ev, buf, sizeof buf);
    if (n == 0) {
        d.emit_fail++;
        return;
    }
    size_t jn = 0;
    if (d.fmt != GS_FMT_JSON && (d.json_sinks || d.kiosk_on())) jn = gs_emit(GS_FMT_JSON, ev, jbuf, sizeof jbuf);
    d.write(buf, n, jn ? jbuf : nullptr, jn);
}

// One core pipeline per tracked object.
class Pipelines {
public:
    Pipelines(const gs_core_config &cfg, gs_layout layout, Daemon &d) : cfg_(cfg), layout_(layout), d_(d) {}
    gs_pipeline *get(uint32_t track)
    {
        if (track >= kMaxTracks) return nullptr;
        while (pipes_.size() <= track) {
            auto tp = std::make_unique<Pipe>();
            size_t bytes = gs_pipeline_storage_bytes(&cfg_);
            tp->storage.assign(bytes / sizeof(double) + 1, 0.0);
            gs_status st = gs_pipeline_init(&tp->p, &cfg_, layout_, tp->storage.data(),
                                            tp->storage.size() * sizeof(double), on_event, &d_);
            if (st != GS_OK) {
                init_error = st;
                return nullptr;
            }
            gs_pipeline_set_track(&tp->p, static_cast<uint32_t>(pipes_.size()));
            if (d_.kiosk_on()) gs_pipeline_set_trace(&tp->p, true);
            pipes_.push_back(std::move(tp));
        }
        return &pipes_[track]->p;
    }
    void flush_all()
    {
        if (pipes_.empty()) get(0);  // nothing seen: a summary for track 0 with a null size
        for (auto &tp : pipes_) gs_pipeline_flush(&tp->p);
    }
    gs_status init_error = GS_OK;
    uint64_t refused = 0;

private:
    static constexpr uint32_t kMaxTracks = 64;
    struct Pipe {
        gs_pipeline p;
        std::vector<double> storage;  // doubles: aligned for the ring
    };
    gs_core_config cfg_;
    gs_layout layout_;
    Daemon &d_;
    std::vector<std::unique_ptr<Pipe>> pipes_;
};

// ---- status ----------------------------------------------------------------------------

struct Stats {
    int64_t frames = 0;
    uint64_t dropped = 0, dropped_seq = 0, dropped_time = 0, corrupt = 0;
    double t_source_s = NAN;
    const char *state = "starting";
};

uint8_t nmea_checksum(const char *body, size_t n)
{
    uint8_t c = 0;
    for (size_t i = 0; i < n; i++) c ^= static_cast<uint8_t>(body[i]);
    return c;
}

// the JSON status line into line[cap]; its length, 0 if it does not fit
size_t status_json(const Daemon &d, const Stats &s, double t_s, const char *fps_txt, const char *tsrc, char *line,
                   size_t cap)
{
    static char sinks[8192];
    if (!gs_sinkset_status_json(&d.sinks, sinks, sizeof sinks)) std::snprintf(sinks, sizeof sinks, "null");
    const char *fmt = "{\"event\":\"status\",\"t_s\":%.3f,\"state\":\"%s\",\"frames\":%lld,\"fps\":%s,"
                      "\"dropped\":%llu,\"dropped_seq\":%llu,\"dropped_time\":%llu,\"corrupt\":%llu,"
                      "\"t_source_s\":%s,\"jumps\":%llu,\"accepted\":%llu,\"sinks\":%s}\n";
    int n = 0;
    for (const char *sk : {static_cast<const char *>(sinks), "null"}) {  // many sinks: the line without their details
        n = std::snprintf(line, cap, fmt, t_s, s.state, static_cast<long long>(s.frames), fps_txt,
                          static_cast<unsigned long long>(s.dropped), static_cast<unsigned long long>(s.dropped_seq),
                          static_cast<unsigned long long>(s.dropped_time), static_cast<unsigned long long>(s.corrupt),
                          tsrc, static_cast<unsigned long long>(d.jumps), static_cast<unsigned long long>(d.accepted), sk);
        if (n > 0 && static_cast<size_t>(n) < cap) return static_cast<size_t>(n);
    }
    return 0;
}

void write_status(Daemon &d, const Stats &s, double t_s, double fps)
{
    char line[GS_SINK_LINE_MAX], json[GS_SINK_LINE_MAX];
    char fps_txt[32], tsrc[32];
    if (std::isfinite(fps))
        std::snprintf(fps_txt, sizeof fps_txt, "%.2f", fps);
    else
        std::snprintf(fps_txt, sizeof fps_txt, "null");
    if (std::isfinite(s.t_source_s))
        std::snprintf(tsrc, sizeof tsrc, "%.4f", s.t_source_s);
    else
        std::snprintf(tsrc, sizeof tsrc, "null");
    size_t n = 0, jn = 0;
    if (d.fmt == GS_FMT_NMEA) {
        char body[96];
        int b = std::snprintf(body, sizeof body, "GSSTS,%lld,%s,%llu,%s", static_cast<long long>(s.frames),
                              std::isfinite(fps) && fps < 1e6 ? fps_txt : "", static_cast<unsigned long long>(s.dropped), s.state);
        int w = std::snprintf(line, sizeof line, "$%s*%02X\r\n", body, nmea_checksum(body, static_cast<size_t>(b)));
        n = w > 0 && static_cast<size_t>(w) < sizeof line ? static_cast<size_t>(w) : 0;
        if (d.json_sinks || d.kiosk_on()) jn = status_json(d, s, t_s, fps_txt, tsrc, json, sizeof json);
    } else {
        n = status_json(d, s, t_s, fps_txt, tsrc, line, sizeof line);
    }
    if (n) d.write(line, n, jn ? json : nullptr, jn);
}

std::string kiosk_text(const KioskConfig &k)
{
#if defined(GS_HAVE_KIOSK)
    if (k.on())
        return ", kiosk on " + k.bind + ":" + std::to_string(k.port) + " with history in " + k.db +
               (k.wait_for_athlete ? ", waiting for an athlete" : "");
#endif
    (void)k;
    return "";
}

// ---- the run -----------------------------------------------------------------------------

int run(const Options &o)
{
    Profile prof;
    int rc = load_profile(o, prof);
    if (rc != EXIT_OK) return rc;
    const CamConfig &cc = prof.cam;
    if (o.check) {
        size_t n_sinks = 0;
        const gs_sink_switch *sw[] = {&prof.sinks.file_sw, &prof.sinks.serial_sw, &prof.sinks.tcp_sw,
                                      &prof.sinks.tcp_client_sw, &prof.sinks.udp_sw};
        for (const gs_sink_switch *x : sw) n_sinks += gs_sinks_config_on(x, false);
        n_sinks += gs_sinks_config_on(&prof.sinks.stdout_sw, true);
        n_sinks += gs_sinks_config_on(&prof.sinks.mqtt_sw, false);
        std::printf("%s: backend %s, device '%s', %dx%d, %g fps, pixel format %s, detector %s, format %s, "
                    "%zu sink(s), status every %g s%s\n",
                    o.config.c_str(), cc.cap.backend.c_str(), cc.cap.device.c_str(), cc.cap.width, cc.cap.height,
                    cc.cap.fps, cc.cap.pixel_format.c_str(), cc.detector.c_str(), gs_format_name(prof.core.format),
                    n_sinks, prof.sinks.status_interval_s, kiosk_text(prof.kiosk).c_str());
        return std::fflush(stdout) == 0 ? EXIT_OK : EXIT_IO;
    }
    install_signals();

    // the source
    const bool keypoints = cc.cap.backend == "keypoints";
    std::unique_ptr<gs::Capture> cap;
    KeypointFeed feed;
    std::unique_ptr<gs::Detector> det;
    gs_layout layout = GS_LAYOUT_POINT;
    std::string err;
    if (keypoints) {
        if (!feed.open(cc.cap.device, cc.cap.realtime, err)) {
            std::fprintf(stderr, "gravscale: %s\n", err.c_str());
            return EXIT_USAGE;
        }
        layout = feed.layout();
    } else {
        det = gs::make_detector(cc.detector, prof.det, err);
        if (!det) {
            std::fprintf(stderr, "gravscale: %s: %s\n", o.config.c_str(), err.c_str());
            return EXIT_USAGE;
        }
        layout = det->layout();
        gs::CaptureError kind;
        cap = gs::open_capture(cc.cap, err, kind);
        if (!cap) {
            std::fprintf(stderr, "gravscale: %s: %s\n", o.config.c_str(), err.c_str());
            return EXIT_USAGE;
        }
    }

    // the sinks
    Daemon d;
    d.fmt = prof.core.format;
    char serr[256];
    const double t0 = gs_sink_now_s();
    if (gs_sinkset_open_config(&d.sinks, &prof.sinks, t0, serr, sizeof serr) != 0) {
        std::fprintf(stderr, "gravscale: %s: %s\n", o.config.c_str(), serr);
        return EXIT_USAGE;
    }
    d.json_sinks = d.fmt != GS_FMT_JSON && gs_sinkset_wants_json(&d.sinks);
#if defined(GS_HAVE_KIOSK)
    if (prof.kiosk.on()) {
        d.kiosk = gs::kiosk::Kiosk::start(prof.kiosk, err);
        if (!d.kiosk) {
            std::fprintf(stderr, "gravscale: %s: %s\n", o.config.c_str(), err.c_str());
            gs_sinkset_close(&d.sinks);
            return EXIT_USAGE;
        }
        std::fprintf(stderr, "gravscale: cam: kiosk page on %s\n", d.kiosk->url().c_str());
    }
#endif
    for (size_t i = 0; i < d.sinks.n; i++) {
        uint16_t port = gs_sink_tcp_port(&d.sinks.sinks[i]);
        if (port) {
            gs_sink_info in;
            d.sinks.sinks[i].info(d.sinks.sinks[i].state, &in);
            std::string target = in.target;
            size_t colon = target.rfind(':');
            std::fprintf(stderr, "gravscale: cam: tcp sink listening on %s:%u\n",
                         target.substr(0, colon).c_str(), static_cast<unsigned>(port));
        }
    }
    if (cap) std::fprintf(stderr, "gravscale: cam: %s\n", cap->description().c_str());

    gs_event ev;
    std::memset(&ev, 0, sizeof ev);
    ev.type = GS_EV_START;
    ev.u.start.version = GS_VERSION;
    ev.u.start.config = o.config.c_str();
    ev.u.start.fps_source = cap && cap->fps() > 0.0 ? cap->fps() : NAN;
    ev.u.start.fps_origin = cap ? "capture" : "timestamps";
    ev.u.start.layout = gs_layout_name(layout);
    on_event(&d, &ev);

    Pipelines pipes(prof.core, layout, d);
    Stats st;
    st.state = "running";
    std::vector<gs::DetectorObs> obs;
    gs::CaptureFrame frame;
    gs_kpframe kf;
    const double interval = prof.sinks.status_interval_s;
    double next_status = interval > 0 ? t0 + interval : INFINITY;
    int64_t frames_at_status = 0;
    double t_at_status = t0, last_frame_wall = t0;
    int exit_rc = EXIT_OK;
    // a recorded source waits until the kiosk's operator names an athlete ([kiosk] wait_for_athlete)
    auto holding = [&]() {
#if defined(GS_HAVE_KIOSK)
        return d.kiosk && d.kiosk->holding();
#else
        return false;
#endif
    };
    while (!g_stop && holding()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(kStepMs));
        gs_sinkset_poll(&d.sinks, gs_sink_now_s());
    }
    bool source_ended = false;
    while (!g_stop) {
        gs::ReadResult r = keypoints ? feed.read(kf, kStepMs, err) : cap->read(frame, kStepMs);
        const double now = gs_sink_now_s();
        if (r == gs::ReadResult::end) {
            source_ended = true;
            break;
        }
        if (r == gs::ReadResult::error) {
            std::fprintf(stderr, "gravscale: %s\n", keypoints ? err.c_str() : cap->error().c_str());
            exit_rc = EXIT_SOURCE;
            break;
        }
        if (r == gs::ReadResult::frame) {
            last_frame_wall = now;
            if (keypoints) {
                st.frames = feed.frames();
                st.t_source_s = kf.t_s;
                gs_pipeline *p = pipes.get(0);
                gs_status ps = layout == GS_LAYOUT_POINT
                                   ? gs_pipeline_push_point(p, kf.t_s, kf.kp[0].x_px, kf.kp[0].y_px, kf.kp[0].c, kf.size_px)
                                   : gs_pipeline_push_keypoints(p, kf.t_s, kf.kp);
                if (ps != GS_OK) pipes.refused++;
            } else {
                st.frames = cap->frames();
                st.t_source_s = frame.t_s;
                st.dropped = cap->drops().dropped();
                st.dropped_seq = cap->drops().by_sequence();
                st.dropped_time = cap->drops().by_time();
                det->process(frame.bgr, frame.t_s, obs);
                // the driver's integer microseconds as they are; other sources' seconds rounded
                const int64_t t_us = frame.t_us != GS_T_NONE ? frame.t_us : gs_time_us_of_s(frame.t_s);
                for (const gs::DetectorObs &b : obs) {
                    gs_pipeline *p = pipes.get(static_cast<uint32_t>(b.track));
                    if (!p) {
                        pipes.refused++;
                        continue;
                    }
                    gs_status ps = layout == GS_LAYOUT_POINT
                                       ? gs_pipeline_push_point_us(p, t_us, static_cast<float>(b.x_px),
                                                                   static_cast<float>(b.y_px),
                                                                   static_cast<float>(b.confidence),
                                                                   static_cast<float>(b.size_px))
                                       : gs_pipeline_push_keypoints_us(p, t_us, b.kp.data());
                    if (ps != GS_OK) pipes.refused++;
                }
            }
        }
        if (cap) st.corrupt = cap->corrupt();
        gs_sinkset_poll(&d.sinks, now);
        if (now >= next_status) {
            // no frame for a second (and several intervals): the camera stalls
            double frame_gap = cap && cap->fps() > 0.0 ? 5.0 / cap->fps() : 0.0;
            st.state = now - last_frame_wall > std::max(1.0, frame_gap) ? "stalled" : "running";
            double fps = (st.frames - frames_at_status) / (now - t_at_status);
            write_status(d, st, now - t0, fps);
            frames_at_status = st.frames;
            t_at_status = now;
            next_status = now + interval;
        }
    }
    if (g_stop) std::fprintf(stderr, "gravscale: cam: %s: stopping\n", g_stop == SIGINT ? "SIGINT" : "SIGTERM");
    // the end: open flights and summaries out, a last status, then the sinks drained
    pipes.flush_all();
    st.state = "stopped";
    if (interval > 0) {
        double now = gs_sink_now_s();
        write_status(d, st, now - t0, (st.frames - frames_at_status) / std::max(1e-9, now - t_at_status));
    }
#if defined(GS_HAVE_KIOSK)
    if (d.kiosk) {  // the results stay on the page (a recorded clip ends in seconds) until a signal
        d.kiosk->source_ended();
        if (source_ended && !g_stop)
            std::fprintf(stderr, "gravscale: cam: the source ended; the kiosk page stays up until SIGINT/SIGTERM\n");
        while (source_ended && !g_stop) {
            std::this_thread::sleep_for(std::chrono::milliseconds(kStepMs));
            gs_sinkset_poll(&d.sinks, gs_sink_now_s());
        }
        if (source_ended && g_stop)
            std::fprintf(stderr, "gravscale: cam: %s: stopping\n", g_stop == SIGINT ? "SIGINT" : "SIGTERM");
        d.kiosk.reset();  // civetweb's stop takes about 1 s
    }
#endif
    uint64_t left = gs_sinkset_drain(&d.sinks, cc.drain_s);
    bool failed = false;
    for (size_t i = 0; i < d.sinks.n; i++) {
        gs_sink_info in;
        d.sinks.sinks[i].info(d.sinks.sinks[i].state, &in);
        if (in.state == GS_SINK_FAILED && (std::strcmp(in.kind, "stdout") == 0 || std::strcmp(in.kind, "file") == 0)) {
            failed = true;
            if (in.last_errno != EPIPE)
                std::fprintf(stderr, "gravscale: cam: %s %s failed: %s\n", in.kind, in.target, std::strerror(in.last_errno));
        }
    }
    if (left) std::fprintf(stderr, "gravscale: cam: %llu lines still queued at exit\n", static_cast<unsigned long long>(left));
    if (pipes.refused)
        std::fprintf(stderr, "gravscale: cam: %llu observations refused by the pipeline\n",
                     static_cast<unsigned long long>(pipes.refused));
    if (d.emit_fail)
        std::fprintf(stderr, "gravscale: cam: %llu events could not be formatted\n", static_cast<unsigned long long>(d.emit_fail));
    std::fprintf(stderr, "gravscale: cam: %lld frames, %llu dropped, %llu flights (%llu accepted)\n",
                 static_cast<long long>(st.frames), static_cast<unsigned long long>(st.dropped),
                 static_cast<unsigned long long>(d.jumps), static_cast<unsigned long long>(d.accepted));
    gs_sinkset_close(&d.sinks);
    cap.reset();
    if (exit_rc != EXIT_OK) return exit_rc;
    return failed ? EXIT_IO : EXIT_OK;
}

}  // namespace

extern "C" int gs_cmd_cam(int argc, char **argv)
{
    Options o;
    int rc = parse_args(argc, argv, o);
    if (rc >= 0) return rc;
    try {
        return run(o);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "gravscale: cam: %s\n", e.what());
        return EXIT_SOURCE;
    }
}
