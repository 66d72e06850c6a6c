// kiosk_db.cpp - the kiosk's SQLite store (kiosk_db.hpp).
#include "kiosk_db.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <sys/time.h>

#include <sqlite3.h>

namespace gs::kiosk {

namespace {

constexpr int32_t kAppId = 0x47534b31;  // 'GSK1': refuse a database that is not ours

const char *const kSchemaV1 = R"SQL(
CREATE TABLE athletes(
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL,
  name_key TEXT NOT NULL UNIQUE,
  created_at TEXT NOT NULL);
CREATE TABLE runs(
  id INTEGER PRIMARY KEY,
  started_at TEXT NOT NULL,
  version TEXT, config TEXT, layout TEXT, fps REAL);
CREATE TABLE sessions(
  id INTEGER PRIMARY KEY,
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  track INTEGER NOT NULL,
  core_session INTEGER,
  athlete_id INTEGER REFERENCES athletes(id) ON DELETE SET NULL,
  day TEXT NOT NULL,
  started_at TEXT NOT NULL,
  ended_at TEXT,
  end_reason TEXT,
  t_start_s REAL, t_end_s REAL,
  stature_m REAL, ci95_lo_m REAL, ci95_hi_m REAL,
  n_jumps INTEGER NOT NULL DEFAULT 0,
  n_rejected INTEGER NOT NULL DEFAULT 0,
  end_json TEXT);
CREATE INDEX sessions_athlete ON sessions(athlete_id);
CREATE INDEX sessions_day ON sessions(day);
CREATE TABLE jumps(
  id INTEGER PRIMARY KEY,
  session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  at TEXT NOT NULL,
  idx INTEGER,
  t_takeoff_s REAL, t_land_s REAL,
  accepted INTEGER NOT NULL,
  reason TEXT,
  jump_height_m REAL, flight_time_s REAL, takeoff_velocity_m_s REAL,
  height_m REAL, height_se_m REAL,
  warnings TEXT NOT NULL DEFAULT '[]',
  event_json TEXT NOT NULL,
  track_json TEXT);
CREATE INDEX jumps_session ON jumps(session_id);
)SQL";

// a number field of an event, or SQL NULL (json null) when absent, null or not finite
json num(const json &ev, const char *key)
{
    auto it = ev.find(key);
    if (it == ev.end() || !it->is_number()) return nullptr;
    double d = it->get<double>();
    return std::isfinite(d) ? json(d) : json(nullptr);
}

json str(const json &ev, const char *key)
{
    auto it = ev.find(key);
    return it != ev.end() && it->is_string() ? *it : json(nullptr);
}

void bind(sqlite3_stmt *st, int i, const json &v)
{
    if (v.is_null())
        sqlite3_bind_null(st, i);
    else if (v.is_boolean())
        sqlite3_bind_int(st, i, v.get<bool>() ? 1 : 0);
    else if (v.is_number_integer())
        sqlite3_bind_int64(st, i, v.get<int64_t>());
    else if (v.is_number())
        sqlite3_bind_double(st, i, v.get<double>());
    else if (v.is_string())
        sqlite3_bind_text(st, i, v.get_ref<const std::string &>().c_str(), -1, SQLITE_TRANSIENT);
    else
        sqlite3_bind_text(st, i, v.dump().c_str(), -1, SQLITE_TRANSIENT);
}

// columns ending in _json are stored JSON text: given back parsed
json column(sqlite3_stmt *st, int i)
{
    switch (sqlite3_column_type(st, i)) {
    case SQLITE_INTEGER: return json(static_cast<int64_t>(sqlite3_column_int64(st, i)));
    case SQLITE_FLOAT: return json(sqlite3_column_double(st, i));
    case SQLITE_NULL: return json(nullptr);
    default: {
        std::string s(reinterpret_cast<const char *>(sqlite3_column_text(st, i)),
                      static_cast<size_t>(sqlite3_column_bytes(st, i)));
        std::string name = sqlite3_column_name(st, i);
        if ((name.size() > 5 && name.compare(name.size() - 5, 5, "_json") == 0) || name == "warnings") {
            json j = json::parse(s, nullptr, false);
            return j.is_discarded() ? json(nullptr) : j;
        }
        return json(s);
    }
    }
}

std::string name_key(const std::string &name)
{
    std::string k = name;
    for (char &c : k)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return k;
}

// valid UTF-8 without control characters (C0, DEL, C1)
bool clean_utf8(const std::string &s)
{
    const unsigned char *p = reinterpret_cast<const unsigned char *>(s.data());
    size_t n = s.size(), i = 0;
    while (i < n) {
        unsigned c = p[i];
        size_t len = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
        if (!len || i + len > n) return false;
        unsigned cp = len == 1 ? c : len == 2 ? (c & 0x1f) : len == 3 ? (c & 0x0f) : (c & 0x07);
        for (size_t k = 1; k < len; k++) {
            if ((p[i + k] & 0xc0) != 0x80) return false;
            cp = (cp << 6) | (p[i + k] & 0x3f);
        }
        static const unsigned kMin[5] = {0, 0, 0x80, 0x800, 0x10000};
        if (cp < kMin[len] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return false;
        if (cp < 0x20 || (cp >= 0x7f && cp < 0xa0)) return false;
        i += len;
    }
    return true;
}

size_t utf8_chars(const std::string &s)
{
    size_t n = 0;
    for (unsigned char c : s) n += (c & 0xc0) != 0x80;
    return n;
}

}  // namespace

bool athlete_name_ok(const std::string &name, std::string &trimmed, std::string &why)
{
    size_t a = name.find_first_not_of(" \t"), b = name.find_last_not_of(" \t");
    trimmed = a == std::string::npos ? "" : name.substr(a, b - a + 1);
    if (trimmed.empty()) {
        why = "the name is empty";
        return false;
    }
    if (!clean_utf8(trimmed)) {
        why = "the name is not valid UTF-8 text (or holds control characters)";
        return false;
    }
    if (utf8_chars(trimmed) > 80) {
        why = "the name is longer than 80 characters";
        return false;
    }
    return true;
}

Db::~Db()
{
    if (db_) sqlite3_close(db_);
}

std::string Db::now_utc()
{
    struct timeval tv;
    gettimeofday(&tv, nullptr);
    struct tm tm;
    gmtime_r(&tv.tv_sec, &tm);
    char buf[96];
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1,
                  tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(tv.tv_usec / 1000));
    return buf;
}

