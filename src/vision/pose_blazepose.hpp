// pose_blazepose.hpp - BlazePose (MediaPipe's pose detector and landmark
// networks, converted to ONNX at setup) run by OpenCV's DNN module: 33 body
// keypoints per frame in image pixels for the core's BlazePose-33 layout.
//
// Per frame: when no person is tracked, the detector (224x224 letterbox) finds
// one and its two alignment keypoints (hip centre, a point fixing scale and
// rotation) give a rotated square ROI; the landmark network (256x256 crop of
// that ROI) gives 39 points, of which 33 are the keypoints and 33/34 are the
// alignment points for the next frame's ROI. The detector runs again only
// when the pose presence score drops below min_tracking (tracking lost); the
// lost frame is retried with the detector at once, so no frame is skipped.
// One person is kept (keep_person, docs/pose.md "One person"): the detector
// re-checks every recheck_s (every frame while someone else is near, or when
// the landmarks jump beyond what a body can do), in a thread of its own beside
// the tracked ROI's landmarks (side_thread.hpp); a re-detection takes the
// person that matches the tracked one (PoseKeeper), not the most confident;
// body parts whose colours are not the person's (PoseLook, pose_look.hpp) give
// c = 0, and a trunk that is not the person's gives no pose that frame.
// No landmark smoothing: the core fits the raw points (a filter would bend the
// free-flight parabola). Optionally (roi_smoothing) the ROI's two alignment
// points pass a one-euro filter as in MediaPipe, which steadies the crop of a
// still person; off by default: on the one real jump it raised the COM's
// residual about the flight parabola for full and heavy (lowered it for lite;
// docs/pose.md has the details and numbers).
#ifndef GS_POSE_BLAZEPOSE_HPP
#define GS_POSE_BLAZEPOSE_HPP

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pose_engine.hpp"

extern "C" {
#include "gravscale/gs_config.h"
#include "gravscale/gs_types.h"
}

