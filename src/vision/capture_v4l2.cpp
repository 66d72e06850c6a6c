// capture_v4l2.cpp - V4L2 mmap streaming behind the V4l2Io device layer.
#include "capture_v4l2.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace gs {

V4l2Io::~V4l2Io() = default;

namespace {

class SystemIo : public V4l2Io {
public:
    int open(const char *path, int flags) override { return ::open(path, flags); }
    int close(int fd) override { return ::close(fd); }
    int ioctl(int fd, unsigned long req, void *arg) override
    {
        int r;
        do r = ::ioctl(fd, req, arg);
        while (r == -1 && errno == EINTR);
        return r;
    }
    void *mmap(size_t len, int prot, int flags, int fd, off_t offset) override
    {
        return ::mmap(nullptr, len, prot, flags, fd, offset);
    }
    int munmap(void *addr, size_t len) override { return ::munmap(addr, len); }
    int poll(struct pollfd *fds, nfds_t n, int timeout_ms) override { return ::poll(fds, n, timeout_ms); }
};

std::string fourcc_text(uint32_t f)
{
    std::string s;
    for (int i = 0; i < 4; i++) {
        char c = static_cast<char>((f >> (8 * i)) & 0xff);
        s += (c >= 32 && c < 127) ? c : '?';
    }
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
}

std::string errtext(int e) { return std::strerror(e); }

class V4l2Capture : public Capture {
public:
    V4l2Capture(std::shared_ptr<V4l2Io> io, std::string path) : io_(std::move(io)), path_(std::move(path)) {}
    ~V4l2Capture() override { shutdown(); }

    bool start(const CaptureConfig &cfg, std::string &err, CaptureError &kind);
    ReadResult read(CaptureFrame &f, int timeout_ms) override;

private:
    struct Buffer {
        void *ptr = nullptr;
        size_t len = 0;
    };
    ReadResult fail(const std::string &what, int e)
    {
        error_ = "v4l2 " + path_ + ": " + what + (e ? ": " + errtext(e) : "");
        failed_ = true;
        shutdown();
        return ReadResult::error;
    }
    bool negotiate(const CaptureConfig &cfg, std::string &err, CaptureError &kind);
    bool map_buffers(unsigned count, std::string &err);
    bool decode(const Buffer &b, uint32_t bytesused, cv::Mat &out);
    void shutdown();

    std::shared_ptr<V4l2Io> io_;
    std::string path_;
    int fd_ = -1;
    bool streaming_ = false, failed_ = false, monotonic_ = false;
    uint32_t pixfmt_ = 0, bytesperline_ = 0;
    std::vector<Buffer> bufs_;
};

void V4l2Capture::shutdown()
{
    if (fd_ < 0) return;
    if (streaming_) {
        int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        io_->ioctl(fd_, VIDIOC_STREAMOFF, &type);  // a vanished device fails here: nothing to do
        streaming_ = false;
    }
    for (Buffer &b : bufs_)
        if (b.ptr) io_->munmap(b.ptr, b.len);
    bufs_.clear();
    io_->close(fd_);
    fd_ = -1;
}

bool V4l2Capture::negotiate(const CaptureConfig &cfg, std::string &err, CaptureError &kind)
{
    std::vector<uint32_t> want;
    if (cfg.pixel_format == "mjpeg") {
        want = {V4L2_PIX_FMT_MJPEG};
    } else if (cfg.pixel_format == "yuyv") {
        want = {V4L2_PIX_FMT_YUYV};
    } else if (cfg.pixel_format == "auto") {
        want = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV};  // MJPEG first: USB bandwidth at high rates
    } else {
        err = "pixel format must be auto, mjpeg or yuyv, not '" + cfg.pixel_format + "'";
        kind = CaptureError::usage;
        return false;
    }
    v4l2_format fmt;
    bool got = false;
    int last_errno = 0;
    for (uint32_t pf : want) {
        std::memset(&fmt, 0, sizeof fmt);
        fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        fmt.fmt.pix.width = static_cast<uint32_t>(cfg.width);
        fmt.fmt.pix.height = static_cast<uint32_t>(cfg.height);
        fmt.fmt.pix.pixelformat = pf;
        fmt.fmt.pix.field = V4L2_FIELD_NONE;
        if (io_->ioctl(fd_, VIDIOC_S_FMT, &fmt) != 0) {
            last_errno = errno;
            continue;
        }
        // the driver replaces a format it lacks by one it has: take only ours
        if (fmt.fmt.pix.pixelformat == V4L2_PIX_FMT_MJPEG || fmt.fmt.pix.pixelformat == V4L2_PIX_FMT_YUYV) {
            got = fmt.fmt.pix.pixelformat == pf || cfg.pixel_format == "auto";
            if (got) break;
        }
    }
    if (!got) {
        err = "v4l2 " + path_ + ": " +
              (cfg.pixel_format == "auto" ? std::string("the device offers neither MJPEG nor YUYV")
                                          : "the device does not offer " + std::string(cfg.pixel_format == "mjpeg" ? "MJPEG" : "YUYV")) +
              (last_errno ? " (VIDIOC_S_FMT: " + errtext(last_errno) + ")" : "");
        kind = CaptureError::device;
        return false;
    }
    pixfmt_ = fmt.fmt.pix.pixelformat;
    size_ = cv::Size(static_cast<int>(fmt.fmt.pix.width), static_cast<int>(fmt.fmt.pix.height));
    bytesperline_ = fmt.fmt.pix.bytesperline;
    if (pixfmt_ == V4L2_PIX_FMT_YUYV && bytesperline_ < 2u * fmt.fmt.pix.width)
        bytesperline_ = 2u * fmt.fmt.pix.width;
    if (size_.width <= 0 || size_.height <= 0) {
        err = "v4l2 " + path_ + ": the driver gave an empty frame size";
        kind = CaptureError::device;
        return false;
    }

