// kiosk_server.cpp - the kiosk: events in (the daemon's loop thread), the
// page, the live stream and the API out (civetweb's worker threads), one mutex
// between them. Routes and rules: docs/kiosk.md.
#include "kiosk.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>

#include <sys/time.h>

#include <civetweb.h>

#include "kiosk_db.hpp"
#include "kiosk_live.hpp"
#include "kiosk_www.hpp"

namespace gs::kiosk {

namespace {

constexpr size_t kBodyMax = 16 * 1024;
constexpr int kKeepAliveS = 15;
constexpr size_t kListMax = 30;  // jumps listed on the live page (the latest)  // a comment line this often tells a dead live page from a quiet one

double wall_ms()
{
    struct timeval tv;
    gettimeofday(&tv, nullptr);
    return tv.tv_sec * 1000.0 + tv.tv_usec / 1000.0;
}

bool const_time_eq(const std::string &a, const std::string &b)
{
    if (a.size() != b.size()) return false;
    unsigned char d = 0;
    for (size_t i = 0; i < a.size(); i++) d |= static_cast<unsigned char>(a[i] ^ b[i]);
    return d == 0;
}

const char *status_text(int code)
{
    switch (code) {
    case 200: return "OK";
    case 201: return "Created";
    case 204: return "No Content";
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 409: return "Conflict";
    case 411: return "Length Required";
    case 413: return "Payload Too Large";
    case 415: return "Unsupported Media Type";
    case 503: return "Service Unavailable";
    default: return "Error";
    }
}

void reply(mg_connection *c, int code, const char *type, const std::string &body, const char *extra = nullptr)
{
    mg_printf(c,
              "HTTP/1.1 %d %s\r\nContent-Type: %s\r\nContent-Length: %zu\r\nCache-Control: no-store\r\n"
              "X-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\nReferrer-Policy: no-referrer\r\n%s\r\n",
              code, status_text(code), type, body.size(), extra ? extra : "");
    if (!body.empty()) mg_write(c, body.data(), body.size());
}

int reply_json(mg_connection *c, int code, const json &j)
{
    reply(c, code, "application/json; charset=utf-8", j.dump(-1, ' ', false, json::error_handler_t::replace));
    return code;
}

int error(mg_connection *c, int code, const std::string &why) { return reply_json(c, code, json{{"error", why}}); }

// /api/athletes/12 -> 12; nullopt unless the rest is a decimal id
std::optional<int64_t> id_after(const std::string &path, const std::string &prefix)
{
    if (path.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
    std::string rest = path.substr(prefix.size());
    if (rest.empty() || rest.size() > 15 || rest.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    return std::stoll(rest);
}

std::string query_param(const mg_request_info *ri, const char *name)
{
    if (!ri->query_string) return "";
    char buf[128];
    int n = mg_get_var(ri->query_string, std::strlen(ri->query_string), name, buf, sizeof buf);
    return n >= 0 ? std::string(buf, static_cast<size_t>(n)) : std::string();
}

bool day_ok(const std::string &d)
{
    int y, m, dd;
    char tail;
    return d.size() == 10 && std::sscanf(d.c_str(), "%4d-%2d-%2d%c", &y, &m, &dd, &tail) == 3 && m >= 1 && m <= 12 &&
           dd >= 1 && dd <= 31;
}

}  // namespace

struct Kiosk::Impl {
    Config cfg;
    Db db;
    Live live;
    mutable std::mutex mu;
    std::condition_variable cv;
    uint64_t seq = 1;
    std::string snapshot = "{}";
    bool stopping = false, ended = false;
    uint32_t viewers = 0;
    mg_context *ctx = nullptr;
    uint16_t port = 0;
    std::optional<int64_t> athlete;  // the current athlete
    std::string athlete_name;
    int64_t run = 0;
    std::map<uint32_t, int64_t> open;  // track -> open visit
    std::map<uint32_t, bool> implicit; // ... opened by a jump (no visits: a ball)
    json jumps = json::array(), best = nullptr, mean = nullptr, status = nullptr;
    size_t n_jumps = 0;

    explicit Impl(const Config &c) : cfg(c), live(LiveConfig{c.result_hold_s}) {}

    // ---- events in (the daemon's thread) ----
    void on_event(const json &ev, double ms);
    void refresh_jumps();
    void publish();  // under mu
    // ---- requests (civetweb's threads) ----
    int handle(mg_connection *c);
    int serve_events(mg_connection *c);
    int api(mg_connection *c, const mg_request_info *ri, const std::string &path, const std::string &method);
    bool allowed(mg_connection *c, const mg_request_info *ri, bool changes);
    bool read_body(mg_connection *c, const mg_request_info *ri, json &body);
    int set_current(mg_connection *c, const json &body);
};

// ---- events ----------------------------------------------------------------------

void Kiosk::Impl::refresh_jumps()
{
    Filter f;
    json all = json::array();
    if (athlete) {
        f.athlete = athlete;
        f.day = Db::today_local();
        all = db.jumps(f);
    } else if (open.count(0)) {
        f.session = open[0];
        all = db.jumps(f);
    }
    best = mean = nullptr;
    double sum_h = 0, sum_t = 0, sum_v = 0;
    int n = 0, nt = 0, nv = 0;
    for (const json &j : all) {
        if (!j.value("accepted", false) || !j["jump_height_m"].is_number()) continue;
        double h = j["jump_height_m"].get<double>();
        if (best.is_null() || h > best["jump_height_m"].get<double>()) best = j;
        sum_h += h, n++;
        if (j["flight_time_s"].is_number()) sum_t += j["flight_time_s"].get<double>(), nt++;
        if (j["takeoff_velocity_m_s"].is_number()) sum_v += j["takeoff_velocity_m_s"].get<double>(), nv++;
    }
    if (!best.is_null()) best.erase("event_json");
    if (n)
        mean = {{"jump_height_m", sum_h / n},
                {"flight_time_s", nt ? json(sum_t / nt) : json(nullptr)},
                {"takeoff_velocity_m_s", nv ? json(sum_v / nv) : json(nullptr)},
                {"n", n}};
    // the page lists the latest; the history page has them all
    jumps = json::array();
    n_jumps = all.size();
    for (size_t i = all.size() > kListMax ? all.size() - kListMax : 0; i < all.size(); i++) {
        all[i].erase("event_json");
        jumps.push_back(std::move(all[i]));
    }
}

void Kiosk::Impl::publish()
{
    const bool holding = cfg.wait_for_athlete && !athlete;
    json s = {{"seq", seq},
              {"wall_ms", wall_ms()},
              {"title", cfg.title},
              {"word", holding ? "waiting" : live.word()},
              {"holding", holding},
              {"ended", ended},
              {"athlete", athlete ? json{{"id", *athlete}, {"name", athlete_name}} : json(nullptr)},
              {"last_jump", live.last_jump()},
              {"stature", live.stature()},
              {"jumps", jumps},
              {"n_jumps", n_jumps},
              {"best", best},
              {"mean", mean},
              {"warnings", live.live_warnings()},
              {"status", status},
              {"db_error", db.write_error().empty() ? json(nullptr) : json(db.write_error())},
              {"fps", std::isfinite(live.fps()) ? json(live.fps()) : json(nullptr)}};
    snapshot = s.dump(-1, ' ', false, json::error_handler_t::replace);
    seq++;
    cv.notify_all();
}

void Kiosk::Impl::on_event(const json &ev, double ms)
{
    bool changed = live.on_event(ev, ms);
    const std::string type = ev.value("event", std::string());
    const uint32_t track = ev.contains("track") && ev["track"].is_number_unsigned() ? ev["track"].get<uint32_t>() : 0;
    if (type == "start") {
        run = db.add_run(ev);
        open.clear();
        implicit.clear();
    } else if (type == "session") {
        if (ev.value("state", std::string()) == "start") {
            double t = num_or_nan(ev, "t_start_s");
            json sn = ev.contains("session") && ev["session"].is_number_integer() ? ev["session"] : json(nullptr);
            open[track] = db.open_session(run, track, sn.is_null() ? std::nullopt : std::optional<int64_t>(sn.get<int64_t>()),
                                          athlete, t);
            implicit[track] = false;
        } else if (open.count(track)) {
            db.end_session(open[track], ev, nullptr);
            open.erase(track);
        }
        refresh_jumps();
    } else if (type == "jump") {
        if (!open.count(track)) {  // no visits (a ball): one per run and track
            open[track] = db.open_session(run, track, std::nullopt, athlete, num_or_nan(ev, "t_takeoff_s"));
            implicit[track] = true;
        }
        const json &lj = live.last_jump();
        db.add_jump(open[track], ev, lj.is_object() ? lj["plot"] : json(nullptr));
        refresh_jumps();
    } else if (type == "height") {
        if (open.count(track)) db.session_height(open[track], ev);
    } else if (type == "summary") {
        if (open.count(track) && implicit[track]) {
            db.end_session(open[track], ev, "end_of_stream");
            open.erase(track);
        }
    } else if (type == "status") {
        status = ev;
        changed = true;
    }
    if (changed) publish();
}

// ---- requests -----------------------------------------------------------------

bool Kiosk::Impl::allowed(mg_connection *c, const mg_request_info *ri, bool changes)
{
    const bool local = is_loopback(cfg.bind);
    if (local) {
        // a page from elsewhere reaching this port through a name that points here (DNS rebinding)
        const char *host = mg_get_header(c, "Host");
        std::string h = host ? host : "";
        size_t colon = h.rfind(':');
        std::string name = colon == std::string::npos ? h : h.substr(0, colon);
        if (!(name == "localhost" || is_loopback(name))) {
            error(c, 403, "this kiosk answers only as localhost or 127.0.0.1");
            return false;
        }
    }
    if (changes) {
        // a change from another site's page: refused by its Origin
        const char *origin = mg_get_header(c, "Origin");
        const char *host = mg_get_header(c, "Host");
        if (origin && !(host && std::string(origin) == std::string("http://") + host)) {
            error(c, 403, "a change from another site's page");
            return false;
        }
    }
    if (local || (!changes && cfg.open_read)) return true;
    std::string given;
    const char *auth = mg_get_header(c, "Authorization");
    if (auth && std::strncmp(auth, "Bearer ", 7) == 0) given = auth + 7;
    if (given.empty() && !changes) {  // reads also by the page's cookie (EventSource sends no headers)
        char buf[160];
        const char *cookie = mg_get_header(c, "Cookie");
        if (cookie && mg_get_cookie(cookie, "gs_token", buf, sizeof buf) > 0) given = buf;
    }
    (void)ri;
    if (given.empty() || !const_time_eq(given, cfg.token)) {
        error(c, 401, given.empty() ? "this needs the kiosk's token" : "wrong token");
        return false;
    }
    return true;
}

bool Kiosk::Impl::read_body(mg_connection *c, const mg_request_info *ri, json &body)
{
    body = json::object();
    if (ri->content_length <= 0) return true;
    const char *type = mg_get_header(c, "Content-Type");
    if (!type || std::strncmp(type, "application/json", 16) != 0) {
        error(c, 415, "send JSON (Content-Type: application/json)");
        return false;
    }
    if (static_cast<unsigned long long>(ri->content_length) > kBodyMax) {
        error(c, 413, "the body is larger than 16 KB");
        return false;
    }
    std::string text(static_cast<size_t>(ri->content_length), '\0');
    size_t got = 0;
    while (got < text.size()) {
        int n = mg_read(c, &text[got], text.size() - got);
        if (n <= 0) break;
        got += static_cast<size_t>(n);
    }
    if (got != text.size()) {
        error(c, 400, "the body ended early");
        return false;
    }
    body = json::parse(text, nullptr, false);
    if (body.is_discarded() || !body.is_object()) {
        error(c, 400, "the body is not a JSON object");
        return false;
    }
    return true;
}

int Kiosk::Impl::set_current(mg_connection *c, const json &body)
{
    std::optional<int64_t> id;
    std::string name;
    if (body.contains("athlete_id")) {
        if (!body["athlete_id"].is_number_integer()) return error(c, 400, "athlete_id must be a whole number");
        id = body["athlete_id"].get<int64_t>();
        if (!db.athlete_exists(*id)) return error(c, 404, "no athlete " + std::to_string(*id));
    } else if (body.contains("name")) {
        std::string why;
        if (!body["name"].is_string() || !athlete_name_ok(body["name"].get<std::string>(), name, why))
            return error(c, 400, body["name"].is_string() ? why : "name must be text");
        bool created;
        id = db.athlete_named(name, created);
        if (!id || !*id) return error(c, 503, "the history could not be written: " + db.write_error());
    } else {
        return error(c, 400, "give name or athlete_id");
    }
    json a = db.athlete(*id);
    athlete = id;
    athlete_name = a["name"].get<std::string>();
    // the visit in progress is this athlete's
    if (open.count(0)) db.set_session_athlete(open[0], athlete);
    refresh_jumps();
    publish();
    return reply_json(c, 200, json{{"id", *id}, {"name", athlete_name}});
}

int Kiosk::Impl::api(mg_connection *c, const mg_request_info *ri, const std::string &path, const std::string &m)
{
    const bool get = m == "GET";
    json body;
    if (!get && !read_body(c, ri, body)) return 400;
    std::lock_guard<std::mutex> lk(mu);
    if (path == "/api/state") {
        if (!get) return error(c, 405, "GET only");
        reply(c, 200, "application/json; charset=utf-8", snapshot);
        return 200;
    }
    if (path == "/api/current") {
        if (get) return reply_json(c, 200, athlete ? json{{"id", *athlete}, {"name", athlete_name}} : json(nullptr));
        if (m == "PUT" || m == "POST") return set_current(c, body);
        if (m == "DELETE") {
            athlete.reset();
            athlete_name.clear();
            refresh_jumps();
            publish();
            return reply_json(c, 200, nullptr);
        }
        return error(c, 405, "GET, PUT or DELETE");
    }
    if (path == "/api/athletes") {
        if (get) return reply_json(c, 200, db.athletes());
        if (m != "POST") return error(c, 405, "GET or POST");
        std::string name, why;
        if (!body.contains("name") || !body["name"].is_string() || !athlete_name_ok(body["name"].get<std::string>(), name, why))
            return error(c, 400, body.contains("name") ? why : "give name");
        bool created;
        int64_t id = db.athlete_named(name, created);
        if (!id) return error(c, 503, "the history could not be written: " + db.write_error());
        return reply_json(c, created ? 201 : 200, db.athlete(id));
    }
    if (auto id = id_after(path, "/api/athletes/")) {
        if (!db.athlete_exists(*id)) return error(c, 404, "no athlete " + std::to_string(*id));
        if (get) return reply_json(c, 200, db.athlete(*id));
        if (m != "PATCH") return error(c, 405, "GET or PATCH");
        std::string name, why, err;
        if (!body.contains("name") || !body["name"].is_string() || !athlete_name_ok(body["name"].get<std::string>(), name, why))
            return error(c, 400, body.contains("name") ? why : "give name");
        if (!db.rename_athlete(*id, name, err)) return error(c, 409, err);
        if (athlete == id) athlete_name = name, publish();
        return reply_json(c, 200, db.athlete(*id));
    }
    Filter f;
    auto parse_filter = [&](std::string &why) {
        std::string a = query_param(ri, "athlete"), s = query_param(ri, "session"), d = query_param(ri, "day");
        if (!a.empty()) {
            auto v = id_after("/" + a, "/");
            if (!v) return why = "athlete must be an id", false;
            f.athlete = v;
        }
        if (!s.empty()) {
            auto v = id_after("/" + s, "/");
            if (!v) return why = "session must be an id", false;
            f.session = v;
        }
        if (!d.empty()) {
            if (!day_ok(d)) return why = "day must be YYYY-MM-DD", false;
            f.day = d;
        }
        return true;
    };
    if (path == "/api/sessions" || path == "/api/jumps" || path == "/api/jumps.csv") {
        if (!get) return error(c, 405, "GET only");
        std::string why;
        if (!parse_filter(why)) return error(c, 400, why);
        if (path == "/api/sessions") return reply_json(c, 200, db.sessions(f));
        if (path == "/api/jumps") return reply_json(c, 200, db.jumps(f));
        std::string name = "gravscale-jumps";
        if (f.day) name += "-" + *f.day;
        if (f.athlete) name += "-athlete" + std::to_string(*f.athlete);
        if (f.session) name += "-session" + std::to_string(*f.session);
        std::string disp = "Content-Disposition: attachment; filename=\"" + name + ".csv\"\r\n";
        reply(c, 200, "text/csv; charset=utf-8", db.jumps_csv(f), disp.c_str());
        return 200;
    }
    if (auto id = id_after(path, "/api/sessions/")) {
        if (!db.session_exists(*id)) return error(c, 404, "no visit " + std::to_string(*id));
        if (get) return reply_json(c, 200, db.session(*id));
        if (m == "DELETE") {
            for (auto it = open.begin(); it != open.end(); ++it)
                if (it->second == *id) return error(c, 409, "the visit is in progress");
            if (!db.delete_session(*id)) return error(c, 503, "the history could not be written: " + db.write_error());
            refresh_jumps();
            publish();
            return reply_json(c, 200, json{{"deleted", *id}});
        }
        if (m == "PATCH") {
            if (!body.contains("athlete_id")) return error(c, 400, "give athlete_id (a number or null)");
            std::optional<int64_t> a;
            if (body["athlete_id"].is_number_integer()) {
                a = body["athlete_id"].get<int64_t>();
                if (!db.athlete_exists(*a)) return error(c, 404, "no athlete " + std::to_string(*a));
            } else if (!body["athlete_id"].is_null()) {
                return error(c, 400, "athlete_id must be a whole number or null");
            }
            if (!db.set_session_athlete(*id, a)) return error(c, 503, "the history could not be written");
            refresh_jumps();
            publish();
            return reply_json(c, 200, db.session(*id));
        }
        return error(c, 405, "GET, PATCH or DELETE");
    }
    if (auto id = id_after(path, "/api/jumps/")) {
        if (!get) return error(c, 405, "GET only");
        json j = db.jump(*id);
        if (j.is_null()) return error(c, 404, "no jump " + std::to_string(*id));
        return reply_json(c, 200, j);
    }
    return error(c, 404, "no such API path");
}

int Kiosk::Impl::serve_events(mg_connection *c)
{
    {
        std::lock_guard<std::mutex> lk(mu);
        if (viewers >= cfg.max_viewers) return error(c, 503, "too many live pages open");
        viewers++;
    }
    mg_printf(c, "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n"
                 "X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\nretry: 1000\n\n");
    uint64_t seen = 0;
    for (;;) {
        std::string msg;
        {
            std::unique_lock<std::mutex> lk(mu);
            cv.wait_for(lk, std::chrono::seconds(kKeepAliveS), [&] { return stopping || seq != seen; });
            if (stopping) break;
            if (seq != seen) msg = "event: state\ndata: " + snapshot + "\n\n", seen = seq;
        }
        if (msg.empty()) msg = ": keep-alive\n\n";
        if (mg_write(c, msg.data(), msg.size()) <= 0) break;  // the page went away
    }
    std::lock_guard<std::mutex> lk(mu);
    viewers--;
    return 200;
}

int Kiosk::Impl::handle(mg_connection *c)
{
    const mg_request_info *ri = mg_get_request_info(c);
    const std::string m = ri->request_method ? ri->request_method : "";
    // the path as sent (decoded, not cleaned): only exact names match, "/a/../b" is no name
    const std::string path = ri->local_uri_raw ? ri->local_uri_raw : "";
    const bool changes = !(m == "GET" || m == "HEAD");
    if (m != "GET" && m != "POST" && m != "PUT" && m != "PATCH" && m != "DELETE")
        return error(c, 405, "method not allowed");
    if (path.compare(0, 5, "/api/") == 0) {
        if (!allowed(c, ri, changes)) return 403;
        return api(c, ri, path, m);
    }
    if (path == "/events") {
        if (m != "GET") return error(c, 405, "GET only");
        if (!allowed(c, ri, false)) return 403;
        return serve_events(c);
    }
    // the page's own files (no data in them): a fixed table compiled in, so no path
    // reaches the file system
    if (m != "GET") return error(c, 405, "GET only");
    const WwwFile *f = www_find(path == "/" ? "/index.html" : path);
    if (!f) return error(c, 404, "no such page");
    mg_printf(c,
              "HTTP/1.1 200 OK\r\nContent-Type: %s\r\nContent-Length: %zu\r\nCache-Control: no-cache\r\n"
              "X-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\nReferrer-Policy: no-referrer\r\n"
              "Content-Security-Policy: default-src 'self'; img-src 'self' data:; style-src 'self'; "
              "script-src 'self'; connect-src 'self'; frame-ancestors 'none'\r\n\r\n",
              f->type, f->size);
    mg_write(c, f->data, f->size);
    return 200;
}

// ---- the public side ----------------------------------------------------------------

Kiosk::Kiosk(std::unique_ptr<Impl> p) : p_(std::move(p)) {}

Kiosk::~Kiosk()
{
    {
        std::lock_guard<std::mutex> lk(p_->mu);
        p_->stopping = true;
        p_->cv.notify_all();
    }
    if (p_->ctx) mg_stop(p_->ctx);  // waits for the workers (live pages have been told)
}

static int handler(mg_connection *c, void *data) { return static_cast<Kiosk::Impl *>(data)->handle(c); }

// while starting, errors come back through mg_start2 (one line for the caller)
static std::atomic<bool> g_log_running{false};

static int log_message(const mg_connection *, const char *msg)
{
    if (g_log_running) std::fprintf(stderr, "gravscale: kiosk: %s\n", msg);
    return 1;
}

std::unique_ptr<Kiosk> Kiosk::start(const Config &c, std::string &err)
{
    auto p = std::make_unique<Impl>(c);
    if (!p->db.open(c.db, err)) {
        err = "kiosk: " + err;
        return nullptr;
    }
    {
        std::lock_guard<std::mutex> lk(p->mu);
        p->publish();
    }
    mg_init_library(0);
    const std::string ports = c.bind + ":" + std::to_string(c.port);
    const std::string threads = std::to_string(c.max_viewers + 4);
    const char *opts[] = {"listening_ports", ports.c_str(), "num_threads", threads.c_str(), "request_timeout_ms",
                          "10000", "enable_keep_alive", "yes", "keep_alive_timeout_ms", "5000", nullptr};
    mg_callbacks cb;
    std::memset(&cb, 0, sizeof cb);
    cb.log_message = log_message;  // the library's own complaints while running, one line each
    mg_init_data init;
    std::memset(&init, 0, sizeof init);
    init.callbacks = &cb;
    init.user_data = p.get();
    init.configuration_options = opts;
    char text[256] = "";
    unsigned code = 0;
    mg_error_data e{&code, text, sizeof text};
    p->ctx = mg_start2(&init, &e);
    if (!p->ctx) {
        err = "kiosk: http " + ports + ": " + (text[0] ? text : "cannot listen");
        return nullptr;
    }
    g_log_running = true;
    mg_set_request_handler(p->ctx, "/", handler, p.get());
    mg_server_port sp[2];
    int n = mg_get_server_ports(p->ctx, 2, sp);
    p->port = n > 0 ? static_cast<uint16_t>(sp[0].port) : c.port;
    return std::unique_ptr<Kiosk>(new Kiosk(std::move(p)));
}

void Kiosk::on_line(const char *line, size_t len)
{
    json ev = json::parse(line, line + len, nullptr, false);
    if (ev.is_discarded() || !ev.is_object()) return;
    double ms = wall_ms();
    std::lock_guard<std::mutex> lk(p_->mu);
    p_->on_event(ev, ms);
}

bool Kiosk::holding() const
{
    std::lock_guard<std::mutex> lk(p_->mu);
    return p_->cfg.wait_for_athlete && !p_->athlete;
}

void Kiosk::source_ended()
{
    std::lock_guard<std::mutex> lk(p_->mu);
    p_->ended = true;
    p_->publish();
}

uint16_t Kiosk::port() const { return p_->port; }

std::string Kiosk::url() const
{
    std::string host = p_->cfg.bind == "0.0.0.0" ? "127.0.0.1" : p_->cfg.bind;
    return "http://" + host + ":" + std::to_string(p_->port) + "/";
}

}  // namespace gs::kiosk
