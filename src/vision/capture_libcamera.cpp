// capture_libcamera.cpp - libcamera 0.0.3 behind the Capture interface.
// libcamera completes requests on its own thread; the handler only queues the
// finished request, and read() (the daemon's single thread) decodes, takes the
// SensorTimestamp and queues the request again.
#include "capture_libcamera.hpp"

#if defined(GS_HAVE_LIBCAMERA) && GS_HAVE_LIBCAMERA

#include <sys/mman.h>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>

#include <libcamera/libcamera.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace gs {

bool have_libcamera() { return true; }

namespace {

namespace lc = libcamera;

// libcamera logs INFO lines to stderr; the daemon wants one line per problem
void quiet_libcamera_log() { setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0); }

class LibcameraCapture : public Capture {
public:
    ~LibcameraCapture() override { shutdown(); }
    bool start(const CaptureConfig &cfg, std::string &err, CaptureError &kind);
    ReadResult read(CaptureFrame &f, int timeout_ms) override;

private:
    void on_complete(lc::Request *r)
    {
        std::lock_guard<std::mutex> lk(mu_);
        done_.push_back(r);
        cv_.notify_one();
    }
    bool decode(lc::FrameBuffer *fb, cv::Mat &out);
    void shutdown();

    std::unique_ptr<lc::CameraManager> cm_;
    std::shared_ptr<lc::Camera> cam_;
    std::unique_ptr<lc::CameraConfiguration> config_;
    std::unique_ptr<lc::FrameBufferAllocator> alloc_;
    std::vector<std::unique_ptr<lc::Request>> requests_;
    lc::Stream *stream_ = nullptr;
    lc::PixelFormat fmt_;
    unsigned stride_ = 0;
    std::map<int, std::pair<void *, size_t>> maps_;  // dmabuf fd -> mapping
    bool acquired_ = false, started_ = false;
    std::mutex mu_;
    std::condition_variable cv_;
    std::deque<lc::Request *> done_;
};

void LibcameraCapture::shutdown()
{
    if (cam_) {
        if (started_) cam_->stop();
        started_ = false;
        cam_->requestCompleted.disconnect(this);
        requests_.clear();
        for (auto &m : maps_) munmap(m.second.first, m.second.second);
        maps_.clear();
        alloc_.reset();
        config_.reset();
        if (acquired_) cam_->release();
        acquired_ = false;
        cam_.reset();
    }
    if (cm_) {
        cm_->stop();
        cm_.reset();
    }
}

