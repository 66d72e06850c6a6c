// kiosk_db.hpp - athletes, visits (sessions) and jumps in SQLite (Debian's
// libsqlite3-dev). WAL with synchronous = FULL and one transaction per event:
// a jump is on disk when add_jump returns, so a power cut loses at most the jump
// still in the air. The schema is versioned (PRAGMA user_version) and checked at
// open; a visit left open by a killed daemon is closed as "interrupted".
// Not thread-safe: the kiosk serialises every call under its own mutex.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

struct sqlite3;

namespace gs::kiosk {

using json = nlohmann::json;

constexpr int kSchemaVersion = 1;

// What an export or a listing covers; every set field narrows it.
struct Filter {
    std::optional<int64_t> athlete, session;
    std::optional<std::string> day;  // YYYY-MM-DD, local time
};

class Db {
public:
    Db() = default;
    ~Db();
    Db(const Db &) = delete;
    Db &operator=(const Db &) = delete;

    // Create or open, migrate, check (quick_check); false with err naming the file.
    bool open(const std::string &path, std::string &err);
    const std::string &path() const { return path_; }
    // The last write error ("" none): shown on the page, never fatal.
    const std::string &write_error() const { return write_error_; }

    // ---- writes: one transaction each ----
    int64_t add_run(const json &start_event);
    int64_t open_session(int64_t run, uint32_t track, std::optional<int64_t> core_session,
                         std::optional<int64_t> athlete, double t_start_s);
    void session_height(int64_t session, const json &height_event);
    void end_session(int64_t session, const json &end_event, const char *reason);
    int64_t add_jump(int64_t session, const json &jump_event, const json &track);
    // The athlete of that name (case and surrounding spaces ignored), created if new.
    int64_t athlete_named(const std::string &name, bool &created);
    bool rename_athlete(int64_t id, const std::string &name, std::string &err);
    bool set_session_athlete(int64_t session, std::optional<int64_t> athlete);
    bool delete_session(int64_t session);

    // ---- reads ----
    bool athlete_exists(int64_t id);
    bool session_exists(int64_t id);
    json athletes();
    json athlete(int64_t id);           // with its sessions and jumps; null if unknown
    json sessions(const Filter &f);     // with athlete names and counts
    json session(int64_t id);           // with its jumps; null if unknown
    json jumps(const Filter &f);
    json jump(int64_t id);              // with its track; null if unknown
    std::string jumps_csv(const Filter &f);
    std::string integrity_check();      // "ok" or the first problem

    // wall-clock helpers (UTC ISO 8601 with ms; the local day)
    static std::string now_utc();
    static std::string today_local();

private:
    bool exec(const char *sql);
    bool begin();
    bool commit();
    void write_failed(const char *what);
    json query(const std::string &sql, const std::vector<json> &args);
    std::string filter_sql(const Filter &f, std::vector<json> &args) const;

    sqlite3 *db_ = nullptr;
    std::string path_, write_error_;
};

// A name as stored: trimmed, 1 .. 80 characters of valid UTF-8 without control
// characters; false with the reason otherwise.
bool athlete_name_ok(const std::string &name, std::string &trimmed, std::string &why);

}  // namespace gs::kiosk