std::string Db::today_local()
{
    time_t t = time(nullptr);
    struct tm tm;
    localtime_r(&t, &tm);
    char buf[48];
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02d", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday);
    return buf;
}

bool Db::exec(const char *sql)
{
    char *msg = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &msg) == SQLITE_OK) return true;
    write_error_ = msg ? msg : sqlite3_errmsg(db_);
    sqlite3_free(msg);
    return false;
}

bool Db::begin()
{
    if (exec("BEGIN IMMEDIATE")) return true;
    write_failed("a transaction");
    return false;
}

bool Db::commit()
{
    if (exec("COMMIT")) return true;
    exec("ROLLBACK");
    return false;
}

void Db::write_failed(const char *what)
{
    std::string e = sqlite3_errmsg(db_);
    write_error_ = std::string(what) + ": " + e;
    std::fprintf(stderr, "gravscale: kiosk: %s: %s\n", path_.c_str(), write_error_.c_str());
    if (sqlite3_get_autocommit(db_) == 0) exec("ROLLBACK");
}

bool Db::open(const std::string &path, std::string &err)
{
    path_ = path;
    int rc = sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                             nullptr);
    if (rc != SQLITE_OK) {
        err = path + ": " + (db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc));
        return false;
    }
    sqlite3_busy_timeout(db_, 2000);
    sqlite3_extended_result_codes(db_, 1);
    json v = query("PRAGMA user_version", {}), app = query("PRAGMA application_id", {});
    if (v.empty() || app.empty()) {
        err = path + ": not an SQLite database (" + sqlite3_errmsg(db_) + ")";
        return false;
    }
    int64_t version = v[0]["user_version"].get<int64_t>(), appid = app[0]["application_id"].get<int64_t>();
    json tables = query("SELECT count(*) AS n FROM sqlite_master", {});
    bool empty = tables.empty() || tables[0]["n"].get<int64_t>() == 0;
    if (!empty && appid != kAppId) {
        err = path + ": an SQLite database of another program (application_id " + std::to_string(appid) + ")";
        return false;
    }
    if (version > kSchemaVersion) {
        err = path + ": schema version " + std::to_string(version) + " is newer than this gravscale's (" +
              std::to_string(kSchemaVersion) + ")";
        return false;
    }
    // WAL: readers never block the writer; FULL: each commit is synced (power cuts)
    if (!exec("PRAGMA journal_mode = WAL") || !exec("PRAGMA synchronous = FULL") || !exec("PRAGMA foreign_keys = ON")) {
        err = path + ": " + write_error_;
        return false;
    }
    json jm = query("PRAGMA journal_mode", {});
    if (jm.empty() || jm[0]["journal_mode"] != "wal") {
        err = path + ": cannot use write-ahead logging here";
        return false;
    }
    std::string ck = integrity_check();
    if (ck != "ok") {
        err = path + ": the database is damaged: " + ck;
        return false;
    }
    if (version == 0) {
        std::string create = std::string("BEGIN IMMEDIATE;") + kSchemaV1 + "PRAGMA application_id = " +
                             std::to_string(kAppId) + "; PRAGMA user_version = " + std::to_string(kSchemaVersion) +
                             "; COMMIT;";
        if (!exec(create.c_str())) {
            exec("ROLLBACK");
            err = path + ": cannot create the schema: " + write_error_;
            return false;
        }
    }
    // visits a killed daemon left open end where their last jump (or their start) was
    if (!exec("UPDATE sessions SET end_reason = 'interrupted', ended_at = coalesce((SELECT max(at) FROM jumps "
              "WHERE session_id = sessions.id), started_at) WHERE ended_at IS NULL")) {
        err = path + ": " + write_error_;
        return false;
    }
    write_error_.clear();
    return true;
}

