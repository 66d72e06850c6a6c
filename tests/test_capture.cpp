// test_capture.cpp - the capture layer of `gravscale cam` without a camera: a
// fake V4L2 device behind V4l2Io replays frames rendered here (served as MJPEG
// or YUYV buffers with synthetic driver timestamps and sequence gaps), the
// GStreamer videotestsrc as a live-like source, libcamera's no-camera path.
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture.hpp"
#include "capture_libcamera.hpp"
#include "capture_v4l2.hpp"

extern "C" {
#include "unity.h"
}

void setUp(void) {}
void tearDown(void) {}

namespace {

constexpr int kW = 320, kH = 240;
constexpr double kT0 = 5000.0;  // a monotonic clock far from zero, as a real one
constexpr double kFps = 30.0;

// A frame the fake device serves: its bytes and what the driver would say.
struct FakeFrame {
    std::vector<uint8_t> bytes;
    double t_s;
    uint32_t seq;
    bool error_flag = false;
};

cv::Point2d disc_centre(int i) { return {60.0 + 11.0 * i, 200.0 - 9.0 * i}; }

cv::Mat render(int i)
{
    cv::Mat img(kH, kW, CV_8UC3, cv::Scalar(128, 128, 128));
    cv::Point2d c = disc_centre(i);
    // drawn at 1/16 px precision so the centre is exact
    cv::circle(img, cv::Point(static_cast<int>(std::lround(c.x * 16)), static_cast<int>(std::lround(c.y * 16))), 12 * 16,
               cv::Scalar(0, 130, 255), cv::FILLED, cv::LINE_8, 4);
    return img;
}

std::vector<uint8_t> as_mjpeg(const cv::Mat &bgr)
{
    std::vector<uint8_t> out;
    TEST_ASSERT_TRUE(cv::imencode(".jpg", bgr, out, {cv::IMWRITE_JPEG_QUALITY, 95}));
    return out;
}

// BGR -> packed YUYV (Y0 U Y1 V) in BT.601 limited range, as cameras send it
std::vector<uint8_t> as_yuyv(const cv::Mat &bgr)
{
    auto ycc = [](cv::Vec3b p, double &y, double &cb, double &cr) {
        double b = p[0], g = p[1], r = p[2];
        y = 16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0;
        cb = 128.0 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0;
        cr = 128.0 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0;
    };
    std::vector<uint8_t> out(static_cast<size_t>(bgr.cols) * bgr.rows * 2);
    for (int y = 0; y < bgr.rows; y++)
        for (int x = 0; x < bgr.cols; x += 2) {
            double y0, cb0, cr0, y1, cb1, cr1;
            ycc(bgr.at<cv::Vec3b>(y, x), y0, cb0, cr0);
            ycc(bgr.at<cv::Vec3b>(y, x + 1), y1, cb1, cr1);
            uint8_t *p = &out[(static_cast<size_t>(y) * bgr.cols + x) * 2];
            p[0] = cv::saturate_cast<uint8_t>(y0);
            p[1] = cv::saturate_cast<uint8_t>(0.5 * (cb0 + cb1));
            p[2] = cv::saturate_cast<uint8_t>(y1);
            p[3] = cv::saturate_cast<uint8_t>(0.5 * (cr0 + cr1));
        }
    return out;
}

// The kernel, faked: one device at /dev/fake0, a fixed native size and rate.
class FakeV4l2 : public gs::V4l2Io {
public:
    std::vector<uint32_t> formats = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_YUYV};
    uint32_t caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
    uint32_t ts_flag = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    double max_fps = kFps;
    std::deque<FakeFrame> script;  // frames still to deliver
    bool vanish_at_end = true;     // after the script: ENODEV (unplugged) instead of waiting

    // what the code did
    int opens = 0, closes = 0, maps = 0, unmaps = 0, streamon = 0, streamoff = 0;
    uint32_t pixfmt = 0;
    double fps_set = 0.0;

