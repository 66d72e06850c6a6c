// frame_source.cpp - video files decoded by libavcodec into the frame's own
// buffer (OpenCV's FFmpeg backend for what that path does not reproduce:
// rotated streams, other pixel formats), the stream's times repaired, the
// container's rate and capture-fps tag from libavformat; image sequences.
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
#include <libavutil/display.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libswscale/swscale.h>
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

// libavcodec straight into the frame's buffer: the frames and times of
// cv::VideoCapture (OpenCV 4.6's FFmpeg backend: the packet's decoding time as
// the frame's, 0 when it has none; BGR by sws_scale with SWS_BICUBIC) without
// its copy of every frame, with as many decoding threads as asked (1: all in
// the caller's thread, the least CPU a frame). Only where that is the same
// path: 4:2:0 pictures of the stream's own size, a width of whole 8-pixel
// blocks, no rotation to apply; anything else goes through OpenCV.
class AvDecoder {
public:
    ~AvDecoder()
    {
        sws_freeContext(sws_);
        av_packet_free(&pkt_);
        av_frame_free(&pic_);
        avcodec_free_context(&ctx_);
        avformat_close_input(&ic_);
    }

    // false: this path does not apply (the caller falls back to OpenCV)
    bool open(const std::string &path, int threads)
    {
        if (avformat_open_input(&ic_, path.c_str(), nullptr, nullptr) < 0) return false;
        if (avformat_find_stream_info(ic_, nullptr) < 0) return false;
        for (unsigned i = 0; i < ic_->nb_streams && vs_ < 0; i++)
            if (ic_->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_VIDEO) vs_ = static_cast<int>(i);
        if (vs_ < 0) return false;
        AVStream *st = ic_->streams[vs_];
        const uint8_t *dm = av_stream_get_side_data(st, AV_PKT_DATA_DISPLAYMATRIX, nullptr);
        if (dm && std::lround(av_display_rotation_get(reinterpret_cast<const int32_t *>(dm))) % 360 != 0)
            return false;  // OpenCV turns such frames upright
        const AVCodec *codec = avcodec_find_decoder(st->codecpar->codec_id);
        if (!codec || !(ctx_ = avcodec_alloc_context3(codec))) return false;
        ctx_->thread_count = threads;
        if (avcodec_parameters_to_context(ctx_, st->codecpar) < 0 || avcodec_open2(ctx_, codec, nullptr) < 0)
            return false;
        if ((ctx_->pix_fmt != AV_PIX_FMT_YUV420P && ctx_->pix_fmt != AV_PIX_FMT_YUVJ420P) ||
            ctx_->coded_width != ctx_->width || ctx_->coded_height != ctx_->height || ctx_->width <= 0 ||
            ctx_->height <= 0 || ctx_->width % 8 != 0)
            return false;  // sws_scale converts rows in 8-pixel blocks: other widths depend on the row's padding
        pic_ = av_frame_alloc();
        pkt_ = av_packet_alloc();
        return pic_ && pkt_;
    }

    // the next frame into bgr (its memory reused when it fits) and its time (s); false at the end
    bool read(cv::Mat &bgr, double &t_s)
    {
        const AVStream *st = ic_->streams[vs_];
        if (st->nb_frames > 0 && n_frames_ > st->nb_frames) return false;
        bool valid = avcodec_receive_frame(ctx_, pic_) >= 0;
        for (int errs = 0; !valid;) {
            av_packet_unref(pkt_);
            int rc = av_read_frame(ic_, pkt_);
            if (rc == AVERROR(EAGAIN)) continue;
            if (rc == AVERROR_EOF) {  // drain the decoder's delayed frames
                pkt_->data = nullptr;
                pkt_->size = 0;
                pkt_->stream_index = vs_;
            }
            if (pkt_->stream_index != vs_) {
                av_packet_unref(pkt_);
                if (++errs > kMaxErrors) break;
                continue;
            }
            if (avcodec_send_packet(ctx_, pkt_) < 0) break;
            rc = avcodec_receive_frame(ctx_, pic_);
            if (rc >= 0)
                valid = true;
            else if (rc != AVERROR(EAGAIN) && ++errs > kMaxErrors)
                break;
        }
        if (!valid || pic_->width != ctx_->width || pic_->height != ctx_->height) return false;
        n_frames_++;
        const int64_t dts = pic_->pkt_dts;
        const AVRational tb = st->time_base;
        const double sec_per_tick = tb.num == 0 || tb.den == 0 ? 0.0 : static_cast<double>(tb.num) / tb.den;
        // OpenCV's milliseconds, then seconds, in its order of operations
        const double ms = dts == AV_NOPTS_VALUE ? 0.0
                                                 : static_cast<double>(static_cast<int64_t>(
                                                       static_cast<uint64_t>(dts) - static_cast<uint64_t>(st->start_time))) *
                                                       sec_per_tick * 1000;
        t_s = ms * 1e-3;
        sws_ = sws_getCachedContext(sws_, ctx_->width, ctx_->height, static_cast<AVPixelFormat>(pic_->format),
                                    ctx_->width, ctx_->height, AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr,
                                    nullptr);
        if (!sws_) return false;
        bgr.create(ctx_->height, ctx_->width, CV_8UC3);
        uint8_t *dst[4] = {bgr.data, nullptr, nullptr, nullptr};
        int dst_step[4] = {static_cast<int>(bgr.step), 0, 0, 0};
        sws_scale(sws_, pic_->data, pic_->linesize, 0, pic_->height, dst, dst_step);
        return true;
    }

private:
    static constexpr int kMaxErrors = 1 << 9;
    AVFormatContext *ic_ = nullptr;
    AVCodecContext *ctx_ = nullptr;
    AVFrame *pic_ = nullptr;
    AVPacket *pkt_ = nullptr;
    SwsContext *sws_ = nullptr;
    int vs_ = -1;
    int64_t n_frames_ = 0;
};

class VideoFileSource : public FrameSource {
public:
    bool init(const std::string &path, const FrameSourceOptions &opt, std::string &err)
    {
        if (!probe_video(path, probe_, err)) return false;
        const int threads = opt.decode_threads > 0 ? opt.decode_threads : static_cast<int>(cv::getNumberOfCPUs());
        std::unique_ptr<AvDecoder> av(new AvDecoder);
        if (av->open(path, threads)) {
            av_ = std::move(av);
            decoder_ = "libavcodec";
        } else {
            decoder_ = "opencv";
            av.reset();
            // OpenCV keeps its own FFmpeg state and may reset the log level: quiet it again
            cap_.open(path, cv::CAP_FFMPEG);
            av_log_set_level(AV_LOG_QUIET);
            if (!cap_.isOpened()) {
                err = "cannot decode the video stream (codec " + probe_.codec + ")";
                return false;
            }
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
        if (av_) return av_->read(bgr, t);
        if (!cap_.read(bgr) || bgr.empty()) return false;
        double ms = cap_.get(cv::CAP_PROP_POS_MSEC);
        t = std::isfinite(ms) ? ms * 1e-3 : NAN;
        return true;
    }

private:
    std::unique_ptr<AvDecoder> av_;  // else OpenCV's
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