std::string Db::integrity_check()
{
    json r = query("PRAGMA quick_check", {});
    if (r.empty()) return sqlite3_errmsg(db_);
    return r[0].begin()->is_string() ? r[0].begin()->get<std::string>() : "unknown";
}

json Db::query(const std::string &sql, const std::vector<json> &args)
{
    json out = json::array();
    sqlite3_stmt *st = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &st, nullptr) != SQLITE_OK) return out;
    for (size_t i = 0; i < args.size(); i++) bind(st, static_cast<int>(i + 1), args[i]);
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        json row = json::object();
        for (int c = 0; c < sqlite3_column_count(st); c++) row[sqlite3_column_name(st, c)] = column(st, c);
        out.push_back(std::move(row));
    }
    if (rc != SQLITE_DONE) write_error_ = sqlite3_errmsg(db_);
    sqlite3_finalize(st);
    return out;
}

// one statement that changes rows; false on any error
static bool run(sqlite3 *db, const std::string &sql, const std::vector<json> &args)
{
    sqlite3_stmt *st = nullptr;
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr) != SQLITE_OK) return false;
    for (size_t i = 0; i < args.size(); i++) bind(st, static_cast<int>(i + 1), args[i]);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    return rc == SQLITE_DONE;
}

int64_t Db::add_run(const json &ev)
{
    if (!begin()) return 0;
    if (!run(db_, "INSERT INTO runs(started_at, version, config, layout, fps) VALUES(?,?,?,?,?)",
             {now_utc(), str(ev, "version"), str(ev, "config"), str(ev, "layout"), num(ev, "fps_source")})) {
        write_failed("a run");
        return 0;
    }
    int64_t id = sqlite3_last_insert_rowid(db_);
    return commit() ? id : 0;
}