    int open(const char *path, int) override
    {
        if (std::strcmp(path, "/dev/fake0") != 0) {
            errno = ENOENT;
            return -1;
        }
        opens++;
        return kFd;
    }
    int close(int fd) override
    {
        TEST_ASSERT_EQUAL_INT(kFd, fd);
        closes++;
        return 0;
    }
    int ioctl(int fd, unsigned long req, void *arg) override
    {
        if (fd != kFd) return fail(EBADF);
        if (gone_ && req != VIDIOC_STREAMOFF) return fail(ENODEV);
        switch (req) {
        case VIDIOC_QUERYCAP: {
            auto *c = static_cast<v4l2_capability *>(arg);
            std::memset(c, 0, sizeof *c);
            std::strcpy(reinterpret_cast<char *>(c->driver), "fake");
            std::strcpy(reinterpret_cast<char *>(c->card), "Fake Cam");
            c->capabilities = caps | V4L2_CAP_DEVICE_CAPS;
            c->device_caps = caps;
            return 0;
        }
        case VIDIOC_S_FMT: {
            auto *f = static_cast<v4l2_format *>(arg);
            if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return fail(EINVAL);
            bool have = false;
            for (uint32_t x : formats) have = have || x == f->fmt.pix.pixelformat;
            if (!have) f->fmt.pix.pixelformat = formats[0];  // as drivers do: their own format instead
            pixfmt = f->fmt.pix.pixelformat;
            f->fmt.pix.width = kW;  // one native size, whatever was asked
            f->fmt.pix.height = kH;
            f->fmt.pix.bytesperline = pixfmt == V4L2_PIX_FMT_YUYV ? 2 * kW : 0;
            f->fmt.pix.sizeimage = 2 * kW * kH;
            return 0;
        }
        case VIDIOC_S_PARM: {
            auto *p = static_cast<v4l2_streamparm *>(arg);
            double want = static_cast<double>(p->parm.capture.timeperframe.denominator) / p->parm.capture.timeperframe.numerator;
            fps_set = std::min(want, max_fps);
            return 0;
        }
        case VIDIOC_G_PARM: {
            auto *p = static_cast<v4l2_streamparm *>(arg);
            p->parm.capture.timeperframe.numerator = 1000;
            p->parm.capture.timeperframe.denominator = static_cast<uint32_t>(std::lround(fps_set * 1000));
            return 0;
        }
        case VIDIOC_REQBUFS: {
            auto *r = static_cast<v4l2_requestbuffers *>(arg);
            if (r->memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
            r->count = std::min<uint32_t>(r->count, 3);  // fewer than asked: the code must cope
            bufs_.assign(r->count, std::vector<uint8_t>(kBufBytes));
            return 0;
        }
        case VIDIOC_QUERYBUF: {
            auto *b = static_cast<v4l2_buffer *>(arg);
            if (b->index >= bufs_.size()) return fail(EINVAL);
            b->length = kBufBytes;
            b->m.offset = b->index * kBufBytes;
            return 0;
        }
        case VIDIOC_QBUF: {
            auto *b = static_cast<v4l2_buffer *>(arg);
            if (b->index >= bufs_.size()) return fail(EINVAL);
            for (uint32_t q : queued_) TEST_ASSERT_NOT_EQUAL_MESSAGE(q, b->index, "a buffer queued twice");
            queued_.push_back(b->index);
            return 0;
        }
        case VIDIOC_STREAMON: streamon++; return 0;
        case VIDIOC_STREAMOFF: streamoff++; return 0;
        case VIDIOC_DQBUF: {
            if (!streamon) return fail(EINVAL);
            if (script.empty() || queued_.empty()) return fail(EAGAIN);
            auto *b = static_cast<v4l2_buffer *>(arg);
            uint32_t idx = queued_.front();
            queued_.pop_front();
            FakeFrame fr = script.front();
            script.pop_front();
            TEST_ASSERT_TRUE(fr.bytes.size() <= kBufBytes);
            std::memcpy(bufs_[idx].data(), fr.bytes.data(), fr.bytes.size());
            b->index = idx;
            b->bytesused = static_cast<uint32_t>(fr.bytes.size());
            b->sequence = fr.seq;
            b->flags = ts_flag | (fr.error_flag ? V4L2_BUF_FLAG_ERROR : 0u);
            double whole = std::floor(fr.t_s);
            b->timestamp.tv_sec = static_cast<time_t>(whole);
            b->timestamp.tv_usec = static_cast<suseconds_t>(std::lround((fr.t_s - whole) * 1e6));
            if (script.empty() && vanish_at_end) gone_ = true;
            return 0;
        }
        }
        return fail(ENOTTY);
    }
    void *mmap(size_t len, int, int, int fd, off_t offset) override
    {
        size_t i = static_cast<size_t>(offset) / kBufBytes;
        if (fd != kFd || i >= bufs_.size() || len != kBufBytes) {
            errno = EINVAL;
            return MAP_FAILED;
        }
        maps++;
        return bufs_[i].data();
    }
    int munmap(void *, size_t) override
    {
        unmaps++;
        return 0;
    }
    int poll(struct pollfd *fds, nfds_t, int) override
    {
        fds[0].revents = 0;
        if (gone_) {
            fds[0].revents = POLLERR | POLLHUP;
            return 1;
        }
        if (!script.empty() && !queued_.empty()) {
            fds[0].revents = POLLIN;
            return 1;
        }
        return 0;  // a timeout, at once
    }

private:
    static constexpr int kFd = 42;
    static constexpr size_t kBufBytes = 2 * kW * kH;
    static int fail(int e)
    {
        errno = e;
        return -1;
    }
    std::vector<std::vector<uint8_t>> bufs_;
    std::deque<uint32_t> queued_;
    bool gone_ = false;
};

// Frames 0..n-1 with sequence = index and t = kT0 + index / fps; `skip` indices are never delivered.
void script_frames(FakeV4l2 &dev, int n, bool mjpeg, const std::vector<int> &skip)
{
    for (int i = 0; i < n; i++) {
        bool skipped = false;
        for (int s : skip) skipped = skipped || s == i;
        if (skipped) continue;
        cv::Mat img = render(i);
        dev.script.push_back({mjpeg ? as_mjpeg(img) : as_yuyv(img), kT0 + i / kFps, static_cast<uint32_t>(i)});
    }
}

// centroid of the orange disc (R high, B low)
cv::Point2d find_disc(const cv::Mat &bgr)
{
    double sx = 0, sy = 0, n = 0;
    for (int y = 0; y < bgr.rows; y++)
        for (int x = 0; x < bgr.cols; x++) {
            cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
            if (p[2] > 192 && p[0] < 64) sx += x, sy += y, n++;
        }
    return n > 0 ? cv::Point2d(sx / n, sy / n) : cv::Point2d(NAN, NAN);
}

gs::CaptureConfig v4l2_config(const char *pixfmt)
{
    gs::CaptureConfig c;
    c.backend = "v4l2";
    c.device = "/dev/fake0";
    c.width = 1280;
    c.height = 720;
    c.fps = 60.0;
    c.pixel_format = pixfmt;
    return c;
}

// Read until the device errors out; returns the frames in order.
std::vector<gs::CaptureFrame> read_all(gs::Capture &cap, gs::ReadResult &last)
{
    std::vector<gs::CaptureFrame> out;
    for (int guard = 0; guard < 1000; guard++) {
        gs::CaptureFrame f;
        last = cap.read(f, 0);
        if (last == gs::ReadResult::frame) {
            f.bgr = f.bgr.clone();
            out.push_back(f);
        } else if (last != gs::ReadResult::timeout) {
            break;
        }
    }
    return out;
}

}  // namespace

