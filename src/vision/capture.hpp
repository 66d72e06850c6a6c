// capture.hpp - live frames for `gravscale cam`: one interface over V4L2
// (directly, through a replaceable device layer), libcamera, any OpenCV/GStreamer
// pipeline string and a video file (at real speed or as fast as possible).
//
// Times are the source's own: the V4L2 buffer timestamp (CLOCK_MONOTONIC when
// the driver says so), libcamera's SensorTimestamp, the GStreamer pipeline
// position, the file's stream time. Never the wall clock at read time.
// Dropped frames are counted from sequence-number gaps (V4L2, libcamera) and
// from timestamp gaps longer than 1.5 nominal intervals (every source).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace gs {

struct CaptureFrame {
    cv::Mat bgr;            // 8-bit BGR (owned: valid after the next read)
    double t_s = 0.0;       // the source's timestamp, seconds
    int64_t t_us = INT64_MIN;  // the same in whole microseconds where the source counts in
                               // integers (V4L2, libcamera), INT64_MIN (GS_T_NONE) otherwise
    int64_t index = 0;      // 0-based count of delivered frames
    int64_t sequence = -1;  // driver sequence number, -1 when the source has none
};

// Counts frames lost between delivered ones.
class DropCounter {
public:
    // nominal_interval_s <= 0: learnt from the first regular intervals
    void reset(double nominal_interval_s);
    // One delivered frame: t_s (seconds), seq (-1 when unknown).
    void frame(double t_s, int64_t seq);
    uint64_t by_sequence() const { return seq_drops_; }
    uint64_t by_time() const { return ts_drops_; }
    // frames lost: the larger of the two evidences
    uint64_t dropped() const { return seq_drops_ > ts_drops_ ? seq_drops_ : ts_drops_; }
    double interval_s() const { return interval_s_; }

private:
    double interval_s_ = 0.0, last_t_ = 0.0;
    int64_t last_seq_ = -1;
    uint32_t n_intervals_ = 0;
    bool have_ = false, learnt_ = false;
    uint64_t seq_drops_ = 0, ts_drops_ = 0;
};

struct CaptureConfig {
    std::string backend = "v4l2";   // v4l2 | libcamera | gstreamer | file
    std::string device = "/dev/video0";  // device path, camera id or index, pipeline string, file path
    int width = 640, height = 480;  // requested; the driver may give another size
    double fps = 30.0;              // requested
    std::string pixel_format = "auto";  // auto | mjpeg | yuyv (V4L2, libcamera)
    unsigned buffers = 4;           // V4L2 mmap buffers / libcamera requests
    bool realtime = true;           // file: pace frames at their stream times
    // gstreamer: "count" = frame count / fps (exact while no frame is lost; a
    // lost frame is invisible), "position" = the pipeline position when the
    // frame is read (OpenCV 4.6 exposes no buffer PTS; frames queued in
    // appsink under load get nearly equal times)
    std::string gst_time = "count";
};

enum class ReadResult { frame, timeout, end, error };

class Capture {
public:
    virtual ~Capture();
    // Wait up to timeout_ms for the next frame. frame: f is filled; timeout:
    // nothing yet; end: the source ended (a file, a finite pipeline); error:
    // the device failed or went away (error() says why).
    virtual ReadResult read(CaptureFrame &f, int timeout_ms) = 0;
    // "v4l2 /dev/video0: 640x480 MJPG 30 fps (driver timestamps, monotonic)"
    const std::string &description() const { return desc_; }
    const std::string &error() const { return error_; }
    double fps() const { return fps_; }           // the rate in force (0 unknown)
    cv::Size size() const { return size_; }
    // where t_s comes from: "driver", "sensor", "position", "count", "stream"
    const char *time_origin() const { return time_origin_; }
    int64_t frames() const { return frames_; }
    uint64_t corrupt() const { return corrupt_; }  // frames delivered but undecodable (skipped)
    const DropCounter &drops() const { return drops_; }

protected:
    // bookkeeping for one delivered frame (t_us: the source's integer time, if any)
    void deliver(CaptureFrame &f, double t_s, int64_t seq, int64_t t_us = INT64_MIN);
    std::string desc_, error_;
    double fps_ = 0.0;
    cv::Size size_;
    const char *time_origin_ = "driver";
    int64_t frames_ = 0;
    uint64_t corrupt_ = 0;
    DropCounter drops_;
};

// What kind of failure open_capture met: usage (bad settings) or the device
// (missing, busy, not a camera).
enum class CaptureError { none, usage, device };

// nullptr on failure with one line in err (without a "gravscale:" prefix).
std::unique_ptr<Capture> open_capture(const CaptureConfig &cfg, std::string &err, CaptureError &kind);

// Whether this build has libcamera.
bool have_libcamera();

}  // namespace gs