    // frame rate: ask, then read back what the driver chose
    v4l2_streamparm parm;
    std::memset(&parm, 0, sizeof parm);
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (cfg.fps > 0.0) {
        parm.parm.capture.timeperframe.numerator = 1000;
        parm.parm.capture.timeperframe.denominator = static_cast<uint32_t>(std::lround(cfg.fps * 1000.0));
        io_->ioctl(fd_, VIDIOC_S_PARM, &parm);  // not every driver sets the rate; G_PARM tells
    }
    std::memset(&parm, 0, sizeof parm);
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fps_ = 0.0;
    if (io_->ioctl(fd_, VIDIOC_G_PARM, &parm) == 0 && parm.parm.capture.timeperframe.numerator > 0 &&
        parm.parm.capture.timeperframe.denominator > 0)
        fps_ = static_cast<double>(parm.parm.capture.timeperframe.denominator) /
               parm.parm.capture.timeperframe.numerator;
    return true;
}

bool V4l2Capture::map_buffers(unsigned count, std::string &err)
{
    v4l2_requestbuffers req;
    std::memset(&req, 0, sizeof req);
    req.count = count;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (io_->ioctl(fd_, VIDIOC_REQBUFS, &req) != 0) {
        err = "v4l2 " + path_ + ": VIDIOC_REQBUFS (mmap streaming): " + errtext(errno);
        return false;
    }
    if (req.count < 2) {
        err = "v4l2 " + path_ + ": the driver gave " + std::to_string(req.count) + " buffer(s), 2 needed";
        return false;
    }
    bufs_.resize(req.count);
    for (uint32_t i = 0; i < req.count; i++) {
        v4l2_buffer b;
        std::memset(&b, 0, sizeof b);
        b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        b.memory = V4L2_MEMORY_MMAP;
        b.index = i;
        if (io_->ioctl(fd_, VIDIOC_QUERYBUF, &b) != 0) {
            err = "v4l2 " + path_ + ": VIDIOC_QUERYBUF: " + errtext(errno);
            return false;
        }
        void *p = io_->mmap(b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, static_cast<off_t>(b.m.offset));
        if (p == MAP_FAILED) {
            err = "v4l2 " + path_ + ": mmap of buffer " + std::to_string(i) + ": " + errtext(errno);
            return false;
        }
        bufs_[i].ptr = p;
        bufs_[i].len = b.length;
        if (io_->ioctl(fd_, VIDIOC_QBUF, &b) != 0) {
            err = "v4l2 " + path_ + ": VIDIOC_QBUF: " + errtext(errno);
            return false;
        }
    }
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (io_->ioctl(fd_, VIDIOC_STREAMON, &type) != 0) {
        err = "v4l2 " + path_ + ": VIDIOC_STREAMON: " + errtext(errno);
        return false;
    }
    streaming_ = true;
    return true;
}

