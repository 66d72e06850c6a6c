// frame_source.cpp - video files through OpenCV's FFmpeg backend (timestamps,
// repaired) and libavformat (container rate, capture-fps tag); image sequences.
#include "frame_source.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
}

namespace fs = std::filesystem;

namespace gs {

namespace {

constexpr double kMaxFps = 100000.0;
constexpr size_t kRatePrefetch = 16;  // frames whose times give the rate when the container has none

bool plausible_fps(double f) { return std::isfinite(f) && f >= 0.01 && f <= kMaxFps; }

std::string av_err_text(int code)
{
    char buf[AV_ERROR_MAX_STRING_SIZE] = {0};
    av_strerror(code, buf, sizeof buf);
    return buf;
}

std::string lower(std::string s)
{
    for (char &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

bool is_image_name(const std::string &name)
{
    static const char *const exts[] = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff",
                                       ".webp", ".pgm", ".ppm", ".pnm", ".exr", ".jp2"};
    std::string l = lower(name);
    for (const char *e : exts) {
        size_t n = std::strlen(e);
        if (l.size() > n && l.compare(l.size() - n, n, e) == 0) return true;
    }
    return false;
}

// Names compared with runs of digits as numbers: img2 < img10.
bool natural_less(const std::string &a, const std::string &b)
{
    size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        unsigned char ca = static_cast<unsigned char>(a[i]), cb = static_cast<unsigned char>(b[j]);
        if (std::isdigit(ca) && std::isdigit(cb)) {
            size_t i2 = i, j2 = j;
            while (i2 < a.size() && a[i2] == '0') i2++;
            while (j2 < b.size() && b[j2] == '0') j2++;
            size_t ie = i2, je = j2;
            while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ie++;
            while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) je++;
            if (ie - i2 != je - j2) return ie - i2 < je - j2;
            int c = a.compare(i2, ie - i2, b, j2, je - j2);
            if (c != 0) return c < 0;
            i = ie;
            j = je;
            continue;
        }
        if (ca != cb) return ca < cb;
        i++;
        j++;
    }
    return a.size() - i < b.size() - j;
}

void quiet_libraries()
{
    static bool done = false;
    if (done) return;
    done = true;
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    av_log_set_level(AV_LOG_QUIET);
}

double median(std::vector<double> v)
{
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    size_t m = v.size();
    return m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
}

// ---- video file -------------------------------------------------------------

class VideoFileSource : public FrameSource {
public:
    bool init(const std::string &path, const FrameSourceOptions &opt, std::string &err)
    {
        if (!probe_video(path, probe_, err)) return false;
        // OpenCV keeps its own FFmpeg state and may reset the log level: quiet it again
        cap_.open(path, cv::CAP_FFMPEG);
        av_log_set_level(AV_LOG_QUIET);
        if (!cap_.isOpened()) {
            err = "cannot decode the video stream (codec " + probe_.codec + ")";
            return false;
        }
        size_ = cv::Size(probe_.width, probe_.height);
        if (plausible_fps(probe_.avg_fps)) {
            stream_fps_ = probe_.avg_fps;
            origin_ = "container";
        } else if (plausible_fps(probe_.r_fps)) {
            stream_fps_ = probe_.r_fps;
            origin_ = "container";
        } else {
            stream_fps_ = rate_from_first_times(kRatePrefetch);
            origin_ = "timestamps";
        }
        fps_ = stream_fps_;
        scale_ = 1.0;
        double true_fps = 0.0;
        if (opt.fps > 0.0) {
            true_fps = opt.fps;
            origin_ = "cli";
        } else if (plausible_fps(probe_.capture_fps)) {
            true_fps = probe_.capture_fps;
            origin_ = "metadata";
        }
        if (true_fps > 0.0) {
            fps_ = true_fps;
            scale_ = plausible_fps(stream_fps_) ? stream_fps_ / true_fps : 1.0;
        }
        return true;
    }

protected:
    bool read_raw(cv::Mat &bgr, double &t) override
    {
        if (!cap_.read(bgr) || bgr.empty()) return false;
        double ms = cap_.get(cv::CAP_PROP_POS_MSEC);
        t = std::isfinite(ms) ? ms * 1e-3 : NAN;
        return true;
    }

private:
    cv::VideoCapture cap_;
};

// ---- image sequence ------------------------------------------------------------

class ImageSequenceSource : public FrameSource {
public:
    bool init(std::vector<std::string> files, const FrameSourceOptions &opt, std::string &err)
    {
        files_ = std::move(files);
        if (files_.empty()) {
            err = "no images found (a folder of .png/.jpg/... files or a pattern like frames/%05d.png)";
            return false;
        }
        if (!(opt.fps > 0.0)) {
            err = "an image sequence needs --fps N (its frames carry no times)";
            return false;
        }
        images_ = true;
        fps_ = stream_fps_ = opt.fps;
        origin_ = "cli";
        scale_ = 1.0;
        probe_.n_frames = static_cast<int64_t>(files_.size());
        probe_.codec = "images";
        return true;
    }

protected:
    bool read_raw(cv::Mat &bgr, double &t) override
    {
        if (next_ >= files_.size()) return false;
        const std::string &f = files_[next_];
        bgr = cv::imread(f, cv::IMREAD_COLOR);
        if (bgr.empty()) {
            error_ = f + ": cannot decode the image";
            return false;
        }
        if (size_.width == 0) size_ = bgr.size();
        if (bgr.size() != size_) {
            error_ = f + ": image size differs from the first image";
            bgr.release();
            return false;
        }
        t = static_cast<double>(next_) / fps_;
        next_++;
        return true;
    }

private:
    std::vector<std::string> files_;
    size_t next_ = 0;
};

}  // namespace

