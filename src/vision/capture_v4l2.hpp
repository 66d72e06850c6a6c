// capture_v4l2.hpp - V4L2 capture through a thin device layer (open, close,
// ioctl, mmap, munmap, poll), so tests replace the kernel with a fake device
// that replays frames. Negotiates MJPEG or YUYV at the asked size and rate and
// accepts what the driver gives (reported in the description), streams with
// mmap buffers, timestamps from the buffers (timeval -> seconds; the
// V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC flag is checked and reported).
#pragma once

#include <poll.h>
#include <sys/types.h>

#include <memory>
#include <string>

#include "capture.hpp"

namespace gs {

class V4l2Io {
public:
    virtual ~V4l2Io();
    // The system calls, with their return conventions (-1 and errno on failure).
    virtual int open(const char *path, int flags) = 0;
    virtual int close(int fd) = 0;
    virtual int ioctl(int fd, unsigned long req, void *arg) = 0;
    virtual void *mmap(size_t len, int prot, int flags, int fd, off_t offset) = 0;
    virtual int munmap(void *addr, size_t len) = 0;
    virtual int poll(struct pollfd *fds, nfds_t n, int timeout_ms) = 0;
};

// The real kernel.
std::shared_ptr<V4l2Io> system_v4l2_io();

// nullptr on failure with one line in err and kind (device: missing, busy,
// not a capture device, no MJPEG/YUYV; usage: a bad pixel format name).
std::unique_ptr<Capture> open_v4l2(const CaptureConfig &cfg, std::shared_ptr<V4l2Io> io, std::string &err,
                                   CaptureError &kind);

}  // namespace gs