int64_t Db::open_session(int64_t run_id, uint32_t track, std::optional<int64_t> core_session,
                         std::optional<int64_t> athlete, double t_start_s)
{
    if (!begin()) return 0;
    if (!run(db_,
             "INSERT INTO sessions(run_id, track, core_session, athlete_id, day, started_at, t_start_s) "
             "VALUES(?,?,?,?,?,?,?)",
             {run_id ? json(run_id) : json(nullptr), track, core_session ? json(*core_session) : json(nullptr),
              athlete ? json(*athlete) : json(nullptr), today_local(), now_utc(),
              std::isfinite(t_start_s) ? json(t_start_s) : json(nullptr)})) {
        write_failed("a visit");
        return 0;
    }
    int64_t id = sqlite3_last_insert_rowid(db_);
    return commit() ? id : 0;
}

void Db::session_height(int64_t sid, const json &ev)
{
    const json ci = ev.contains("ci95_m") && ev["ci95_m"].is_array() && ev["ci95_m"].size() == 2 ? ev["ci95_m"] : json();
    if (!begin()) return;
    if (!run(db_, "UPDATE sessions SET stature_m = ?, ci95_lo_m = ?, ci95_hi_m = ? WHERE id = ?",
             {num(ev, "height_m"), ci.is_array() ? ci[0] : json(nullptr), ci.is_array() ? ci[1] : json(nullptr), sid})) {
        write_failed("a height");
        return;
    }
    commit();
}

void Db::end_session(int64_t sid, const json &ev, const char *reason)
{
    const json ci = ev.contains("ci95_m") && ev["ci95_m"].is_array() && ev["ci95_m"].size() == 2 ? ev["ci95_m"] : json();
    if (!begin()) return;
    // a summary (no visits: a ball) keeps the counts of its jumps; a visit's end brings its own
    bool ok = run(db_,
                  "UPDATE sessions SET ended_at = ?, end_reason = ?, t_end_s = coalesce(?, t_end_s), "
                  "stature_m = coalesce(?, stature_m), ci95_lo_m = coalesce(?, ci95_lo_m), "
                  "ci95_hi_m = coalesce(?, ci95_hi_m), end_json = ? WHERE id = ?",
                  {now_utc(), reason ? json(reason) : str(ev, "reason"), num(ev, "t_end_s"),
                   ev.contains("stature_m") ? num(ev, "stature_m") : num(ev, "height_m"),
                   ci.is_array() ? ci[0] : json(nullptr), ci.is_array() ? ci[1] : json(nullptr), ev.dump(), sid});
    if (!ok) {
        write_failed("the end of a visit");
        return;
    }
    commit();
}

int64_t Db::add_jump(int64_t sid, const json &ev, const json &track)
{
    bool accepted = ev.value("accepted", false);
    json warnings = ev.contains("warnings") && ev["warnings"].is_array() ? ev["warnings"] : json::array();
    if (!begin()) return 0;
    bool ok = run(db_,
                  "INSERT INTO jumps(session_id, at, idx, t_takeoff_s, t_land_s, accepted, reason, jump_height_m, "
                  "flight_time_s, takeoff_velocity_m_s, height_m, height_se_m, warnings, event_json, track_json) "
                  "VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
                  {sid, now_utc(), num(ev, "index"), num(ev, "t_takeoff_s"), num(ev, "t_land_s"), accepted,
                   str(ev, "reason"), num(ev, "jump_height_m"), num(ev, "flight_time_s"),
                   num(ev, "takeoff_velocity_m_s"), num(ev, "height_m"), num(ev, "height_se_m"), warnings.dump(),
                   ev.dump(), track.is_null() ? json(nullptr) : json(track.dump())});
    int64_t id = ok ? sqlite3_last_insert_rowid(db_) : 0;
    ok = ok && run(db_,
                   accepted ? "UPDATE sessions SET n_jumps = n_jumps + 1 WHERE id = ?"
                            : "UPDATE sessions SET n_rejected = n_rejected + 1 WHERE id = ?",
                   {sid});
    if (!ok) {
        write_failed("a jump");
        return 0;
    }
    return commit() ? id : 0;
}