// Asked 1280x720 MJPEG at 60: the device gives 320x240 at 30, which is taken
// and reported; the frames decode to the rendered picture; times are the
// driver's to the microsecond; two frames the driver skipped count as two
// drops by sequence and by time; the unplug ends it with a clean error and
// every buffer unmapped, the descriptor closed.
static void test_v4l2_mjpeg_negotiation_timestamps_drops_unplug(void)
{
    auto dev = std::make_shared<FakeV4l2>();
    script_frames(*dev, 12, true, {5, 6});
    std::string err;
    gs::CaptureError kind;
    auto cap = gs::open_v4l2(v4l2_config("auto"), dev, err, kind);
    TEST_ASSERT_NOT_NULL_MESSAGE(cap.get(), err.c_str());
    TEST_ASSERT_EQUAL_UINT32(V4L2_PIX_FMT_MJPEG, dev->pixfmt);
    TEST_ASSERT_EQUAL_INT(kW, cap->size().width);
    TEST_ASSERT_EQUAL_INT(kH, cap->size().height);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, kFps, cap->fps());
    TEST_ASSERT_TRUE_MESSAGE(cap->description().find("320x240 MJPG 30 fps") != std::string::npos, cap->description().c_str());
    TEST_ASSERT_EQUAL_INT(3, dev->maps);
    TEST_ASSERT_EQUAL_INT(1, dev->streamon);

    gs::ReadResult last;
    auto frames = read_all(*cap, last);
    TEST_ASSERT_EQUAL_INT(10, static_cast<int>(frames.size()));
    int k = 0;
    for (int i = 0; i < 12; i++) {
        if (i == 5 || i == 6) continue;
        const gs::CaptureFrame &f = frames[k];
        TEST_ASSERT_EQUAL_INT64(k, f.index);
        TEST_ASSERT_EQUAL_INT64(i, f.sequence);
        TEST_ASSERT_DOUBLE_WITHIN(1.5e-6, kT0 + i / kFps, f.t_s);
        // the driver's whole microseconds reach the core exactly (as the fake set them)
        const double t = kT0 + i / kFps, whole = std::floor(t);
        TEST_ASSERT_EQUAL_INT64(static_cast<int64_t>(whole) * 1000000 + std::lround((t - whole) * 1e6), f.t_us);
        cv::Point2d c = find_disc(f.bgr), truth = disc_centre(i);
        TEST_ASSERT_DOUBLE_WITHIN(0.3, truth.x, c.x);
        TEST_ASSERT_DOUBLE_WITHIN(0.3, truth.y, c.y);
        k++;
    }
    TEST_ASSERT_EQUAL_UINT64(2, cap->drops().by_sequence());
    TEST_ASSERT_EQUAL_UINT64(2, cap->drops().by_time());
    TEST_ASSERT_EQUAL_UINT64(2, cap->drops().dropped());
    TEST_ASSERT_EQUAL_STRING("driver", cap->time_origin());

    TEST_ASSERT_TRUE(last == gs::ReadResult::error);
    TEST_ASSERT_TRUE_MESSAGE(cap->error().find("/dev/fake0") != std::string::npos &&
                                 cap->error().find("went away") != std::string::npos,
                             cap->error().c_str());
    TEST_ASSERT_EQUAL_INT(3, dev->unmaps);
    TEST_ASSERT_EQUAL_INT(1, dev->closes);
    gs::CaptureFrame f;
    TEST_ASSERT_TRUE(cap->read(f, 0) == gs::ReadResult::error);  // stays failed
    cap.reset();
    TEST_ASSERT_EQUAL_INT(1, dev->closes);  // not closed twice
}

