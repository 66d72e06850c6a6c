// capture.cpp - the capture interface, drop counting, the GStreamer and file
// sources, and the backend switch.
#include "capture.hpp"

#include <chrono>
#include <cmath>
#include <thread>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "capture_libcamera.hpp"
#include "capture_v4l2.hpp"
#include "frame_source.hpp"

namespace gs {

Capture::~Capture() = default;

void Capture::deliver(CaptureFrame &f, double t_s, int64_t seq, int64_t t_us)
{
    f.t_s = t_s;
    f.t_us = t_us;
    f.sequence = seq;
    f.index = frames_++;
    drops_.frame(t_s, seq);
}

// ---- drops ------------------------------------------------------------------

void DropCounter::reset(double nominal_interval_s)
{
    *this = DropCounter();
    interval_s_ = nominal_interval_s > 0.0 ? nominal_interval_s : 0.0;
    learnt_ = interval_s_ > 0.0;
}

void DropCounter::frame(double t_s, int64_t seq)
{
    if (have_) {
        if (seq >= 0 && last_seq_ >= 0 && seq > last_seq_ + 1) seq_drops_ += static_cast<uint64_t>(seq - last_seq_ - 1);
        const double dt = t_s - last_t_;
        if (!learnt_) {
            // no nominal rate: the first positive interval, then the smallest seen
            if (dt > 0.0 && (interval_s_ == 0.0 || dt < interval_s_)) interval_s_ = dt;
        } else if (dt > 1.5 * interval_s_) {
            // a gap of k intervals hides k - 1 frames
            ts_drops_ += static_cast<uint64_t>(std::lround(dt / interval_s_)) - 1u;
        }
        if (!learnt_ && interval_s_ > 0.0 && ++n_intervals_ >= 8) learnt_ = true;
    }
    have_ = true;
    last_t_ = t_s;
    if (seq >= 0) last_seq_ = seq;
}

namespace {

// ---- GStreamer through OpenCV ---------------------------------------------------

class GstCapture : public Capture {
public:
    bool start(const CaptureConfig &cfg, std::string &err, CaptureError &kind)
    {
        kind = CaptureError::device;
        pipeline_ = cfg.device;
        if (pipeline_.find("appsink") == std::string::npos) {
            err = "gstreamer: the pipeline must end in appsink: '" + pipeline_ + "'";
            kind = CaptureError::usage;
            return false;
        }
        if (cv::videoio_registry::hasBackend(cv::CAP_GSTREAMER) == false) {
            err = "gstreamer: this OpenCV has no GStreamer support";
            return false;
        }
        cv::utils::logging::LogLevel old = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
        bool ok = cap_.open(pipeline_, cv::CAP_GSTREAMER);
        cv::utils::logging::setLogLevel(old);
        if (!ok) {
            err = "gstreamer: cannot start the pipeline '" + pipeline_ + "' (a missing element or plugin?)";
            return false;
        }
        fps_ = cap_.get(cv::CAP_PROP_FPS);
        if (!(fps_ > 0.0 && fps_ < 100000.0)) fps_ = cfg.fps > 0.0 ? cfg.fps : 0.0;
        size_ = cv::Size(static_cast<int>(cap_.get(cv::CAP_PROP_FRAME_WIDTH)),
                         static_cast<int>(cap_.get(cv::CAP_PROP_FRAME_HEIGHT)));
        drops_.reset(fps_ > 0.0 ? 1.0 / fps_ : 0.0);
        by_position_ = cfg.gst_time == "position";
        if (!by_position_ && cfg.gst_time != "count") {
            err = "gstreamer: timestamps must be count or position, not '" + cfg.gst_time + "'";
            kind = CaptureError::usage;
            return false;
        }
        if (!by_position_ && !(fps_ > 0.0)) {
            err = "gstreamer: the pipeline gives no frame rate: set fps in the caps or use timestamps = position";
            kind = CaptureError::usage;
            return false;
        }
        time_origin_ = by_position_ ? "position" : "count";
        char line[128];
        std::snprintf(line, sizeof line, "gstreamer: %dx%d %.3g fps: ", size_.width, size_.height, fps_);
        desc_ = line + pipeline_;
        return true;
    }

