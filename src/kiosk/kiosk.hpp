// kiosk.hpp - the gym kiosk (docs/kiosk.md): a results page served by
// `gravscale cam` itself (civetweb, Debian's libcivetweb-dev), live by
// server-sent events, athletes and their history in SQLite, a JSON API under
// /api/ and CSV export. It consumes the daemon's events as JSON lines (trace
// included) like a sink; the core knows nothing of it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

extern "C" {
#include "gravscale/gs_config.h"
}

namespace gs::kiosk {

// [kiosk] (docs/kiosk.md has the table)
struct Config {
    bool present = false;        // a key was given: the kiosk is on (enabled = no turns it off)
    int enabled = -1;            // -1 not written
    std::string bind = "127.0.0.1";
    uint16_t port = 8080;        // 0: a free one (printed on stderr)
    std::string db = "kiosk.sqlite";  // relative to the working directory (the unit's StateDirectory)
    std::string token;           // needed for every change when bind is not a loopback address
    bool open_read = true;       // on such an address: read-only pages and the API's reads without the token
    bool wait_for_athlete = false;  // file and keypoint sources: start only once an athlete is named
    double result_hold_s = 4.0;  // "result" stays on screen this long after the landing
    uint32_t max_viewers = 8;    // live pages at once (each holds one server thread)
    std::string title = "gravscale";
    bool on() const { return enabled >= 0 ? enabled == 1 : present; }
};

// The [kiosk] section for gs_cfg_parse, and the checks after parsing
// (a non-loopback bind needs a token of at least 16 characters).
gs_cfg_section config_section(Config &c);
gs_status config_check(const Config &c, gs_cfg_error &e);
bool is_loopback(const std::string &numeric_ipv4);

class Kiosk {
public:
    // Opens the database and starts the server; nullptr with err (one line:
    // the file, the port in use, the reason).
    static std::unique_ptr<Kiosk> start(const Config &c, std::string &err);
    ~Kiosk();  // stops the server (live pages are told and closed first)

    // Every event of the daemon as one JSON line (trace events and status lines too).
    void on_line(const char *line, size_t len);
    // wait_for_athlete: true until an athlete is named on the page
    bool holding() const;
    // The source ended (a file): the page says so and stays up.
    void source_ended();
    uint16_t port() const;
    std::string url() const;

    struct Impl;

private:
    explicit Kiosk(std::unique_ptr<Impl> p);
    std::unique_ptr<Impl> p_;
};

}  // namespace gs::kiosk