namespace gs {

enum class PoseModel { lite, full, heavy };
const char *pose_model_name(PoseModel m);

// The [pose] section. Models dir: models_dir if set (--models DIR or the
// `models` key), else $GS_MODELS_DIR, else <source>/models (fetched at setup).
struct PoseConfig {
    std::string models_dir;
    PoseModel model = PoseModel::lite;
    PoseEngine engine = PoseEngine::automatic;  // OpenVINO when built in and its models are there, else OpenCV DNN
    int threads = 0;               // the engine's threads (OpenCV's are process-wide); 0 = its default (the CPUs allowed)
    double min_detection = 0.5;    // detector score that makes a person
    double min_tracking = 0.5;     // pose presence below this = tracking lost
    double nms_iou = 0.3;          // detections overlapping more are merged (weighted NMS)
    bool heatmap_refine = true;    // refine x, y with the landmark heatmap (as MediaPipe)
    bool roi_smoothing = false;    // one-euro filter on the tracked ROI's alignment points (never on keypoints);
                                   // off: it steadies a still person's crop, but the flight residuals were mixed (docs/pose.md)
    // Keeping one person (docs/pose.md, "One person"): while a person is tracked,
    // the detector re-checks the scene every recheck_s; while another person is
    // near, every frame. The landmarks are the tracked person's only when they
    // lie where that body can be (its motion predicted from the last accepted
    // frames) and nearer to it than to anyone else; otherwise the person's own
    // detection is tried, else the frame gives no pose (c = 0). A person unseen
    // for forget_s is forgotten: the next one found is a new person.
    bool keep_person = true;       // off: the old behaviour (follow the ROI, most confident when lost)
    double recheck_s = 0.25;       // detector census while tracking alone
    double forget_s = 1.0;         // a tracked person unseen this long is forgotten
};

// gs_cfg_handler for [pose]; ctx is a PoseConfig*. Keys: models, model,
// engine (auto|opencv|openvino), threads, min_detection, min_tracking, heatmap_refine (on|off),
// roi_smoothing (on|off).
gs_status pose_config_set(void *ctx, const char *key, size_t key_len, const char *value,
                          size_t value_len, char *msg, size_t cap);

// The models folder in force for cfg (see PoseConfig) and the two files used:
// OpenCV: pose_detection.onnx and pose_landmark_<model>_noseg.onnx when present
// (no segmentation output, faster), else pose_landmark_<model>.onnx; OpenVINO:
// the same graphs with the spec form of Clip, pose_detection_strict.onnx and
// pose_landmark_<model>_noseg_strict.onnx (OpenCV 4.6 reads only the other).
std::string pose_models_dir(const PoseConfig &cfg);
// The engine that runs cfg's networks: cfg.engine, or for automatic OpenVINO
// when this build has it and its two files are in the models folder, else OpenCV.
PoseEngine pose_engine_in_force(const PoseConfig &cfg);
std::string pose_detector_path(const PoseConfig &cfg);
std::string pose_landmark_path(const PoseConfig &cfg);
// true when both files exist; else false and err names the missing file and
// how to get it.
bool pose_models_present(const PoseConfig &cfg, std::string &err);

// ---- geometry (pure functions, tested without the networks) -------------------

// A rotated square in image pixels (OpenCV convention: pixel centres at integers).
// rotation_rad turns the crop's x axis to (cos, sin) in the image (y down), so a
// positive rotation is clockwise on screen; 0 = an upright person.
struct PoseRoi {
    double cx_px = 0.0, cy_px = 0.0;
    double size_px = 0.0;
    double rotation_rad = 0.0;
};

// MediaPipe's alignment-point rect: centre = (x0, y0), side = 2 x the distance
// to (x1, y1) x scale (1.25 for BlazePose), rotated so that the vector
// centre -> (x1, y1) points up in the crop (target angle 90 degrees).
PoseRoi pose_roi_from_alignment(double x0_px, double y0_px, double x1_px, double y1_px,
                                double scale = 1.25);

// 2x3 affine (CV_64F) mapping crop pixels (side x side) to image pixels.
cv::Mat pose_roi_crop_to_image(const PoseRoi &roi, int side);
// A point given in the crop's normalised coordinates (0..1 across the ROI,
// MediaPipe's convention) in image pixels.
cv::Point2d pose_roi_to_image(const PoseRoi &roi, double xn, double yn);

// SSD anchor centres of the detector (normalised 0..1; fixed size 1), in the
// network's output order: 2254 for the 224 input (28x28x2, 14x14x2, 7x7x6).
struct PoseAnchor {
    float x, y;
};
std::vector<PoseAnchor> pose_detector_anchors();

// One person found by the detector, in image pixels.
struct PoseDetection {
    float score = 0.0f;                      // sigmoid of the logit
    float xmin = 0, ymin = 0, xmax = 0, ymax = 0;
    float kp_x[4] = {0, 0, 0, 0}, kp_y[4] = {0, 0, 0, 0};  // 0 hip centre, 1 full-body scale point, 2/3 upper body
};

// Letterbox of a w x h image into the square detector input: image pixel
// x = (u - pad_x) / scale_x - 0.5 for u in continuous input coordinates.
struct PoseLetterbox {
    double scale_x = 1.0, scale_y = 1.0;
    double pad_x = 0.0, pad_y = 0.0;
    int side = 224;
};
PoseLetterbox pose_letterbox(int width, int height, int side = 224);

// Decode raw detector outputs (n x 12 regressors, n logits) against the anchors,
// keep scores >= min_score, merge overlaps (weighted NMS, IoU > nms_iou), and
// map to image pixels; best score first.
std::vector<PoseDetection> pose_decode_detections(const float *regressors, const float *logits,
                                                  const std::vector<PoseAnchor> &anchors,
                                                  const PoseLetterbox &lb, double min_score,
                                                  double nms_iou);

// ---- keeping one person (pure logic, tested without the networks) ----------------

// A body as the ROI rule sees it: the hip centre and the distance to the scale
// point (the detector's keypoints 0 and 1, the landmarks' alignment points 33
// and 34), image px.
struct PoseBody {
    double t_s = 0.0;
    double x_px = 0.0, y_px = 0.0;
    double r_px = 0.0;
};

// The tracked person's recent accepted bodies and the rules that say whether
// a body is that person: where it can be now (constant velocity from the last
// two accepted frames, the speed capped at max_speed_r_s body radii a second),
// how far from there (gate_r radii plus max_accel_r_s2 x dt^2 / 2) and how much
// its size may differ (size_ratio).
struct PoseKeeperConfig {
    double gate_r = 0.35;          // position gate at the frame after an accepted one, in body radii
    double max_speed_r_s = 8.0;    // a hip faster than this (radii/s) is no body (a jump's take-off: ~4)
    double max_accel_r_s2 = 60.0;  // widening of the gate with time since the last accepted frame
    double size_ratio = 1.4;       // r beyond this factor of the last accepted r is someone else
    double near_r = 2.2;           // another person whose hip is nearer than near_r x (r + its r) is near
    double history_s = 1.0;        // accepted bodies kept this long
};

class PoseKeeper {
public:
    explicit PoseKeeper(const PoseKeeperConfig &cfg = PoseKeeperConfig()) : cfg_(cfg) {}
    bool has() const { return !hist_.empty(); }
    double last_t() const { return hist_.empty() ? -1e300 : hist_.back().t_s; }
    // where the tracked body is expected at t (has() must be true)
    PoseBody predict(double t_s) const;
    // b is where the tracked body can be at its time
    bool plausible(const PoseBody &b) const;
    // normalised distance of b from the prediction (position in radii + size log-ratio)
    double cost(const PoseBody &b) const;
    // the candidate that is the tracked person: the plausible one of lowest cost; -1 none
    int match(const std::vector<PoseBody> &cands) const;
    // someone (not the tracked person) whose body reaches the tracked one's ROI
    bool near(const PoseBody &other, double t_s) const;
    // b is the tracked body and not one of others: plausible, and nearer to the
    // prediction than any other person is
    bool keeps(const PoseBody &b, const std::vector<PoseBody> &others) const;
    void accept(const PoseBody &b);
    void forget() { hist_.clear(); }

private:
    PoseKeeperConfig cfg_;
    std::vector<PoseBody> hist_;
};

// ---- the tracker ---------------------------------------------------------------

constexpr int kPoseKeypoints = 33;

struct PoseOutput {
    double t_s = 0.0;
    bool present = false;      // landmarks valid this frame
    bool detector_ran = false; // the detector ran this frame (start, or tracking lost)
    float presence = 0.0f;     // pose presence score of the landmark network 0..1; NaN not run
    float det_score = 0.0f;    // score of the detection used; NaN when the detector did not run
    gs_kp kp[kPoseKeypoints];  // image px; c = visibility x in_frame (0 when !present)
    float z_px[kPoseKeypoints];       // depth relative to the hips, in image px at the ROI's scale; < 0 nearer the camera; NaN none
    float visibility[kPoseKeypoints]; // sigmoid of the visibility logit (not occluded)
    float in_frame[kPoseKeypoints];   // sigmoid of the presence logit (inside the image)
    PoseRoi roi;               // the crop the landmarks came from
    int persons = -1;          // persons the detector found this frame; -1 when it did not run
    int covered = 0;           // bits (1 << PoseLookPart) of parts not the kept person's colours: their keypoints c = 0
    bool rejected = false;     // landmarks were found but judged not the tracked person's (someone
                               // else, or a body that cannot be there): present = false
    double det_ms = 0.0;       // this frame's detector time (pre- and post-processing included; at a census beside lm_ms)
    double lm_ms = 0.0;        // this frame's landmark time
};

class PoseTracker {
public:
    // Loads the two networks; on failure ok() is false and error() says why
    // (missing file with how to get it, or a load error).
    explicit PoseTracker(const PoseConfig &cfg);
    ~PoseTracker();
    PoseTracker(const PoseTracker &) = delete;
    PoseTracker &operator=(const PoseTracker &) = delete;

    // ok(): the networks loaded. error(): why not, or the first OpenCV error
    // while running (that frame gave no pose; the tracker goes on).
    bool ok() const;
    const std::string &error() const;
    // the inference engine running the networks (pose_engine_in_force)
    PoseEngine engine() const;

    // One 8-bit frame (BGR; grey and BGRA are converted), any size; fills *out.
    // Returns out->present. Other types give no pose.
    bool process(const cv::Mat &bgr, double t_s, PoseOutput *out);
    // Forget the tracked person: the next frame runs the detector.
    void reset();

    // The networks alone, for tests and benchmarks: every detection in the frame,
    // and the landmarks of a given ROI (present set from the presence score).
    std::vector<PoseDetection> detect(const cv::Mat &bgr);
    void landmarks(const cv::Mat &bgr, const PoseRoi &roi, PoseOutput *out, PoseRoi *next_roi);

private:
    struct Impl;
    std::unique_ptr<Impl> p_;
};

}  // namespace gs

#endif