// A YUYV-only device: auto takes YUYV, colours and positions survive the conversion.
static void test_v4l2_yuyv_conversion(void)
{
    auto dev = std::make_shared<FakeV4l2>();
    dev->formats = {V4L2_PIX_FMT_YUYV};
    dev->vanish_at_end = false;
    script_frames(*dev, 4, false, {});
    std::string err;
    gs::CaptureError kind;
    auto cap = gs::open_v4l2(v4l2_config("auto"), dev, err, kind);
    TEST_ASSERT_NOT_NULL_MESSAGE(cap.get(), err.c_str());
    TEST_ASSERT_EQUAL_UINT32(V4L2_PIX_FMT_YUYV, dev->pixfmt);
    TEST_ASSERT_TRUE(cap->description().find("YUYV") != std::string::npos);
    gs::ReadResult last;
    auto frames = read_all(*cap, last);
    TEST_ASSERT_TRUE_MESSAGE(last == gs::ReadResult::timeout, "no more frames: a wait, not an error");
    TEST_ASSERT_EQUAL_INT(4, static_cast<int>(frames.size()));
    for (int i = 0; i < 4; i++) {
        cv::Point2d c = find_disc(frames[i].bgr), truth = disc_centre(i);
        TEST_ASSERT_DOUBLE_WITHIN(0.3, truth.x, c.x);
        TEST_ASSERT_DOUBLE_WITHIN(0.3, truth.y, c.y);
        cv::Vec3b bg = frames[i].bgr.at<cv::Vec3b>(5, 5);
        for (int ch = 0; ch < 3; ch++) TEST_ASSERT_INT_WITHIN(2, 128, bg[ch]);
        cv::Point2d t = disc_centre(i);
        cv::Vec3b ball = frames[i].bgr.at<cv::Vec3b>(static_cast<int>(t.y), static_cast<int>(t.x));
        TEST_ASSERT_INT_WITHIN(6, 0, ball[0]);
        TEST_ASSERT_INT_WITHIN(6, 130, ball[1]);
        TEST_ASSERT_INT_WITHIN(6, 255, ball[2]);
    }
    TEST_ASSERT_EQUAL_UINT64(0, cap->drops().dropped());
    cap.reset();
    TEST_ASSERT_EQUAL_INT(1, dev->streamoff);
    TEST_ASSERT_EQUAL_INT(dev->maps, dev->unmaps);
    TEST_ASSERT_EQUAL_INT(1, dev->closes);
}