int64_t Db::athlete_named(const std::string &name, bool &created)
{
    created = false;
    json r = query("SELECT id FROM athletes WHERE name_key = ?", {name_key(name)});
    if (!r.empty()) return r[0]["id"].get<int64_t>();
    if (!begin()) return 0;
    if (!run(db_, "INSERT INTO athletes(name, name_key, created_at) VALUES(?,?,?)", {name, name_key(name), now_utc()})) {
        write_failed("an athlete");
        return 0;
    }
    int64_t id = sqlite3_last_insert_rowid(db_);
    created = commit();
    return created ? id : 0;
}

bool Db::rename_athlete(int64_t id, const std::string &name, std::string &err)
{
    json r = query("SELECT id FROM athletes WHERE name_key = ? AND id <> ?", {name_key(name), id});
    if (!r.empty()) {
        err = "another athlete has that name";
        return false;
    }
    if (!begin()) return false;
    if (!run(db_, "UPDATE athletes SET name = ?, name_key = ? WHERE id = ?", {name, name_key(name), id})) {
        write_failed("a rename");
        err = write_error_;
        return false;
    }
    return commit();
}

bool Db::set_session_athlete(int64_t sid, std::optional<int64_t> athlete)
{
    if (!begin()) return false;
    if (!run(db_, "UPDATE sessions SET athlete_id = ? WHERE id = ?", {athlete ? json(*athlete) : json(nullptr), sid})) {
        write_failed("a visit's athlete");
        return false;
    }
    return commit();
}

bool Db::delete_session(int64_t sid)
{
    if (!begin()) return false;
    if (!run(db_, "DELETE FROM sessions WHERE id = ?", {sid})) {
        write_failed("deleting a visit");
        return false;
    }
    return commit();
}

bool Db::athlete_exists(int64_t id) { return !query("SELECT 1 AS x FROM athletes WHERE id = ?", {id}).empty(); }
bool Db::session_exists(int64_t id) { return !query("SELECT 1 AS x FROM sessions WHERE id = ?", {id}).empty(); }

json Db::athletes()
{
    return query("SELECT a.id, a.name, a.created_at, count(DISTINCT s.id) AS n_sessions, "
                 "count(j.id) FILTER (WHERE j.accepted) AS n_jumps, max(j.jump_height_m) FILTER (WHERE j.accepted) "
                 "AS best_jump_m, max(s.started_at) AS last_seen FROM athletes a LEFT JOIN sessions s ON "
                 "s.athlete_id = a.id LEFT JOIN jumps j ON j.session_id = s.id GROUP BY a.id ORDER BY a.name_key",
                 {});
}

std::string Db::filter_sql(const Filter &f, std::vector<json> &args) const
{
    std::string w = " WHERE 1";
    if (f.athlete) {
        w += " AND s.athlete_id = ?";
        args.push_back(*f.athlete);
    }
    if (f.session) {
        w += " AND s.id = ?";
        args.push_back(*f.session);
    }
    if (f.day) {
        w += " AND s.day = ?";
        args.push_back(*f.day);
    }
    return w;
}

static const char kSessionCols[] =
    "SELECT s.id, s.athlete_id, a.name AS athlete, s.day, s.started_at, s.ended_at, s.end_reason, s.track, "
    "s.core_session, s.stature_m, s.ci95_lo_m, s.ci95_hi_m, s.n_jumps, s.n_rejected, "
    "(SELECT max(jump_height_m) FROM jumps WHERE session_id = s.id AND accepted) AS best_jump_m, "
    "(SELECT avg(jump_height_m) FROM jumps WHERE session_id = s.id AND accepted) AS mean_jump_m "
    "FROM sessions s LEFT JOIN athletes a ON a.id = s.athlete_id";

static const char kJumpCols[] =
    "SELECT j.id, j.session_id, s.athlete_id, a.name AS athlete, s.day, j.at, j.idx, j.t_takeoff_s, j.t_land_s, "
    "j.accepted, j.reason, j.jump_height_m, j.flight_time_s, j.takeoff_velocity_m_s, j.height_m, j.height_se_m, "
    "j.warnings, j.event_json FROM jumps j JOIN sessions s ON s.id = j.session_id LEFT JOIN athletes a ON "
    "a.id = s.athlete_id";

