// frame_source.hpp - frames with real-time timestamps from a video file (any
// container FFmpeg reads) or an image sequence (a folder of images or a printf
// pattern such as frames/%05d.png).
//
// Times: a video's frames carry the stream's presentation times
// (CAP_PROP_POS_MSEC). A time that does not increase (Debian's OpenCV 4.6
// reports 0 for the frames an H.264 decoder drains at the end) is repaired to
// the previous time plus one nominal frame interval. Slow-motion phone clips
// store e.g. 120 fps capture as a 30 fps stream; the true rate comes from
// --fps N (origin "cli") or the metadata tag com.android.capture.fps (origin
// "metadata"), and every stream time is then scaled by stream_rate / true_rate
// so gaps keep their proportion. Otherwise the rate is the container's
// ("container") or, when it has none, the median interval of the first
// presentation times ("timestamps"). An image sequence needs --fps (t = i / N).
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace gs {

struct FrameSourceOptions {
    double fps = 0.0;  // --fps: the true frame rate; 0 = not given
    int decode_threads = 0;  // a video's decoding threads; 0: one per CPU
};

// What the probe learns from the container (libavformat), before decoding.
struct StreamProbe {
    double avg_fps = 0.0;         // stream's average rate (0 unknown)
    double r_fps = 0.0;           // stream's base rate (0 unknown)
    double capture_fps = 0.0;     // com.android.capture.fps (0 absent)
    int64_t n_frames = 0;         // frames the container announces (0 unknown)
    double duration_s = 0.0;      // 0 unknown
    int width = 0, height = 0;
    double sample_aspect = 0.0;   // a pixel's width / height as the container states it (0 not stated)
    std::string codec;            // decoder name
};

// Reads the container of a video file with libavformat. false with a reason
// (no video stream, not a format FFmpeg reads, ...) in err.
bool probe_video(const std::string &path, StreamProbe &out, std::string &err);

struct Frame {
    cv::Mat bgr;             // 8-bit BGR
    int64_t index = 0;       // 0-based decode order
    double t_s = 0.0;        // real time, seconds (scaled, repaired)
    double t_stream_s = 0.0; // the stream's own time (before scaling)
    bool t_repaired = false; // the stream's time did not increase: extrapolated
};

class FrameSource {
public:
    enum class Error { none, missing, unreadable, usage };

    // nullptr on failure, with err (one line, without the file name) and kind.
    static std::unique_ptr<FrameSource> open(const std::string &path,
                                             const FrameSourceOptions &opt,
                                             std::string &err, Error &kind);
    virtual ~FrameSource();

    // The next frame; false at the end of the stream (error() tells a decode
    // failure of an image apart from the end).
    bool next(Frame &f);

    double fps() const { return fps_; }                 // true frame rate used
    const char *fps_origin() const { return origin_; }  // "cli", "metadata", "container", "timestamps"
    double stream_fps() const { return stream_fps_; }   // the stored stream's rate
    double time_scale() const { return scale_; }        // t = t_stream * time_scale
    double capture_fps_tag() const { return probe_.capture_fps; }
    double sample_aspect() const { return probe_.sample_aspect; }  // 0: not stated
    int64_t frames_announced() const { return probe_.n_frames; }
    int64_t frames_read() const { return n_read_; }
    int64_t times_repaired() const { return n_repaired_; }
    bool is_image_sequence() const { return images_; }
    const char *decoder() const { return decoder_; }   // "libavcodec", "opencv" or "images"
    cv::Size size() const { return size_; }
    const std::string &error() const { return error_; }

protected:
    FrameSource() = default;
    // one raw frame in decode order with the stream's time (NaN = none); false at the end
    virtual bool read_raw(cv::Mat &bgr, double &t_stream_s) = 0;
    // Decode up to n frames ahead (kept for next()) and return the rate from
    // the median interval of their stream times; 0 when they give none.
    double rate_from_first_times(size_t n);

    StreamProbe probe_;
    double fps_ = 0.0, stream_fps_ = 0.0, scale_ = 1.0;
    const char *origin_ = "container";
    const char *decoder_ = "images";
    bool images_ = false;
    cv::Size size_;
    std::string error_;

private:

    struct Raw {
        cv::Mat bgr;
        double t;
    };
    // the frames' buffers, handed out again once every frame made in them is let go
    cv::Mat spare_buffer();
    void keep_buffer(const cv::Mat &m);
    std::vector<cv::Mat> buffers_;
    std::deque<Raw> prefetch_;
    bool eof_ = false;
    int64_t n_read_ = 0, n_repaired_ = 0;
    double last_t_stream_ = 0.0;
};

// Files of an image sequence in order: a folder's images (names compared
// with digit runs as numbers), or a printf pattern tried from index 0 and 1.
std::vector<std::string> list_image_sequence(const std::string &path);

}  // namespace gs