// A time gap without a sequence gap (a driver that renumbers) still counts;
// a corrupt JPEG and a buffer flagged as an error are skipped and counted;
// a clock that is not monotonic is reported.
static void test_v4l2_time_gap_corrupt_frames_clock_flag(void)
{
    auto dev = std::make_shared<FakeV4l2>();
    dev->ts_flag = V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
    for (int i = 0; i < 8; i++) {
        double t = kT0 + (i < 4 ? i : i + 3) / kFps;  // 3 frame times missing after frame 3
        dev->script.push_back({as_mjpeg(render(i)), t, static_cast<uint32_t>(i)});
    }
    dev->script[5].bytes.resize(dev->script[5].bytes.size() / 3);  // a cut JPEG
    dev->script[5].bytes.resize(600);
    std::memset(dev->script[5].bytes.data() + 100, 0, 500);
    dev->script[6].error_flag = true;
    std::string err;
    gs::CaptureError kind;
    auto cap = gs::open_v4l2(v4l2_config("mjpeg"), dev, err, kind);
    TEST_ASSERT_NOT_NULL_MESSAGE(cap.get(), err.c_str());
    gs::ReadResult last;
    auto frames = read_all(*cap, last);
    TEST_ASSERT_EQUAL_INT(6, static_cast<int>(frames.size()));
    TEST_ASSERT_EQUAL_UINT64(2, cap->corrupt());
    TEST_ASSERT_EQUAL_UINT64(2, cap->drops().by_sequence());  // the two skipped ones
    TEST_ASSERT_EQUAL_UINT64(5, cap->drops().by_time());      // 3 never sent + the 2 skipped
    TEST_ASSERT_EQUAL_UINT64(5, cap->drops().dropped());
    TEST_ASSERT_EQUAL_STRING("driver_unknown_clock", cap->time_origin());
}

// Opening fails cleanly: a missing device, not a capture device, a format it
// lacks, a bad format name; nothing stays open.
static void test_v4l2_open_errors(void)
{
    std::string err;
    gs::CaptureError kind;
    auto dev = std::make_shared<FakeV4l2>();
    gs::CaptureConfig c = v4l2_config("auto");
    c.device = "/dev/video9";
    TEST_ASSERT_NULL(gs::open_v4l2(c, dev, err, kind).get());
    TEST_ASSERT_EQUAL_STRING("v4l2 /dev/video9: cannot open: No such file or directory", err.c_str());
    TEST_ASSERT_TRUE(kind == gs::CaptureError::device);

    dev = std::make_shared<FakeV4l2>();
    dev->caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
    TEST_ASSERT_NULL(gs::open_v4l2(v4l2_config("auto"), dev, err, kind).get());
    TEST_ASSERT_EQUAL_STRING("v4l2 /dev/fake0: not a video capture device", err.c_str());
    TEST_ASSERT_EQUAL_INT(dev->opens, dev->closes);

    dev = std::make_shared<FakeV4l2>();
    dev->formats = {V4L2_PIX_FMT_YUYV};
    TEST_ASSERT_NULL(gs::open_v4l2(v4l2_config("mjpeg"), dev, err, kind).get());
    TEST_ASSERT_EQUAL_STRING("v4l2 /dev/fake0: the device does not offer MJPEG", err.c_str());
    TEST_ASSERT_EQUAL_INT(dev->opens, dev->closes);

    dev = std::make_shared<FakeV4l2>();
    TEST_ASSERT_NULL(gs::open_v4l2(v4l2_config("rgb"), dev, err, kind).get());
    TEST_ASSERT_TRUE(kind == gs::CaptureError::usage);
    TEST_ASSERT_EQUAL_INT(dev->opens, dev->closes);
}

// Without a nominal rate the interval is learnt from the first frames.
static void test_drop_counter_learns_the_interval(void)
{
    gs::DropCounter d;
    d.reset(0.0);
    int64_t seq = 0;
    double t = 100.0;
    for (int i = 0; i < 10; i++) d.frame(t += 0.01, seq++);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.01, d.interval_s());
    TEST_ASSERT_EQUAL_UINT64(0, d.dropped());
    d.frame(t += 0.04, seq += 3);  // 3 missing
    TEST_ASSERT_EQUAL_UINT64(3, d.by_time());
    TEST_ASSERT_EQUAL_UINT64(3, d.by_sequence());
    d.frame(t += 0.014, seq++);  // jitter below 1.5 intervals: no drop
    TEST_ASSERT_EQUAL_UINT64(3, d.dropped());
}

