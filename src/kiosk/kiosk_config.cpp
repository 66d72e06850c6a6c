// kiosk_config.cpp - the [kiosk] section of a profile.
#include "kiosk.hpp"

#include <arpa/inet.h>
#include <cmath>
#include <cstdio>
#include <cstring>

extern "C" {
#include "gravscale/gs_num.h"
}

namespace gs::kiosk {

namespace {

gs_status fail(char *msg, size_t cap, const char *text, gs_status st)
{
    if (msg && cap) std::snprintf(msg, cap, "%s", text);
    return st;
}

bool yes_no(const std::string &v, bool &out)
{
    if (v == "yes" || v == "true" || v == "on" || v == "1") return out = true, true;
    if (v == "no" || v == "false" || v == "off" || v == "0") return out = false, true;
    return false;
}

gs_status set(void *ctx, const char *key, size_t kl, const char *v, size_t vl, char *msg, size_t cap)
{
    Config &c = *static_cast<Config *>(ctx);
    c.present = true;
    const std::string k(key, kl), val(v, vl);
    double d;
    bool b;
    if (k == "enabled") {
        if (!yes_no(val, b)) return fail(msg, cap, "expected yes or no", GS_EINVAL);
        c.enabled = b ? 1 : 0;
    } else if (k == "bind") {
        struct in_addr a;
        if (inet_pton(AF_INET, val.c_str(), &a) != 1)
            return fail(msg, cap, "expected a numeric IPv4 address (127.0.0.1, 0.0.0.0, ...)", GS_EINVAL);
        c.bind = val;
    } else if (k == "port") {
        if (!gs_num_parse(v, vl, &d) || d != std::floor(d)) return fail(msg, cap, "expected a whole number", GS_EINVAL);
        if (d < 0 || d > 65535) return fail(msg, cap, "out of range 0 .. 65535", GS_ERANGE);
        c.port = static_cast<uint16_t>(d);
    } else if (k == "db") {
        if (val.empty() || val.size() > 1000) return fail(msg, cap, "expected a file path", GS_EINVAL);
        c.db = val;
    } else if (k == "token") {
        if (val.size() < 16 || val.size() > 128) return fail(msg, cap, "expected 16 .. 128 characters", GS_ERANGE);
        for (char ch : val)
            if (ch <= ' ' || ch > '~' || ch == ';' || ch == ',' || ch == '"' || ch == '\\')
                return fail(msg, cap, "printable ASCII without spaces, quotes, ',', ';' or '\\'", GS_EINVAL);
        c.token = val;
    } else if (k == "open_read") {
        if (!yes_no(val, c.open_read)) return fail(msg, cap, "expected yes or no", GS_EINVAL);
    } else if (k == "wait_for_athlete") {
        if (!yes_no(val, c.wait_for_athlete)) return fail(msg, cap, "expected yes or no", GS_EINVAL);
    } else if (k == "result_hold_s") {
        if (!gs_num_parse(v, vl, &d)) return fail(msg, cap, "expected a number", GS_EINVAL);
        if (!(d >= 0.5 && d <= 60)) return fail(msg, cap, "out of range 0.5 .. 60", GS_ERANGE);
        c.result_hold_s = d;
    } else if (k == "max_viewers") {
        if (!gs_num_parse(v, vl, &d) || d != std::floor(d)) return fail(msg, cap, "expected a whole number", GS_EINVAL);
        if (d < 1 || d > 64) return fail(msg, cap, "out of range 1 .. 64", GS_ERANGE);
        c.max_viewers = static_cast<uint32_t>(d);
    } else if (k == "title") {
        if (val.empty() || val.size() > 60) return fail(msg, cap, "expected 1 .. 60 characters", GS_ERANGE);
        c.title = val;
    } else {
        return GS_ENOKEY;
    }
    return GS_OK;
}

}  // namespace

bool is_loopback(const std::string &ip)
{
    struct in_addr a;
    return inet_pton(AF_INET, ip.c_str(), &a) == 1 && (ntohl(a.s_addr) >> 24) == 127;
}

gs_cfg_section config_section(Config &c) { return gs_cfg_section{"kiosk", set, &c}; }

gs_status config_check(const Config &c, gs_cfg_error &e)
{
    if (!c.on()) return GS_OK;
    if (!is_loopback(c.bind) && c.token.empty()) {
        std::memset(&e, 0, sizeof e);
        std::snprintf(e.section, sizeof e.section, "kiosk");
        std::snprintf(e.key, sizeof e.key, "token");
        std::snprintf(e.msg, sizeof e.msg, "a kiosk on a non-loopback address (bind = %s) needs a token",
                      c.bind.c_str());
        return GS_EINVAL;
    }
    return GS_OK;
}

}  // namespace gs::kiosk