bool LibcameraCapture::start(const CaptureConfig &cfg, std::string &err, CaptureError &kind)
{
    kind = CaptureError::device;
    quiet_libcamera_log();
    cm_ = std::make_unique<lc::CameraManager>();
    int r = cm_->start();
    if (r) {
        err = std::string("libcamera: the camera manager does not start: ") + std::strerror(-r);
        return false;
    }
    auto cams = cm_->cameras();
    if (cams.empty()) {
        err = "libcamera: no camera found";
        return false;
    }
    const std::string &dev = cfg.device;
    if (dev.empty() || dev == "auto") {
        cam_ = cams[0];
    } else if (dev.find_first_not_of("0123456789") == std::string::npos) {
        size_t i = std::strtoul(dev.c_str(), nullptr, 10);
        if (i >= cams.size()) {
            err = "libcamera: camera " + dev + " not found (" + std::to_string(cams.size()) + " camera(s))";
            return false;
        }
        cam_ = cams[i];
    } else {
        cam_ = cm_->get(dev);
        if (!cam_) {
            err = "libcamera: no camera with id '" + dev + "'";
            return false;
        }
    }
    if (cam_->acquire()) {
        err = "libcamera: camera " + cam_->id() + " is busy";
        return false;
    }
    acquired_ = true;
    config_ = cam_->generateConfiguration({lc::StreamRole::VideoRecording});
    if (!config_ || config_->empty()) {
        err = "libcamera: camera " + cam_->id() + " has no video stream";
        return false;
    }
    lc::StreamConfiguration &sc = config_->at(0);
    if (cfg.pixel_format == "mjpeg")
        sc.pixelFormat = lc::formats::MJPEG;
    else if (cfg.pixel_format == "yuyv")
        sc.pixelFormat = lc::formats::YUYV;
    else
        sc.pixelFormat = lc::formats::RGB888;  // B, G, R in memory: OpenCV's order
    sc.size = lc::Size(static_cast<unsigned>(cfg.width), static_cast<unsigned>(cfg.height));
    sc.bufferCount = cfg.buffers < 2 ? 2 : cfg.buffers;
    if (config_->validate() == lc::CameraConfiguration::Invalid) {
        err = "libcamera: camera " + cam_->id() + ": no usable stream configuration";
        return false;
    }
    fmt_ = sc.pixelFormat;
    if (fmt_ != lc::formats::RGB888 && fmt_ != lc::formats::BGR888 && fmt_ != lc::formats::YUYV &&
        fmt_ != lc::formats::MJPEG && fmt_ != lc::formats::NV12) {
        err = "libcamera: camera " + cam_->id() + " offers " + fmt_.toString() + ", not RGB888/YUYV/MJPEG/NV12";
        return false;
    }
    if (cam_->configure(config_.get())) {
        err = "libcamera: camera " + cam_->id() + ": configure failed";
        return false;
    }
    stream_ = sc.stream();
    stride_ = sc.stride;
    size_ = cv::Size(static_cast<int>(sc.size.width), static_cast<int>(sc.size.height));
    alloc_ = std::make_unique<lc::FrameBufferAllocator>(cam_);
    if (alloc_->allocate(stream_) < 0) {
        err = "libcamera: cannot allocate buffers";
        return false;
    }
    for (const std::unique_ptr<lc::FrameBuffer> &fb : alloc_->buffers(stream_)) {
        std::unique_ptr<lc::Request> req = cam_->createRequest();
        if (!req || req->addBuffer(stream_, fb.get())) {
            err = "libcamera: cannot create a request";
            return false;
        }
        for (const lc::FrameBuffer::Plane &p : fb->planes()) {
            int fd = p.fd.get();
            size_t end = static_cast<size_t>(p.offset) + p.length;
            auto it = maps_.find(fd);
            if (it != maps_.end() && it->second.second >= end) continue;
            if (it != maps_.end()) {
                munmap(it->second.first, it->second.second);
                maps_.erase(it);
            }
            void *m = mmap(nullptr, end, PROT_READ, MAP_SHARED, fd, 0);
            if (m == MAP_FAILED) {
                err = std::string("libcamera: mmap: ") + std::strerror(errno);
                return false;
            }
            maps_[fd] = {m, end};
        }
        requests_.push_back(std::move(req));
    }
    cam_->requestCompleted.connect(this, &LibcameraCapture::on_complete);
    lc::ControlList controls;
    if (cfg.fps > 0.0) {
        int64_t us = static_cast<int64_t>(1e6 / cfg.fps);
        controls.set(lc::controls::FrameDurationLimits, lc::Span<const int64_t, 2>({us, us}));
    }
    if (cam_->start(&controls)) {
        err = "libcamera: camera " + cam_->id() + " does not start";
        return false;
    }
    started_ = true;
    for (auto &req : requests_) cam_->queueRequest(req.get());
    fps_ = cfg.fps;
    drops_.reset(fps_ > 0.0 ? 1.0 / fps_ : 0.0);
    time_origin_ = "sensor";
    char line[160];
    std::snprintf(line, sizeof line, "libcamera %s: %dx%d %s", cam_->id().c_str(), size_.width, size_.height,
                  fmt_.toString().c_str());
    desc_ = line;
    kind = CaptureError::none;
    return true;
}