// ---- FrameSource ----------------------------------------------------------------

FrameSource::~FrameSource() = default;

// at most this many buffers are kept: the frames in flight between the stages
constexpr size_t kMaxBuffers = 8;

cv::Mat FrameSource::spare_buffer()
{
    // only this list holds it: no frame made in it is still in use (other threads drop theirs atomically)
    for (const cv::Mat &m : buffers_)
        if (m.u && __atomic_load_n(&m.u->refcount, __ATOMIC_ACQUIRE) == 1) return m;
    return cv::Mat();
}

void FrameSource::keep_buffer(const cv::Mat &m)
{
    if (!m.u) return;
    for (const cv::Mat &b : buffers_)
        if (b.u == m.u) return;
    for (cv::Mat &b : buffers_) {
        if (__atomic_load_n(&b.u->refcount, __ATOMIC_ACQUIRE) == 1) {  // one the reader did not write into
            b = m;
            return;
        }
    }
    if (buffers_.size() < kMaxBuffers) buffers_.push_back(m);
}

double FrameSource::rate_from_first_times(size_t n)
{
    while (prefetch_.size() < n && !eof_) {
        Raw r;
        r.bgr = spare_buffer();
        bool ok = read_raw(r.bgr, r.t);
        keep_buffer(r.bgr);
        if (!ok) {
            eof_ = true;
            break;
        }
        prefetch_.push_back(std::move(r));
    }
    std::vector<double> d;
    for (size_t i = 1; i < prefetch_.size(); i++) {
        double dt = prefetch_[i].t - prefetch_[i - 1].t;
        if (std::isfinite(dt) && dt > 0.0) d.push_back(dt);
    }
    double m = median(d);
    return std::isfinite(m) && m > 0.0 && plausible_fps(1.0 / m) ? 1.0 / m : 0.0;
}

bool FrameSource::next(Frame &f)
{
    Raw r;
    if (!prefetch_.empty()) {
        r = std::move(prefetch_.front());
        prefetch_.pop_front();
    } else {
        if (eof_) return false;
        r.bgr = spare_buffer();
        bool ok = read_raw(r.bgr, r.t);
        keep_buffer(r.bgr);
        if (!ok) {
            eof_ = true;
            return false;
        }
    }
    f.index = n_read_;
    f.t_repaired = false;
    double t = r.t;
    if (n_read_ > 0 && !(std::isfinite(t) && t > last_t_stream_)) {
        // Decoders draining delayed frames report 0: one nominal interval on
        double dt = plausible_fps(stream_fps_) ? 1.0 / stream_fps_ : 1.0 / 30.0;
        t = last_t_stream_ + dt;
        f.t_repaired = true;
        n_repaired_++;
    } else if (n_read_ == 0 && !std::isfinite(t)) {
        t = 0.0;
    }
    last_t_stream_ = t;
    f.t_stream_s = t;
    f.t_s = t * scale_;
    f.bgr = std::move(r.bgr);
    n_read_++;
    return true;
}

