// kiosk_live.cpp - the page's live view from the event stream (kiosk_live.hpp).
#include "kiosk_live.hpp"

#include <algorithm>
#include <cmath>

namespace gs::kiosk {

namespace {

constexpr double kKeepS = 6.0;           // samples kept (source time): a flight plus a margin
constexpr double kPlotMarginS = 0.4;     // the plot shows this much before take-off and after landing
constexpr double kPresentW = 0.3;        // a frame weighing less (head or legs out of view) is nobody
constexpr double kWarnShowS = 5.0;       // a live warning stays on screen this long
// a settled stance, as the core wants one for the standing size: the COM slower than a
// quarter of the body's size per second, upright, for 0.2 s
constexpr double kStillSpeedRel = 0.25;
constexpr double kUpright = 0.7;
constexpr double kSettleS = 0.2;
constexpr double kSpeedLagS = 0.1;

double nz(const json &v) { return v.is_number() ? v.get<double>() : NAN; }

}  // namespace

double num_or_nan(const json &ev, const char *key)
{
    auto it = ev.find(key);
    return it == ev.end() ? NAN : nz(*it);
}

bool Live::present() const
{
    if (samples_.empty()) return false;
    const Sample &s = samples_.back();
    return std::isfinite(s.x) && std::isfinite(s.y) && s.w >= kPresentW;
}

const char *Live::word() const { return word_.c_str(); }

void Live::on_sample(const json &ev, double wall_ms)
{
    Sample s{num_or_nan(ev, "t_s"), num_or_nan(ev, "x_px"), num_or_nan(ev, "y_px"), num_or_nan(ev, "w"),
             num_or_nan(ev, "size_px"), num_or_nan(ev, "upright"), wall_ms};
    if (!std::isfinite(s.t)) return;
    if (!std::isfinite(s.w)) s.w = 0.0;
    t_newest_ = s.t;
    samples_.push_back(s);
    while (!samples_.empty() && samples_.front().t < s.t - kKeepS) samples_.pop_front();
    if (!body_layout_) {
        stance_seen_ = true;  // a ball needs no stance
        return;
    }
    // the speed against the sample kSpeedLagS back
    double speed = NAN;
    for (auto it = samples_.rbegin() + 1; it != samples_.rend(); ++it)
        if (s.t - it->t >= kSpeedLagS) {
            if (std::isfinite(it->x) && std::isfinite(it->y) && it->w > 0.0)
                speed = std::hypot(s.x - it->x, s.y - it->y) / (s.t - it->t);
            break;
        }
    bool still = s.w >= kPresentW && std::isfinite(speed) && std::isfinite(s.size) && speed < kStillSpeedRel * s.size &&
                 s.upright >= kUpright;
    if (!still)
        still_since_ = NAN;
    else if (!std::isfinite(still_since_))
        still_since_ = s.t;
    else if (s.t - still_since_ >= kSettleS)
        stance_seen_ = true;
}

bool Live::on_event(const json &ev, double wall_ms)
{
    if (!ev.is_object()) return false;
    const std::string type = ev.value("event", std::string());
    bool changed = false;
    if (type == "sample") {
        on_sample(ev, wall_ms);
    } else if (type == "state") {
        in_air_ = ev.value("to", std::string()) == "airborne";
    } else if (type == "fit") {
        if (ev.value("purpose", std::string()) == "final") last_fit_ = ev;
    } else if (type == "start") {
        fps_ = num_or_nan(ev, "fps_source");
        body_layout_ = ev.value("layout", std::string()) != "point";
        samples_.clear();
        warnings_.clear();
        last_jump_ = stature_ = last_fit_ = nullptr;
        in_air_ = stance_seen_ = false;
        result_until_ = -INFINITY;
        changed = true;
    } else if (type == "jump") {
        json j = json::object();
        j["event"] = ev;
        j["se"] = uncertainties(ev);
        j["plot"] = plot_for(ev);
        j["received_ms"] = wall_ms;
        double t_land = num_or_nan(ev, "t_land_s");
        json land_wall = nullptr;
        for (const Sample &s : samples_)
            if (s.t >= t_land) {
                land_wall = s.wall_ms;
                break;
            }
        j["land_wall_ms"] = land_wall;
        last_jump_ = std::move(j);
        in_air_ = false;
        result_until_ = std::isfinite(t_land) ? t_land + cfg_.result_hold_s : t_newest_ + cfg_.result_hold_s;
        changed = true;
    } else if (type == "height") {
        stature_ = ev;
        changed = true;
    } else if (type == "session") {
        if (ev.value("state", std::string()) == "start") {
            stance_seen_ = false;
            still_since_ = NAN;
            stature_ = nullptr;
        }
        changed = true;
    } else if (type == "warning") {
        double t = num_or_nan(ev, "t_s");
        if (ev.contains("warnings") && ev["warnings"].is_array())
            for (const json &w : ev["warnings"])
                if (w.is_string()) warnings_.emplace_back(std::isfinite(t) ? t : t_newest_, w.get<std::string>());
        changed = true;
    }
    while (!warnings_.empty() && std::isfinite(t_newest_) && warnings_.front().first < t_newest_ - kWarnShowS) {
        warnings_.pop_front();
        changed = true;
    }
    const char *w = !present()                                          ? "no_one"
                    : in_air_                                           ? "in_the_air"
                    : std::isfinite(t_newest_) && t_newest_ < result_until_ ? "result"
                    : stance_seen_                                      ? "jump_now"
                                                                        : "stand_still";
    if (word_ != w) {
        word_ = w;
        changed = true;
    }
    return changed;
}

json Live::live_warnings() const
{
    json out = json::array();
    for (const auto &w : warnings_)
        if (std::find(out.begin(), out.end(), w.second) == out.end()) out.push_back(w.second);
    return out;
}

json Live::uncertainties(const json &jump) const
{
    json se = json::object(), from = json::object();
    double dt = std::isfinite(fps_) && fps_ > 0 ? 1.0 / fps_ : NAN;
    if (!std::isfinite(dt) && samples_.size() >= 2) {  // the stream's own interval
        std::vector<double> d;
        for (size_t i = 1; i < samples_.size(); i++) d.push_back(samples_[i].t - samples_[i - 1].t);
        std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
        dt = d[d.size() / 2];
    }
    const double T = num_or_nan(jump, "flight_time_s");
    const double sd_T = dt / std::sqrt(6.0);
    // name_m -> name_se_m, name_s -> name_se_s, name_m_s -> name_se_m_s
    auto se_key = [](const std::string &k) {
        for (const char *unit : {"_m_s", "_m", "_s"}) {
            std::string u = unit;
            if (k.size() > u.size() && k.compare(k.size() - u.size(), u.size(), u) == 0)
                return k.substr(0, k.size() - u.size()) + "_se" + u;
        }
        return k + "_se";
    };
    // relative SD from the timing: flight time and contact time ~ T, speeds ~ T, heights ~ T^2
    struct Rule {
        const char *key;
        double power;  // value ~ T^power
    };
    static const Rule rules[] = {{"flight_time_s", 1}, {"jump_height_m", 2}, {"com_rise_m", 2},
                                 {"takeoff_velocity_m_s", 1}, {"contact_time_s", 1}, {"height_m", 0}};
    for (const Rule &r : rules) {
        double v = num_or_nan(jump, r.key);
        if (!std::isfinite(v)) continue;
        double s = num_or_nan(jump, se_key(r.key).c_str());
        if (std::isfinite(s)) {
            se[r.key] = s;
            from[r.key] = "core";
            continue;
        }
        double rel = r.power > 0 && std::isfinite(T) && T > 0 ? r.power * sd_T / T : NAN;
        if (std::string(r.key) == "contact_time_s") rel = sd_T / v;
        if (std::isfinite(rel)) {
            se[r.key] = std::fabs(v) * rel;
            from[r.key] = "frame timing";
        }
    }
    return json{{"sd", se}, {"from", from}, {"frame_interval_s", std::isfinite(dt) ? json(dt) : json(nullptr)}};
}

json Live::plot_for(const json &jump) const
{
    const double t_to = num_or_nan(jump, "t_takeoff_s"), t_land = num_or_nan(jump, "t_land_s");
    if (!std::isfinite(t_to) || !std::isfinite(t_land) || !(t_land > t_to)) return nullptr;
    const double t_apex = num_or_nan(jump, "t_apex_s"), a = num_or_nan(jump, "a_px_s2");
    double g_deg = num_or_nan(jump, "g_dir_deg");
    if (!std::isfinite(g_deg)) g_deg = 0.0;
    const double q = num_or_nan(jump, "q_m_per_px");
    const bool metres = std::isfinite(q) && q > 0;
    const double scale = metres ? q : 1.0;
    const double sg = std::sin(g_deg * M_PI / 180.0), cg = std::cos(g_deg * M_PI / 180.0);
    const double t0 = t_to - kPlotMarginS, t1 = t_land + kPlotMarginS;
    // the core's fit window, when its final fit is this flight's
    double f0 = t_to, f1 = t_land;
    if (last_fit_.is_object()) {
        double a0 = num_or_nan(last_fit_, "t_first_s"), a1 = num_or_nan(last_fit_, "t_last_s");
        if (std::isfinite(a0) && std::isfinite(a1) && a0 < t_land && a1 > t_to) f0 = a0, f1 = a1;
    }
    struct P {
        double t, u, w;
    };
    std::vector<P> pts;
    for (const Sample &s : samples_)
        if (s.t >= t0 && s.t <= t1 && s.w > 0 && std::isfinite(s.x) && std::isfinite(s.y))
            pts.push_back({s.t, s.x * sg + s.y * cg, s.w});  // along gravity, down positive
    if (pts.empty()) return nullptr;
    const bool have_fit = std::isfinite(a) && std::isfinite(t_apex);
    auto model = [&](double t, double u_apex) { return u_apex + 0.5 * a * (t - t_apex) * (t - t_apex); };
    double u_apex = NAN, u_ref = NAN;
    if (have_fit) {  // the parabola's one free level: the in-flight samples' weighted mean offset
        double sw = 0, su = 0;
        for (const P &p : pts)
            if (p.t >= f0 && p.t <= f1) sw += p.w, su += p.w * (p.u - model(p.t, 0.0));
        if (sw > 0) u_apex = su / sw;
    }
    if (std::isfinite(u_apex)) {
        u_ref = model(t_to, u_apex);
    } else {  // no parabola: the level of the sample nearest take-off
        double best = INFINITY;
        for (const P &p : pts)
            if (std::fabs(p.t - t_to) < best) best = std::fabs(p.t - t_to), u_ref = p.u;
    }
    json samples = json::array(), curve = json::array();
    auto r4 = [](double v) { return std::round(v * 1e4) / 1e4; };
    for (const P &p : pts)
        samples.push_back({r4(p.t - t_to), r4((u_ref - p.u) * scale), r4(p.w), p.t >= f0 && p.t <= f1});
    json apex = nullptr;
    if (std::isfinite(u_apex)) {
        const int n = 40;
        for (int i = 0; i <= n; i++) {
            double t = t_to + (t_land - t_to) * i / n;
            curve.push_back({r4(t - t_to), r4((u_ref - model(t, u_apex)) * scale)});
        }
        apex = {r4(t_apex - t_to), r4((u_ref - u_apex) * scale)};
    }
    return json{{"units", metres ? "m" : "px"},
                {"t_ref_s", t_to},
                {"window", {0.0, r4(t_land - t_to)}},
                {"fit_window", {r4(f0 - t_to), r4(f1 - t_to)}},
                {"samples", samples},
                {"curve", curve},
                {"apex", apex}};
}

}  // namespace gs::kiosk
