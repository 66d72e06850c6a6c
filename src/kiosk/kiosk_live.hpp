// kiosk_live.hpp - what the results page shows now, from the daemon's events
// (JSON lines, trace included) as they come: the live state in words (no one in
// view / stand still / jump now / in the air / result), the last jump with its
// uncertainties and the COM track with the fitted parabola, live warnings.
// Guidance only: every number comes from the core's events; the words follow
// the trace's samples and state changes. Fields the page does not know are kept
// and passed on; nulls stay null.
#pragma once

#include <cstdint>
#include <deque>
#include <string>

#include <nlohmann/json.hpp>

namespace gs::kiosk {

using json = nlohmann::json;

struct LiveConfig {
    double result_hold_s = 4.0;  // the word "result" stays this long after the landing (source time)
};

class Live {
public:
    explicit Live(const LiveConfig &c) : cfg_(c) {}

    // One event; wall_ms is the wall clock (ms since 1970) when it arrived.
    // Returns true when the page's view changed.
    bool on_event(const json &ev, double wall_ms);

    // "no_one", "stand_still", "jump_now", "in_the_air", "result"
    const char *word() const;
    // the last jump: the event as emitted, "se" (uncertainties and where they come
    // from), "plot" (track, parabola, windows), "received_ms", "land_wall_ms"; null before one
    const json &last_jump() const { return last_jump_; }
    // warning names that started within the last 5 s of source time (camera_moved, ...)
    json live_warnings() const;
    double fps() const { return fps_; }
    double t_newest_s() const { return t_newest_; }
    const json &stature() const { return stature_; }  // the visit's latest height event, null before one

    // The COM track of [t0, t1] with the parabola the core fitted (acceleration,
    // direction and apex time from the jump event), heights in metres above the
    // take-off level (pixels when the scale is unknown). Public for the tests.
    json plot_for(const json &jump) const;
    // Uncertainties of the jump's numbers: the event's own *_se_* fields where it
    // has them, else from frame timing (each boundary within one frame interval:
    // SD of the flight time = interval / sqrt(6)). Public for the tests.
    json uncertainties(const json &jump) const;

private:
    struct Sample {
        double t, x, y, w, size, upright, wall_ms;
    };
    void on_sample(const json &ev, double wall_ms);
    bool present() const;

    LiveConfig cfg_;
    std::deque<Sample> samples_;   // the last few seconds of source time
    json last_jump_ = nullptr, last_fit_ = nullptr, stature_ = nullptr;
    std::deque<std::pair<double, std::string>> warnings_;  // (source time, name)
    double fps_ = NAN, t_newest_ = NAN, result_until_ = -INFINITY;
    double still_since_ = NAN;
    bool in_air_ = false, stance_seen_ = false, body_layout_ = true;
    std::string word_ = "no_one";
};

// A number from an event, NaN when absent or null.
double num_or_nan(const json &ev, const char *key);

}  // namespace gs::kiosk