// A live-like GStreamer source. count: t = n / fps exactly; position: the
// pipeline position when read, increasing, spanning about the clip (frames
// queued in appsink on a loaded machine get nearly equal times, so only the
// span is checked loosely).
static void test_gstreamer_videotestsrc(void)
{
    for (const char *mode : {"count", "position"}) {
        gs::CaptureConfig c;
        c.backend = "gstreamer";
        c.gst_time = mode;
        c.device = "videotestsrc num-buffers=40 ! video/x-raw,width=160,height=120,framerate=30/1 ! videoconvert ! appsink";
        std::string err;
        gs::CaptureError kind;
        auto cap = gs::open_capture(c, err, kind);
        err += " (videotestsrc is in gstreamer1.0-plugins-base: tools/setup_cam.sh)";
        TEST_ASSERT_NOT_NULL_MESSAGE(cap.get(), err.c_str());
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, 30.0, cap->fps());
        TEST_ASSERT_EQUAL_STRING(mode, cap->time_origin());
        std::vector<double> t;
        gs::CaptureFrame f;
        gs::ReadResult r;
        while ((r = cap->read(f, 100)) != gs::ReadResult::end) {
            TEST_ASSERT_TRUE(r == gs::ReadResult::frame);
            TEST_ASSERT_EQUAL_INT(160, f.bgr.cols);
            TEST_ASSERT_EQUAL_INT(120, f.bgr.rows);
            t.push_back(f.t_s);
            TEST_ASSERT_EQUAL_INT64(INT64_MIN, f.t_us);  // no integer clock: seconds only
        }
        TEST_ASSERT_EQUAL_INT(40, static_cast<int>(t.size()));
        for (size_t i = 1; i < t.size(); i++) {
            TEST_ASSERT_TRUE(t[i] > t[i - 1]);
            if (std::string(mode) == "count") TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.0 / 30, t[i] - t[i - 1]);
        }
        const double span = t.back() - t.front();
        TEST_ASSERT_TRUE_MESSAGE(span > 0.5 * 39 / 30 && span < 2.0 * 39 / 30, mode);
        if (std::string(mode) == "count") TEST_ASSERT_EQUAL_UINT64(0, cap->drops().dropped());
        std::printf("  videotestsrc, times from %s: %zu frames, first %.4f s, mean interval %.5f s\n", mode, t.size(),
                    t.front(), span / 39);
    }
    gs::CaptureConfig c;
    c.backend = "gstreamer";
    std::string err;
    gs::CaptureError kind;
    c.device = "videotestsrc ! video/x-raw,width=-5 ! appsink";  // caps that cannot be met
    TEST_ASSERT_NULL(gs::open_capture(c, err, kind).get());
    TEST_ASSERT_TRUE_MESSAGE(err.find("gstreamer: cannot start the pipeline") == 0, err.c_str());
    c.device = "videotestsrc ! fakesink";
    TEST_ASSERT_NULL(gs::open_capture(c, err, kind).get());
    TEST_ASSERT_TRUE(kind == gs::CaptureError::usage);
}

// No camera on this machine: the CameraManager starts, lists none, and the
// backend says so in one line.
static void test_libcamera_no_camera(void)
{
    gs::CaptureConfig c;
    c.backend = "libcamera";
    c.device = "auto";
    std::string err, err2;
    gs::CaptureError kind;
    if (!gs::have_libcamera()) {
        TEST_ASSERT_NULL(gs::open_capture(c, err, kind).get());
        TEST_ASSERT_TRUE_MESSAGE(err.find("no libcamera support") != std::string::npos, err.c_str());
        TEST_IGNORE_MESSAGE("built without libcamera: only the message checked");
    }
    int n = gs::libcamera_count_cameras(err2);
    TEST_ASSERT_TRUE_MESSAGE(n >= 0, err2.c_str());
    if (n > 0) TEST_IGNORE_MESSAGE("this machine has a camera: the no-camera path cannot be checked");
    TEST_ASSERT_NULL(gs::open_capture(c, err, kind).get());
    TEST_ASSERT_EQUAL_STRING("libcamera: no camera found", err.c_str());
    TEST_ASSERT_TRUE(kind == gs::CaptureError::device);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_v4l2_mjpeg_negotiation_timestamps_drops_unplug);
    RUN_TEST(test_v4l2_yuyv_conversion);
    RUN_TEST(test_v4l2_time_gap_corrupt_frames_clock_flag);
    RUN_TEST(test_v4l2_open_errors);
    RUN_TEST(test_drop_counter_learns_the_interval);
    RUN_TEST(test_gstreamer_videotestsrc);
    RUN_TEST(test_libcamera_no_camera);
    return UNITY_END();
}
