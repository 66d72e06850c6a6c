// ball_flights.hpp - what the video front end adds to a ball's flights, from the
// detections it holds (the core sees only centres and one size per frame):
//
//  * the size where gravity defines the scale: q = g / a_px is a scale along
//    gravity's direction in the image, so the ball's diameter is measured there,
//    from the matte's second moments over the flight with the smear of motion
//    blur and the perspective elongation of an off-axis sphere taken out
//    (ballistic.hpp, fit_size); across the motion when the pixels are known to
//    be square (the container's sample aspect ratio applied, or the ball's own
//    shape round). Its standard error is honest: the fit's scatter plus what the
//    camera's unknown blur and the matte's edge leave (a ball 8 px across is not
//    known to 1 %);
//  * geometry: a flight whose positions along gravity keep a trend a parabola
//    cannot follow (an acceleration that changes along the flight beyond what
//    air drag can do: a camera tilted toward the fall, motion in depth) is
//    rejected as not_planar;
//  * the residual's limit: the core's share of the size, or the centre noise the
//    clip's own detections show for a ball of this size when that is larger (a
//    small ball's centroid is noisier than a fixed share of its size);
//  * motion in depth: a ball whose image size follows its depth is measured in
//    its own diameters ((x - cx) / d, (y - cy) / d are its position in diameters
//    at any depth and focal length), where gravity's g / D is the acceleration;
//  * flights the core cannot seed: the core starts a flight at an apex, so a
//    ball dropped from rest (or one that leaves the frame before its apex) is
//    found here, as a parabola over the track's detections between two breaks,
//    and reported through the same events when the core did not report it.
#ifndef GS_BALL_FLIGHTS_HPP
#define GS_BALL_FLIGHTS_HPP

#include <cstdint>
#include <map>
#include <vector>

#include "ball_detector.hpp"
#include "ballistic.hpp"

extern "C" {
#include "gravscale/gs_config.h"
#include "gravscale/gs_event.h"
}

namespace gs {

struct BallFlightsOptions {
    gs_core_config core;         // the thresholds a flight is judged by (as the core's)
    double g_m_s2 = 9.81;
    double psf_sigma_px = 1.0;   // the camera's blur assumed (BallConfig::psf_sigma_px)
    bool square_pixels = false;  // the detections' x is already scaled by the container's aspect ratio
    double frame_w = 0, frame_h = 0;  // in the detections' units (the optical axis at the centre)
};

// What the judge measured on one flight (also kept for reports and tests).
struct FlightSize {
    bool ok = false;
    double size_px = NAN, size_se_px = NAN;
    bool along_gravity = false;     // the non-square model's diameter along gravity (else the square one)
    double aspect = NAN, aspect_se = NAN;
    double trend_change = NAN, trend_f = NAN, trend_allow = NAN;
    bool not_planar = false;
    double a_sys_rel = 0.0;         // the acceleration's bias bound from a rolling shutter (relative)
    double trend_rms4_px = NAN;     // the quartic's residual
    double psf_sigma_px = NAN;      // the camera's blur used (measured, or the configured one)
    double a_apex_px_s2 = NAN, a_apex_se_px_s2 = NAN;  // the quartic's acceleration at the apex
    size_t n = 0;
};

class BallFlights {
public:
    explicit BallFlights(const BallFlightsOptions &o);

    // Every detection, per track in time order (x and the moments already scaled
    // to square pixels when square_pixels).
    void add(const BallObs &o);

    // A flight the core found: size along gravity, its SE, the geometry test;
    // may reject it (not_planar).
    void judge(gs_ev_jump *j);

    // Flights the core did not report (no apex inside): every one whose last
    // detection is older than t_now_s - wait_s (all of them when flush).
    void take_pending(double t_now_s, bool flush, std::vector<gs_ev_jump> &out);

    // The detector's rolling shutter estimate (s per row; 0: none found, then one
    // frame time per frame height is what a phone's readout may be).
    void set_rolling_shutter(double s_per_row) { rs_k_ = s_per_row; }

    const std::vector<FlightSize> &measured() const { return measured_; }

private:
    struct Arc {
        std::vector<BallObs> pts;
        Parabola fit;
    };
    struct TrackState {
        std::vector<BallObs> obs;       // recent detections (bounded)
        Arc arc;                        // the open arc
        std::vector<std::pair<double, double>> core_windows;  // flights the core reported
        std::vector<Arc> pending;       // closed apex-less arcs waiting for the core
        std::vector<double> breaks;     // times where a new arc began (the parabola broke)
    };

    void close_arc(int track, TrackState &ts);
    FlightSize measure(const std::vector<BallObs> &pts, const Parabola &fit, double a_px_s2);
    bool flight_from_arc(int track, const Arc &a, gs_ev_jump *j);
    // 1: measured in depth (j rewritten), -1: moving in depth but not measurable so
    // (gravity out of the image's plane, too uncertain; j rejected when its size is
    // beyond the bound g / a), 0: not moving in depth
    int depth_flight(const std::vector<BallObs> &pts, gs_ev_jump *j) const;
    double frame_dt(const std::vector<BallObs> &pts) const;
    double centre_var_px2(double d_px) const;
    bool residual_ok(double rms_px, size_t n, double d_px) const;

    BallFlightsOptions opt_;
    std::map<int, TrackState> tracks_;
    std::vector<FlightSize> measured_;
    // the pixels' shape, pooled over flights (inverse-variance weights)
    double aspect_w_ = 0.0, aspect_sum_ = 0.0;
    double rs_k_ = 0.0;
    int n_tested_ = 0, n_not_planar_ = 0;  // flights the geometry test ran on, and failed
    std::vector<double> psf_seen_;  // the blur's variance from each clean detection (px^2)
    std::vector<double> centre_noise_;  // per 4 consecutive detections: centre variance x diameter (px^3)
};

}  // namespace gs

#endif