static void booleans(json &rows)
{
    for (json &r : rows)
        if (r.contains("accepted") && r["accepted"].is_number_integer()) r["accepted"] = r["accepted"].get<int64_t>() != 0;
}

json Db::sessions(const Filter &f)
{
    std::vector<json> args;
    return query(std::string(kSessionCols) + filter_sql(f, args) + " ORDER BY s.started_at, s.id", args);
}

json Db::jumps(const Filter &f)
{
    std::vector<json> args;
    json r = query(std::string(kJumpCols) + filter_sql(f, args) + " ORDER BY j.at, j.id", args);
    booleans(r);
    return r;
}

json Db::session(int64_t id)
{
    json s = query(std::string(kSessionCols) + " WHERE s.id = ?", {id});
    if (s.empty()) return nullptr;
    json out = s[0];
    Filter f;
    f.session = id;
    out["jumps"] = jumps(f);
    return out;
}

json Db::athlete(int64_t id)
{
    json a = query("SELECT id, name, created_at FROM athletes WHERE id = ?", {id});
    if (a.empty()) return nullptr;
    json out = a[0];
    Filter f;
    f.athlete = id;
    out["sessions"] = sessions(f);
    out["jumps"] = jumps(f);
    return out;
}

json Db::jump(int64_t id)
{
    json r = query(std::string(kJumpCols).replace(7, 0, "j.track_json, ") + " WHERE j.id = ?", {id});
    if (r.empty()) return nullptr;
    booleans(r);
    return r[0];
}

namespace {

// RFC 4180 quoting; a leading = + - @ gets a ' so a spreadsheet shows text, not a formula
std::string csv_field(const json &v)
{
    std::string s;
    if (v.is_null()) return "";
    if (v.is_string())
        s = v.get<std::string>();
    else if (v.is_boolean())
        s = v.get<bool>() ? "1" : "0";
    else if (v.is_number_float()) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.6g", v.get<double>());
        s = buf;
    } else
        s = v.dump();
    if (v.is_string() && !s.empty() && (s[0] == '=' || s[0] == '+' || s[0] == '-' || s[0] == '@')) s = "'" + s;
    if (s.find_first_of(",\"\r\n") != std::string::npos) {
        std::string q = "\"";
        for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
        return q + "\"";
    }
    return s;
}

}  // namespace

std::string Db::jumps_csv(const Filter &f)
{
    static const char *const fixed[] = {"id",        "session_id",    "athlete",       "day",
                                        "at",        "accepted",      "reason",        "jump_height_m",
                                        "flight_time_s", "takeoff_velocity_m_s", "height_m", "height_se_m"};
    json rows = jumps(f);
    // the events' other scalar fields (those the core adds later too), in order of first appearance
    std::vector<std::string> extra;
    for (const json &r : rows) {
        if (!r["event_json"].is_object()) continue;
        for (auto it = r["event_json"].begin(); it != r["event_json"].end(); ++it) {
            if (it.value().is_structured() || it.key() == "event") continue;
            bool known = false;
            for (const char *k : fixed) known = known || it.key() == k;
            for (const std::string &k : extra) known = known || it.key() == k;
            if (!known) extra.push_back(it.key());
        }
    }
    std::string out;
    for (const char *k : fixed) out += std::string(out.empty() ? "" : ",") + k;
    out += ",warnings";
    for (const std::string &k : extra) out += "," + csv_field(k);
    out += "\r\n";
    for (const json &r : rows) {
        std::string line;
        for (const char *k : fixed) line += std::string(line.empty() ? "" : ",") + csv_field(r[k]);
        std::string w;
        for (const json &x : r["warnings"])
            if (x.is_string()) w += (w.empty() ? "" : " ") + x.get<std::string>();
        line += "," + csv_field(w);
        for (const std::string &k : extra) {
            const json &ev = r["event_json"];
            line += "," + (ev.is_object() && ev.contains(k) ? csv_field(ev[k]) : std::string());
        }
        out += line + "\r\n";
    }
    return out;
}

}  // namespace gs::kiosk