bool LibcameraCapture::decode(lc::FrameBuffer *fb, cv::Mat &out)
{
    const lc::FrameBuffer::Plane &p0 = fb->planes()[0];
    auto it = maps_.find(p0.fd.get());
    if (it == maps_.end()) return false;
    uint8_t *base = static_cast<uint8_t *>(it->second.first) + p0.offset;
    const int w = size_.width, h = size_.height;
    if (fmt_ == lc::formats::MJPEG) {
        unsigned used = fb->metadata().planes().empty() ? p0.length : fb->metadata().planes()[0].bytesused;
        out = cv::imdecode(cv::Mat(1, static_cast<int>(used), CV_8UC1, base), cv::IMREAD_COLOR);
        return !out.empty();
    }
    if (fmt_ == lc::formats::YUYV) {
        cv::cvtColor(cv::Mat(h, w, CV_8UC2, base, stride_), out, cv::COLOR_YUV2BGR_YUYV);
        return true;
    }
    if (fmt_ == lc::formats::NV12) {
        if (stride_ != static_cast<unsigned>(w)) return false;  // NV12 with padding: not handled
        cv::cvtColor(cv::Mat(h * 3 / 2, w, CV_8UC1, base), out, cv::COLOR_YUV2BGR_NV12);
        return true;
    }
    cv::Mat m(h, w, CV_8UC3, base, stride_);
    if (fmt_ == lc::formats::BGR888)
        cv::cvtColor(m, out, cv::COLOR_RGB2BGR);
    else
        m.copyTo(out);
    return true;
}

ReadResult LibcameraCapture::read(CaptureFrame &f, int timeout_ms)
{
    if (!started_) return ReadResult::error;
    lc::Request *r = nullptr;
    {
        std::unique_lock<std::mutex> lk(mu_);
        if (done_.empty()) cv_.wait_for(lk, std::chrono::milliseconds(timeout_ms), [this] { return !done_.empty(); });
        if (done_.empty()) return ReadResult::timeout;
        r = done_.front();
        done_.pop_front();
    }
    if (r->status() == lc::Request::RequestCancelled) {
        error_ = "libcamera: camera " + cam_->id() + " stopped (request cancelled)";
        return ReadResult::error;
    }
    lc::FrameBuffer *fb = r->findBuffer(stream_);
    bool ok = fb && fb->metadata().status == lc::FrameMetadata::FrameSuccess && decode(fb, f.bgr);
    std::optional<int64_t> ts = r->metadata().get(lc::controls::SensorTimestamp);
    double t = ts ? static_cast<double>(*ts) * 1e-9 : (fb ? static_cast<double>(fb->metadata().timestamp) * 1e-9 : NAN);
    // nanoseconds (>= 0) to the nearest whole microsecond for the core
    int64_t t_us = INT64_MIN;
    if (ts && *ts >= 0)
        t_us = (*ts + 500) / 1000;
    else if (!ts && fb)
        t_us = static_cast<int64_t>((fb->metadata().timestamp + 500u) / 1000u);
    int64_t seq = fb ? static_cast<int64_t>(fb->metadata().sequence) : -1;
    r->reuse(lc::Request::ReuseBuffers);
    cam_->queueRequest(r);
    if (!ok || !std::isfinite(t)) {
        corrupt_++;
        return ReadResult::timeout;
    }
    deliver(f, t, seq, t_us);
    return ReadResult::frame;
}

}  // namespace

std::unique_ptr<Capture> open_libcamera(const CaptureConfig &cfg, std::string &err, CaptureError &kind)
{
    auto c = std::make_unique<LibcameraCapture>();
    if (!c->start(cfg, err, kind)) return nullptr;
    return c;
}

int libcamera_count_cameras(std::string &err)
{
    quiet_libcamera_log();
    lc::CameraManager cm;
    int r = cm.start();
    if (r) {
        err = std::string("libcamera: the camera manager does not start: ") + std::strerror(-r);
        return -1;
    }
    int n = static_cast<int>(cm.cameras().size());
    cm.stop();
    return n;
}

}  // namespace gs

#else  // no libcamera in this build

namespace gs {

bool have_libcamera() { return false; }

std::unique_ptr<Capture> open_libcamera(const CaptureConfig &, std::string &err, CaptureError &kind)
{
    err = "libcamera: this build has no libcamera support (install libcamera-dev and rebuild)";
    kind = CaptureError::usage;
    return nullptr;
}

int libcamera_count_cameras(std::string &err)
{
    err = "libcamera: this build has no libcamera support";
    return -1;
}

}  // namespace gs

#endif
