// capture_libcamera.hpp - libcamera 0.0.3 capture (CameraManager, one stream
// configuration, a ring of requests, SensorTimestamp per completed request).
// Built only when pkg-config finds libcamera; otherwise open_libcamera says so.
#pragma once

#include <memory>
#include <string>

#include "capture.hpp"

namespace gs {

// device: "" or "auto" = the first camera, a number = that index, else a camera id.
// With no camera: nullptr and "libcamera: no camera found".
std::unique_ptr<Capture> open_libcamera(const CaptureConfig &cfg, std::string &err, CaptureError &kind);

// Start a CameraManager and count its cameras (-1 and err when it cannot start
// or this build has no libcamera).
int libcamera_count_cameras(std::string &err);

}  // namespace gs
