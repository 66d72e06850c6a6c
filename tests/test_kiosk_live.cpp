// test_kiosk_live.cpp - the kiosk's live view (src/kiosk/kiosk_live.cpp) on
// event streams with known truth: the words a person reads follow presence,
// stillness, flight and result as scripted; the plot of an exactly ballistic
// centre of mass puts the parabola through every sample and its apex at the
// rise above take-off; uncertainties come from the event when it has them,
// else from frame timing (SD of the flight time = interval / sqrt(6)).
#include <cmath>
#include <string>

#include "kiosk_live.hpp"  // before unity.h, whose isnan/isinf macros break nlohmann's headers

extern "C" {
#include "unity.h"
}

using gs::kiosk::json;
using gs::kiosk::Live;
using gs::kiosk::LiveConfig;

void setUp(void) {}
void tearDown(void) {}

namespace {

constexpr double kFps = 30.0, kG = 9.81, kQ = 0.004;  // m per px at the subject
constexpr double kTo = 2.0, kT = 0.5;                 // take-off, flight time

json sample(double t, double x, double y, double w, double size, double upright)
{
    return json{{"event", "sample"}, {"t_s", t}, {"x_px", x}, {"y_px", y}, {"w", w}, {"size_px", size}, {"upright", upright}};
}

// the COM in px (y down): standing at y0 until take-off, then ballistic until landing
double com_y(double t)
{
    const double y0 = 500.0, v0 = kG * kT / 2.0, a_px = kG / kQ;
    if (t < kTo || t > kTo + kT) return y0;
    double dt = t - kTo;
    return y0 - (v0 / kQ) * dt + 0.5 * a_px * dt * dt;
}

json jump_event()
{
    const double v0 = kG * kT / 2.0;
    return json{{"event", "jump"}, {"track", 0}, {"index", 0}, {"t_takeoff_s", kTo}, {"t_land_s", kTo + kT},
                {"flight_time_s", kT}, {"t_apex_s", kTo + kT / 2}, {"a_px_s2", kG / kQ}, {"g_dir_deg", 0.0},
                {"q_m_per_px", kQ}, {"size_px", 440.0}, {"height_m", 1.76}, {"height_se_m", 0.012},
                {"jump_height_m", v0 * v0 / (2 * kG)}, {"takeoff_velocity_m_s", v0}, {"accepted", true},
                {"reason", nullptr}, {"warnings", json::array()}};
}

}  // namespace

// a visit as a person lives it: nobody, someone walking in, standing, the jump, the result
void test_words_follow_the_visit(void)
{
    Live lv(LiveConfig{1.0});
    lv.on_event(json{{"event", "start"}, {"fps_source", kFps}, {"layout", "blazepose33"}}, 0);
    TEST_ASSERT_EQUAL_STRING("no_one", lv.word());
    int i = 0;
    for (; i < 15; i++) lv.on_event(sample(i / kFps, NAN, NAN, 0.0, NAN, NAN), i);  // nobody
    TEST_ASSERT_EQUAL_STRING("no_one", lv.word());
    lv.on_event(json{{"event", "session"}, {"state", "start"}}, 0);
    for (; i < 30; i++) lv.on_event(sample(i / kFps, 100.0 + 20.0 * i, 500.0, 0.9, 440.0, 0.9), i);  // walking in
    TEST_ASSERT_EQUAL_STRING("stand_still", lv.word());
    int settled_at = -1;
    for (; i < 60; i++) {  // standing
        lv.on_event(sample(i / kFps, 700.0, 500.0, 0.9, 440.0, 0.9), i);
        if (settled_at < 0 && std::string(lv.word()) == "jump_now") settled_at = i;
    }
    TEST_ASSERT_EQUAL_STRING("jump_now", lv.word());
    // 0.1 s of speed lag after the last step, then 0.2 s settled
    TEST_ASSERT_INT_WITHIN(2, 30 + 3 + 6, settled_at);
    lv.on_event(json{{"event", "state"}, {"t_s", 2.3}, {"from", "ground"}, {"to", "airborne"}}, 0);
    TEST_ASSERT_EQUAL_STRING("in_the_air", lv.word());
    for (; i < 80; i++) lv.on_event(sample(i / kFps, 700.0, com_y(i / kFps), 0.9, 440.0, 0.9), i);
    lv.on_event(jump_event(), 1000);
    TEST_ASSERT_EQUAL_STRING("result", lv.word());
    for (; i < 104; i++) lv.on_event(sample(i / kFps, 700.0, 500.0, 0.9, 440.0, 0.9), i);  // t = 3.43 < 2.5 + 1
    TEST_ASSERT_EQUAL_STRING("result", lv.word());
    for (; i < 110; i++) lv.on_event(sample(i / kFps, 700.0, 500.0, 0.9, 440.0, 0.9), i);  // past the hold
    TEST_ASSERT_EQUAL_STRING("jump_now", lv.word());
    lv.on_event(sample(i / kFps, 700.0, 500.0, 0.1, 440.0, 0.9), i);  // head and legs out of view
    TEST_ASSERT_EQUAL_STRING("no_one", lv.word());
    // a new visit needs its own stance
    lv.on_event(json{{"event", "session"}, {"state", "start"}}, 0);
    i++;
    lv.on_event(sample(i / kFps, 700.0, 500.0, 0.9, 440.0, 0.9), i);
    TEST_ASSERT_EQUAL_STRING("stand_still", lv.word());
    // warnings last 5 s of source time
    lv.on_event(json{{"event", "warning"}, {"t_s", i / kFps}, {"warnings", {"camera_moved"}}}, 0);
    TEST_ASSERT_EQUAL_STRING("[\"camera_moved\"]", lv.live_warnings().dump().c_str());
    for (int k = 0; k < 160; k++, i++) lv.on_event(sample(i / kFps, 700.0, 500.0, 0.9, 440.0, 0.9), i);
    TEST_ASSERT_EQUAL_STRING("[]", lv.live_warnings().dump().c_str());
}