bool probe_video(const std::string &path, StreamProbe &out, std::string &err)
{
    quiet_libraries();
    out = StreamProbe();
    AVFormatContext *ic = nullptr;
    int rc = avformat_open_input(&ic, path.c_str(), nullptr, nullptr);
    if (rc < 0) {
        err = "not a video FFmpeg can read (" + av_err_text(rc) + ")";
        return false;
    }
    rc = avformat_find_stream_info(ic, nullptr);
    if (rc < 0) {
        err = "cannot read the stream information (" + av_err_text(rc) + ")";
        avformat_close_input(&ic);
        return false;
    }
    int vs = av_find_best_stream(ic, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    if (vs < 0) {
        err = "no video stream in the file";
        avformat_close_input(&ic);
        return false;
    }
    const AVStream *st = ic->streams[vs];
    if (st->avg_frame_rate.den > 0 && st->avg_frame_rate.num > 0) out.avg_fps = av_q2d(st->avg_frame_rate);
    if (st->r_frame_rate.den > 0 && st->r_frame_rate.num > 0) out.r_fps = av_q2d(st->r_frame_rate);
    out.n_frames = st->nb_frames > 0 ? st->nb_frames : 0;
    if (st->duration != AV_NOPTS_VALUE && st->duration > 0)
        out.duration_s = static_cast<double>(st->duration) * av_q2d(st->time_base);
    else if (ic->duration != AV_NOPTS_VALUE && ic->duration > 0)
        out.duration_s = static_cast<double>(ic->duration) / AV_TIME_BASE;
    out.width = st->codecpar->width;
    out.height = st->codecpar->height;
    out.codec = avcodec_get_name(st->codecpar->codec_id);
    // the pixels' shape: the stream's or the codec's sample aspect ratio (0/1 when not stated)
    AVRational sar = av_guess_sample_aspect_ratio(ic, const_cast<AVStream *>(st), nullptr);
    if (sar.num > 0 && sar.den > 0) out.sample_aspect = av_q2d(sar);
    // Android writes the capture rate of slow motion into the container's metadata
    const AVDictionary *dicts[] = {st->metadata, ic->metadata};
    for (const AVDictionary *d : dicts) {
        const AVDictionaryEntry *e = av_dict_get(d, "com.android.capture.fps", nullptr, 0);
        if (e && e->value) {
            char *end = nullptr;
            errno = 0;
            double v = std::strtod(e->value, &end);
            if (end != e->value && errno == 0 && plausible_fps(v)) {
                out.capture_fps = v;
                break;
            }
        }
    }
    avformat_close_input(&ic);
    if (out.width <= 0 || out.height <= 0) {
        err = "the video stream has no picture size";
        return false;
    }
    return true;
}

std::vector<std::string> list_image_sequence(const std::string &path)
{
    std::vector<std::string> files;
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        std::vector<std::string> names;
        for (const auto &e : fs::directory_iterator(path, ec)) {
            std::error_code ec2;
            if (!e.is_regular_file(ec2)) continue;
            std::string name = e.path().filename().string();
            if (is_image_name(name)) names.push_back(name);
        }
        std::sort(names.begin(), names.end(), natural_less);
        for (const auto &n : names) files.push_back((fs::path(path) / n).string());
        return files;
    }
    if (path.find('%') == std::string::npos) return files;
    for (int start = 0; start <= 1 && files.empty(); start++) {
        for (int i = start;; i++) {
            std::vector<char> buf(path.size() + 64);
            int n = std::snprintf(buf.data(), buf.size(), path.c_str(), i);
            if (n < 0 || static_cast<size_t>(n) >= buf.size()) break;
            std::string f(buf.data());
            if (!fs::is_regular_file(f, ec)) break;
            files.push_back(f);
        }
    }
    return files;
}

std::unique_ptr<FrameSource> FrameSource::open(const std::string &path, const FrameSourceOptions &opt,
                                               std::string &err, Error &kind)
{
    quiet_libraries();
    kind = Error::none;
    err.clear();
    if (opt.fps != 0.0 && !(opt.fps > 0.0 && opt.fps <= kMaxFps)) {
        kind = Error::usage;
        err = "--fps must be a positive frame rate";
        return nullptr;
    }
    std::error_code ec;
    bool exists = fs::exists(path, ec);
    bool pattern = !exists && path.find('%') != std::string::npos;
    if (!exists && !pattern) {
        kind = Error::missing;
        err = "no such file";
        return nullptr;
    }
    if (pattern || fs::is_directory(path, ec)) {
        auto src = std::make_unique<ImageSequenceSource>();
        if (!src->init(list_image_sequence(path), opt, err)) {
            kind = opt.fps > 0.0 ? Error::unreadable : Error::usage;
            return nullptr;
        }
        return src;
    }
    if (is_image_name(path)) {
        kind = Error::usage;
        err = "one image is not a sequence: give its folder or a pattern like frames/%05d.png";
        return nullptr;
    }
    if (fs::is_regular_file(path, ec) && fs::file_size(path, ec) == 0) {
        kind = Error::unreadable;
        err = "empty file";
        return nullptr;
    }
    auto src = std::make_unique<VideoFileSource>();
    if (!src->init(path, opt, err)) {
        kind = Error::unreadable;
        return nullptr;
    }
    return src;
}

}  // namespace gs