bool V4l2Capture::start(const CaptureConfig &cfg, std::string &err, CaptureError &kind)
{
    kind = CaptureError::device;
    fd_ = io_->open(path_.c_str(), O_RDWR | O_NONBLOCK);
    if (fd_ < 0) {
        err = "v4l2 " + path_ + ": cannot open: " + errtext(errno);
        return false;
    }
    v4l2_capability cap;
    std::memset(&cap, 0, sizeof cap);
    if (io_->ioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) {
        err = "v4l2 " + path_ + ": not a V4L2 device (VIDIOC_QUERYCAP: " + errtext(errno) + ")";
        return false;
    }
    uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) {
        err = "v4l2 " + path_ + ": not a video capture device";
        return false;
    }
    if (!(caps & V4L2_CAP_STREAMING)) {
        err = "v4l2 " + path_ + ": the device does not stream (no V4L2_CAP_STREAMING)";
        return false;
    }
    if (!negotiate(cfg, err, kind)) return false;
    if (!map_buffers(cfg.buffers < 2 ? 2u : cfg.buffers, err)) return false;
    drops_.reset(fps_ > 0.0 ? 1.0 / fps_ : 0.0);
    char card[sizeof cap.card + 1] = {0};
    std::memcpy(card, cap.card, sizeof cap.card);
    char line[256];
    std::snprintf(line, sizeof line, "v4l2 %s (%s): %dx%d %s %.3g fps", path_.c_str(), card, size_.width,
                  size_.height, fourcc_text(pixfmt_).c_str(), fps_);
    desc_ = line;
    return true;
}

bool V4l2Capture::decode(const Buffer &b, uint32_t bytesused, cv::Mat &out)
{
    if (pixfmt_ == V4L2_PIX_FMT_MJPEG) {
        if (bytesused == 0 || bytesused > b.len) return false;
        cv::Mat raw(1, static_cast<int>(bytesused), CV_8UC1, b.ptr);
        out = cv::imdecode(raw, cv::IMREAD_COLOR);
        return !out.empty();
    }
    size_t need = static_cast<size_t>(bytesperline_) * static_cast<size_t>(size_.height);
    if (need > b.len || (bytesused != 0 && bytesused < need)) return false;
    cv::Mat yuyv(size_.height, size_.width, CV_8UC2, b.ptr, bytesperline_);
    cv::cvtColor(yuyv, out, cv::COLOR_YUV2BGR_YUYV);
    return true;
}

ReadResult V4l2Capture::read(CaptureFrame &f, int timeout_ms)
{
    if (failed_ || fd_ < 0) return ReadResult::error;
    pollfd p;
    p.fd = fd_;
    p.events = POLLIN;
    p.revents = 0;
    int r = io_->poll(&p, 1, timeout_ms);
    if (r < 0) {
        if (errno == EINTR) return ReadResult::timeout;  // a signal: the caller checks its flag
        return fail("poll", errno);
    }
    if (r == 0) return ReadResult::timeout;
    if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) {
        if (!(p.revents & POLLIN)) return fail("the device went away (poll error)", 0);
    }
    v4l2_buffer b;
    std::memset(&b, 0, sizeof b);
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (io_->ioctl(fd_, VIDIOC_DQBUF, &b) != 0) {
        int e = errno;
        if (e == EAGAIN || e == EINTR) return ReadResult::timeout;
        return fail(e == ENODEV ? "the device went away (VIDIOC_DQBUF)" : "VIDIOC_DQBUF", e);
    }
    if (b.index >= bufs_.size()) return fail("the driver returned buffer " + std::to_string(b.index), 0);
    bool ok = !(b.flags & V4L2_BUF_FLAG_ERROR) && decode(bufs_[b.index], b.bytesused, f.bgr);
    const double t = static_cast<double>(b.timestamp.tv_sec) + 1e-6 * static_cast<double>(b.timestamp.tv_usec);
    // the driver counts whole microseconds: kept exact for the core
    const int64_t t_us = static_cast<int64_t>(b.timestamp.tv_sec) * 1000000 + static_cast<int64_t>(b.timestamp.tv_usec);
    monotonic_ = (b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    time_origin_ = monotonic_ ? "driver" : "driver_unknown_clock";
    if (io_->ioctl(fd_, VIDIOC_QBUF, &b) != 0) {
        // the device went away after giving this frame: deliver it, fail on the next read
        int e = errno;
        ReadResult rr = fail(e == ENODEV ? "the device went away (VIDIOC_QBUF)" : "VIDIOC_QBUF", e);
        if (!ok) return rr;
    }
    if (!ok) {
        corrupt_++;  // a broken JPEG or a short buffer: skipped, counted
        return ReadResult::timeout;
    }
    deliver(f, t, static_cast<int64_t>(b.sequence), t_us);
    return ReadResult::frame;
}

}  // namespace

std::shared_ptr<V4l2Io> system_v4l2_io() { return std::make_shared<SystemIo>(); }

std::unique_ptr<Capture> open_v4l2(const CaptureConfig &cfg, std::shared_ptr<V4l2Io> io, std::string &err,
                                   CaptureError &kind)
{
    auto c = std::make_unique<V4l2Capture>(std::move(io), cfg.device);
    if (!c->start(cfg, err, kind)) return nullptr;
    kind = CaptureError::none;
    return c;
}

}  // namespace gs