// an exactly ballistic COM: the drawn parabola passes through the samples and peaks at the rise
void test_plot_of_a_ballistic_flight(void)
{
    Live lv(LiveConfig{});
    lv.on_event(json{{"event", "start"}, {"fps_source", kFps}, {"layout", "blazepose33"}}, 0);
    for (int i = 0; i < 90; i++) lv.on_event(sample(i / kFps, 700.0, com_y(i / kFps), 0.9, 440.0, 0.9), 1000.0 + i);
    json j = jump_event();
    json p = lv.plot_for(j);
    TEST_ASSERT_EQUAL_STRING("m", p["units"].get<std::string>().c_str());
    const double rise = j["jump_height_m"].get<double>();
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, rise, p["apex"][1].get<double>());
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, kT / 2, p["apex"][0].get<double>());
    int in_flight = 0;
    for (const json &s : p["samples"]) {
        double t = s[0].get<double>(), h = s[1].get<double>();
        if (t >= 0 && t <= kT) {
            in_flight++;
            double want = (kG * kT / 2) * t - 0.5 * kG * t * t;  // metres above take-off
            TEST_ASSERT_DOUBLE_WITHIN(2e-4, want, h);
            TEST_ASSERT_TRUE(s[3].get<bool>());
        } else {
            TEST_ASSERT_DOUBLE_WITHIN(2e-4, 0.0, h);  // standing at the take-off level
        }
    }
    TEST_ASSERT_EQUAL_INT(16, in_flight);  // 0.5 s at 30 fps: frames 60 .. 75
    TEST_ASSERT_EQUAL_INT(41, static_cast<int>(p["curve"].size()));
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, 0.0, p["curve"][0][1].get<double>());
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, 0.0, p["curve"][40][1].get<double>());
    // unknown scale: pixels; no flight window: no plot
    j["q_m_per_px"] = nullptr;
    TEST_ASSERT_EQUAL_STRING("px", lv.plot_for(j)["units"].get<std::string>().c_str());
    TEST_ASSERT_DOUBLE_WITHIN(0.3, rise / kQ, lv.plot_for(j)["apex"][1].get<double>());
    j["t_land_s"] = nullptr;
    TEST_ASSERT_TRUE(lv.plot_for(j).is_null());
    // the jump's record keeps the event whole (fields this page does not know included)
    json k = jump_event();
    k["com_rise_m"] = 0.31;
    k["something_new"] = "kept";
    lv.on_event(k, 5000.0);
    TEST_ASSERT_EQUAL_STRING("kept", lv.last_jump()["event"]["something_new"].get<std::string>().c_str());
    TEST_ASSERT_DOUBLE_WITHIN(0.5, 1000.0 + 75, lv.last_jump()["land_wall_ms"].get<double>());  // frame 75 = t 2.5 s
    TEST_ASSERT_EQUAL_DOUBLE(5000.0, lv.last_jump()["received_ms"].get<double>());
}

void test_uncertainties(void)
{
    Live lv(LiveConfig{});
    lv.on_event(json{{"event", "start"}, {"fps_source", kFps}, {"layout", "blazepose33"}}, 0);
    json j = jump_event();
    j["com_rise_m"] = 0.31;
    json u = lv.uncertainties(j);
    const double sd_T = 1.0 / kFps / std::sqrt(6.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, sd_T, u["sd"]["flight_time_s"].get<double>());
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2 * sd_T / kT * j["jump_height_m"].get<double>(), u["sd"]["jump_height_m"].get<double>());
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, sd_T / kT * j["takeoff_velocity_m_s"].get<double>(),
                              u["sd"]["takeoff_velocity_m_s"].get<double>());
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2 * sd_T / kT * 0.31, u["sd"]["com_rise_m"].get<double>());
    TEST_ASSERT_EQUAL_DOUBLE(0.012, u["sd"]["height_m"].get<double>());
    TEST_ASSERT_EQUAL_STRING("core", u["from"]["height_m"].get<std::string>().c_str());
    TEST_ASSERT_EQUAL_STRING("frame timing", u["from"]["flight_time_s"].get<std::string>().c_str());
    // the core's own standard errors win
    j["flight_time_se_s"] = 0.004;
    j["takeoff_velocity_se_m_s"] = 0.02;
    u = lv.uncertainties(j);
    TEST_ASSERT_EQUAL_DOUBLE(0.004, u["sd"]["flight_time_s"].get<double>());
    TEST_ASSERT_EQUAL_DOUBLE(0.02, u["sd"]["takeoff_velocity_m_s"].get<double>());
    TEST_ASSERT_EQUAL_STRING("core", u["from"]["flight_time_s"].get<std::string>().c_str());
    // nulls stay unknown
    j["jump_height_m"] = nullptr;
    u = lv.uncertainties(j);
    TEST_ASSERT_FALSE(u["sd"].contains("jump_height_m"));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_words_follow_the_visit);
    RUN_TEST(test_plot_of_a_ballistic_flight);
    RUN_TEST(test_uncertainties);
    return UNITY_END();
}