    // A blocking read (appsink gives no descriptor to poll): at the pipeline's
    // rate it returns within one frame interval.
    ReadResult read(CaptureFrame &f, int) override
    {
        if (!cap_.isOpened()) return ReadResult::end;
        cv::utils::logging::LogLevel old = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
        bool ok = cap_.read(f.bgr);
        double pos_ms = ok && by_position_ ? cap_.get(cv::CAP_PROP_POS_MSEC) : NAN;
        cv::utils::logging::setLogLevel(old);
        if (!ok || f.bgr.empty()) {
            cap_.release();
            return ReadResult::end;
        }
        double t;
        if (by_position_) {
            // the position when read, kept increasing (a repeated value gets +1 us)
            t = pos_ms * 1e-3;
            if (!std::isfinite(t)) t = last_t_;
            if (frames_ > 0 && !(t > last_t_)) t = last_t_ + 1e-6;
        } else {
            t = static_cast<double>(frames_) / (fps_ > 0.0 ? fps_ : 30.0);
        }
        last_t_ = t;
        deliver(f, t, -1);
        return ReadResult::frame;
    }

private:
    std::string pipeline_;
    cv::VideoCapture cap_;
    double last_t_ = 0.0;
    bool by_position_ = false;
};

// ---- a file (reuses FrameSource: repaired stream times) ---------------------------

class FileCapture : public Capture {
public:
    bool start(const CaptureConfig &cfg, std::string &err, CaptureError &kind)
    {
        FrameSourceOptions fo;
        fo.fps = 0.0;
        FrameSource::Error k;
        src_ = FrameSource::open(cfg.device, fo, err, k);
        if (!src_) {
            err = "file " + cfg.device + ": " + err;
            kind = k == FrameSource::Error::usage ? CaptureError::usage : CaptureError::device;
            return false;
        }
        realtime_ = cfg.realtime;
        fps_ = src_->fps();
        size_ = src_->size();
        drops_.reset(fps_ > 0.0 ? 1.0 / fps_ : 0.0);
        time_origin_ = "stream";
        char line[96];
        std::snprintf(line, sizeof line, ": %dx%d %.4g fps (%s)%s", size_.width, size_.height, fps_, src_->fps_origin(),
                      realtime_ ? ", real speed" : ", as fast as possible");
        desc_ = "file " + cfg.device + line;
        return true;
    }

    ReadResult read(CaptureFrame &f, int timeout_ms) override
    {
        if (!have_next_) {
            if (!src_->next(next_)) {
                if (!src_->error().empty()) {
                    error_ = "file: " + src_->error();
                    return ReadResult::error;
                }
                return ReadResult::end;
            }
            have_next_ = true;
        }
        if (realtime_) {
            // pace: frame k leaves at wall0 + (t_k - t_first)
            const auto now = std::chrono::steady_clock::now();
            if (!started_) {
                started_ = true;
                wall0_ = now;
                t_first_ = next_.t_s;
            }
            const auto due = wall0_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                          std::chrono::duration<double>(next_.t_s - t_first_));
            if (due > now) {
                const auto wait = std::min<std::chrono::steady_clock::duration>(due - now, std::chrono::milliseconds(timeout_ms));
                std::this_thread::sleep_for(wait);
                if (std::chrono::steady_clock::now() < due) return ReadResult::timeout;
            }
        }
        have_next_ = false;
        f.bgr = next_.bgr;
        deliver(f, next_.t_s, -1);
        return ReadResult::frame;
    }

private:
    std::unique_ptr<FrameSource> src_;
    Frame next_;
    bool have_next_ = false, realtime_ = true, started_ = false;
    std::chrono::steady_clock::time_point wall0_;
    double t_first_ = 0.0;
};

}  // namespace

std::unique_ptr<Capture> open_capture(const CaptureConfig &cfg, std::string &err, CaptureError &kind)
{
    kind = CaptureError::none;
    if (cfg.backend == "v4l2") return open_v4l2(cfg, system_v4l2_io(), err, kind);
    if (cfg.backend == "libcamera") return open_libcamera(cfg, err, kind);
    if (cfg.backend == "gstreamer") {
        auto c = std::make_unique<GstCapture>();
        if (!c->start(cfg, err, kind)) return nullptr;
        return c;
    }
    if (cfg.backend == "file") {
        auto c = std::make_unique<FileCapture>();
        if (!c->start(cfg, err, kind)) return nullptr;
        return c;
    }
    err = "backend must be v4l2, libcamera, gstreamer or file, not '" + cfg.backend + "'";
    kind = CaptureError::usage;
    return nullptr;
}

}  // namespace gs
