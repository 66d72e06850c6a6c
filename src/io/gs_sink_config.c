/* gs_sink_config.c - [sink.*] and [status] handlers for gs_cfg_parse, the
 * checks after parsing, and opening the configured sinks. */
#include "gs_sink_config.h"
#include "gravscale/gs_num.h"

#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

void gs_sinks_config_default(gs_sinks_config *c)
{
    memset(c, 0, sizeof *c);
    gs_sink_switch off = {false, -1};
    c->stdout_sw = c->file_sw = c->serial_sw = c->tcp_sw = c->tcp_client_sw = c->udp_sw = off;
    c->serial.baud = 115200;
    c->serial.reopen_s = 1.0;
    c->serial.queue_lines = 256;
    snprintf(c->tcp.bind, sizeof c->tcp.bind, "127.0.0.1");
    c->tcp.port = 7878;
    c->tcp.max_clients = 4;
    c->tcp.queue_lines = 256;
    c->tcp_client.backoff_min_s = 0.5;
    c->tcp_client.backoff_max_s = 30.0;
    c->tcp_client.queue_lines = 256;
    c->mqtt_sw = off;
    snprintf(c->mqtt.topic_prefix, sizeof c->mqtt.topic_prefix, "gravscale");
    c->mqtt.keepalive_s = 30;
    c->mqtt.backoff_min_s = 0.5;
    c->mqtt.backoff_max_s = 30.0;
    c->mqtt.queue_lines = 256;
    c->status_interval_s = 1.0;
}

bool gs_sinks_config_on(const gs_sink_switch *sw, bool default_on)
{
    if (sw->enabled >= 0)
        return sw->enabled == 1;
    return sw->present || default_on;
}

/* ------------------------------------------------------------ value parsers */

static bool is(const char *s, size_t n, const char *lit) { return n == strlen(lit) && memcmp(s, lit, n) == 0; }

static gs_status set_text(char *dst, size_t cap, const char *v, size_t n, char *msg, size_t mcap)
{
    if (n == 0) {
        snprintf(msg, mcap, "empty value");
        return GS_EINVAL;
    }
    if (n >= cap) {
        snprintf(msg, mcap, "longer than %u characters", (unsigned)(cap - 1));
        return GS_ERANGE;
    }
    memcpy(dst, v, n);
    dst[n] = '\0';
    return GS_OK;
}

static gs_status set_u32(uint32_t *dst, const char *v, size_t n, long lo, long hi, char *msg, size_t mcap)
{
    long x;
    if (!gs_num_parse_int(v, n, &x)) {
        snprintf(msg, mcap, "not an integer");
        return GS_EINVAL;
    }
    if (x < lo || x > hi) {
        snprintf(msg, mcap, "out of range %ld..%ld", lo, hi);
        return GS_ERANGE;
    }
    *dst = (uint32_t)x;
    return GS_OK;
}

static gs_status set_port(uint16_t *dst, const char *v, size_t n, long lo, char *msg, size_t mcap)
{
    uint32_t p;
    gs_status st = set_u32(&p, v, n, lo, 65535, msg, mcap);
    if (st == GS_OK)
        *dst = (uint16_t)p;
    return st;
}

static gs_status set_secs(double *dst, const char *v, size_t n, double lo, double hi, char *msg, size_t mcap)
{
    double x;
    if (!gs_num_parse(v, n, &x) || !isfinite(x)) {
        snprintf(msg, mcap, "not a number");
        return GS_EINVAL;
    }
    if (x < lo || x > hi) {
        snprintf(msg, mcap, "out of range %g..%g s", lo, hi);
        return GS_ERANGE;
    }
    *dst = x;
    return GS_OK;
}

/* enabled = yes|no|true|false|on|off|1|0 */
static gs_status set_enabled(gs_sink_switch *sw, const char *v, size_t n, char *msg, size_t mcap)
{
    if (is(v, n, "yes") || is(v, n, "true") || is(v, n, "on") || is(v, n, "1")) {
        sw->enabled = 1;
        return GS_OK;
    }
    if (is(v, n, "no") || is(v, n, "false") || is(v, n, "off") || is(v, n, "0")) {
        sw->enabled = 0;
        return GS_OK;
    }
    snprintf(msg, mcap, "expected yes or no");
    return GS_EINVAL;
}

#define QUEUE_MAX 65536L

/* ----------------------------------------------------------------- handlers */

static gs_status h_stdout(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg, size_t cap)
{
    gs_sinks_config *c = ctx;
    c->stdout_sw.present = true;
    if (is(k, kn, "enabled"))
        return set_enabled(&c->stdout_sw, v, vn, msg, cap);
    return GS_ENOKEY;
}

static gs_status h_file(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg, size_t cap)
{
    gs_sinks_config *c = ctx;
    c->file_sw.present = true;
    if (is(k, kn, "enabled"))
        return set_enabled(&c->file_sw, v, vn, msg, cap);
    if (is(k, kn, "path"))
        return set_text(c->file_path, sizeof c->file_path, v, vn, msg, cap);
    return GS_ENOKEY;
}

static gs_status h_serial(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg, size_t cap)
{
    gs_sinks_config *c = ctx;
    c->serial_sw.present = true;
    if (is(k, kn, "enabled"))
        return set_enabled(&c->serial_sw, v, vn, msg, cap);
    if (is(k, kn, "device"))
        return set_text(c->serial.device, sizeof c->serial.device, v, vn, msg, cap);
    if (is(k, kn, "baud")) {
        uint32_t b;
        gs_status st = set_u32(&b, v, vn, 1, 100000000L, msg, cap);
        if (st != GS_OK)
            return st;
        if (!gs_sink_serial_baud_ok(b)) {
            snprintf(msg, cap, "unsupported baud (9600 19200 38400 57600 115200 230400 460800 921600)");
            return GS_ERANGE;
        }
        c->serial.baud = b;
        return GS_OK;
    }
    if (is(k, kn, "reopen_s"))
        return set_secs(&c->serial.reopen_s, v, vn, 0.05, 3600.0, msg, cap);
    if (is(k, kn, "queue_lines"))
        return set_u32(&c->serial.queue_lines, v, vn, 1, QUEUE_MAX, msg, cap);
    return GS_ENOKEY;
}

static gs_status h_tcp(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg, size_t cap)
{
    gs_sinks_config *c = ctx;
    c->tcp_sw.present = true;
    if (is(k, kn, "enabled"))
        return set_enabled(&c->tcp_sw, v, vn, msg, cap);
    if (is(k, kn, "bind")) {
        char tmp[sizeof c->tcp.bind];
        gs_status st = set_text(tmp, sizeof tmp, v, vn, msg, cap);
        if (st != GS_OK)
            return st;
        unsigned char a[sizeof(struct in6_addr)];
        if (inet_pton(AF_INET, tmp, a) != 1 && inet_pton(AF_INET6, tmp, a) != 1) {
            snprintf(msg, cap, "not a numeric IPv4 or IPv6 address");
            return GS_EINVAL;
        }
        memcpy(c->tcp.bind, tmp, sizeof tmp);
        c->tcp.allow_remote = true; /* written out: a non-loopback address is meant */
        return GS_OK;
    }
    if (is(k, kn, "port"))
        return set_port(&c->tcp.port, v, vn, 0, msg, cap);
    if (is(k, kn, "max_clients"))
        return set_u32(&c->tcp.max_clients, v, vn, 1, 64, msg, cap);
    if (is(k, kn, "queue_lines"))
        return set_u32(&c->tcp.queue_lines, v, vn, 1, QUEUE_MAX, msg, cap);
    if (is(k, kn, "sndbuf_bytes"))
        return set_u32(&c->tcp.sndbuf_bytes, v, vn, 0, 16L * 1024 * 1024, msg, cap);
    return GS_ENOKEY;
}

static gs_status h_tcp_client(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg,
                              size_t cap)
{
    gs_sinks_config *c = ctx;
    c->tcp_client_sw.present = true;
    if (is(k, kn, "enabled"))
        return set_enabled(&c->tcp_client_sw, v, vn, msg, cap);
    if (is(k, kn, "host"))
        return set_text(c->tcp_client.host, sizeof c->tcp_client.host, v, vn, msg, cap);
    if (is(k, kn, "port"))
        return set_port(&c->tcp_client.port, v, vn, 1, msg, cap);
    if (is(k, kn, "backoff_min_s"))
        return set_secs(&c->tcp_client.backoff_min_s, v, vn, 0.01, 60.0, msg, cap);
    if (is(k, kn, "backoff_max_s"))
        return set_secs(&c->tcp_client.backoff_max_s, v, vn, 0.01, 3600.0, msg, cap);
    if (is(k, kn, "queue_lines"))
        return set_u32(&c->tcp_client.queue_lines, v, vn, 1, QUEUE_MAX, msg, cap);
    return GS_ENOKEY;
}

static gs_status h_udp(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg, size_t cap)
{
    gs_sinks_config *c = ctx;
    c->udp_sw.present = true;
    if (is(k, kn, "enabled"))
        return set_enabled(&c->udp_sw, v, vn, msg, cap);
    if (is(k, kn, "host"))
        return set_text(c->udp.host, sizeof c->udp.host, v, vn, msg, cap);
    if (is(k, kn, "port"))
        return set_port(&c->udp.port, v, vn, 1, msg, cap);
    return GS_ENOKEY;
}

/* a topic level or prefix: no wildcards; a level has no separator either */
static gs_status set_topic(char *dst, size_t cap, const char *v, size_t n, bool level, char *msg, size_t mcap)
{
    for (size_t i = 0; i < n; i++) {
        unsigned char ch = (unsigned char)v[i];
        if (ch == '+' || ch == '#' || ch < 0x20 || (level && ch == '/')) {
            snprintf(msg, mcap, level ? "no '/', '+', '#' or control characters in a topic level"
                                      : "no '+', '#' or control characters in a topic prefix");
            return GS_EINVAL;
        }
    }
    if (!level && n && (v[0] == '/' || v[n - 1] == '/')) {
        snprintf(msg, mcap, "a topic prefix neither starts nor ends with '/'");
        return GS_EINVAL;
    }
    return set_text(dst, cap, v, n, msg, mcap);
}

static gs_status set_bool(bool *dst, const char *v, size_t n, char *msg, size_t mcap)
{
    gs_sink_switch sw = {true, -1};
    gs_status st = set_enabled(&sw, v, n, msg, mcap);
    if (st == GS_OK)
        *dst = sw.enabled == 1;
    return st;
}

static gs_status h_mqtt(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg, size_t cap)
{
    gs_sinks_config *c = ctx;
    gs_sink_mqtt_cfg *m = &c->mqtt;
    c->mqtt_sw.present = true;
    if (is(k, kn, "enabled"))
        return set_enabled(&c->mqtt_sw, v, vn, msg, cap);
    if (is(k, kn, "host"))
        return set_text(m->host, sizeof m->host, v, vn, msg, cap);
    if (is(k, kn, "port"))
        return set_port(&m->port, v, vn, 1, msg, cap);
    if (is(k, kn, "client_id"))
        return set_text(m->client_id, sizeof m->client_id, v, vn, msg, cap);
    if (is(k, kn, "device"))
        return set_topic(m->device, sizeof m->device, v, vn, true, msg, cap);
    if (is(k, kn, "topic_prefix"))
        return set_topic(m->topic_prefix, sizeof m->topic_prefix, v, vn, false, msg, cap);
    if (is(k, kn, "qos")) {
        uint32_t q;
        gs_status st = set_u32(&q, v, vn, 0, 2, msg, cap);
        if (st == GS_OK)
            m->qos = (uint8_t)q;
        return st;
    }
    if (is(k, kn, "keepalive_s"))
        return set_u32(&m->keepalive_s, v, vn, 5, 3600, msg, cap);
    if (is(k, kn, "tls"))
        return set_bool(&m->tls, v, vn, msg, cap);
    if (is(k, kn, "tls_insecure"))
        return set_bool(&m->tls_insecure, v, vn, msg, cap);
    if (is(k, kn, "ca_file"))
        return set_text(m->ca_file, sizeof m->ca_file, v, vn, msg, cap);
    if (is(k, kn, "ca_path"))
        return set_text(m->ca_path, sizeof m->ca_path, v, vn, msg, cap);
    if (is(k, kn, "cert_file"))
        return set_text(m->cert_file, sizeof m->cert_file, v, vn, msg, cap);
    if (is(k, kn, "key_file"))
        return set_text(m->key_file, sizeof m->key_file, v, vn, msg, cap);
    if (is(k, kn, "username"))
        return set_text(m->username, sizeof m->username, v, vn, msg, cap);
    if (is(k, kn, "password"))
        return set_text(m->password, sizeof m->password, v, vn, msg, cap);
    if (is(k, kn, "password_file"))
        return set_text(m->password_file, sizeof m->password_file, v, vn, msg, cap);
    if (is(k, kn, "backoff_min_s"))
        return set_secs(&m->backoff_min_s, v, vn, 0.01, 60.0, msg, cap);
    if (is(k, kn, "backoff_max_s"))
        return set_secs(&m->backoff_max_s, v, vn, 0.01, 3600.0, msg, cap);
    if (is(k, kn, "queue_lines"))
        return set_u32(&m->queue_lines, v, vn, 1, QUEUE_MAX, msg, cap);
    return GS_ENOKEY;
}

static gs_status h_status(void *ctx, const char *k, size_t kn, const char *v, size_t vn, char *msg, size_t cap)
{
    gs_sinks_config *c = ctx;
    if (is(k, kn, "interval_s"))
        return set_secs(&c->status_interval_s, v, vn, 0.0, 3600.0, msg, cap);
    return GS_ENOKEY;
}

size_t gs_sinks_config_sections(gs_sinks_config *c, gs_cfg_section *out, size_t cap)
{
    if (cap < GS_SINKS_CONFIG_SECTIONS)
        return 0;
    out[0] = (gs_cfg_section){"sink.stdout", h_stdout, c};
    out[1] = (gs_cfg_section){"sink.file", h_file, c};
    out[2] = (gs_cfg_section){"sink.serial", h_serial, c};
    out[3] = (gs_cfg_section){"sink.tcp", h_tcp, c};
    out[4] = (gs_cfg_section){"sink.tcp_client", h_tcp_client, c};
    out[5] = (gs_cfg_section){"sink.udp", h_udp, c};
    out[6] = (gs_cfg_section){"sink.mqtt", h_mqtt, c};
    out[7] = (gs_cfg_section){"status", h_status, c};
    return GS_SINKS_CONFIG_SECTIONS;
}

/* ------------------------------------------------------------------- checks */

static gs_status missing(gs_cfg_error *err, const char *sec, const char *key, const char *msg)
{
    memset(err, 0, sizeof *err);
    snprintf(err->section, sizeof err->section, "%s", sec);
    snprintf(err->key, sizeof err->key, "%s", key);
    snprintf(err->msg, sizeof err->msg, "%s", msg);
    return GS_EINVAL;
}

gs_status gs_sinks_config_check(const gs_sinks_config *c, gs_cfg_error *err)
{
    gs_cfg_error dummy;
    if (!err)
        err = &dummy;
    if (gs_sinks_config_on(&c->file_sw, false) && !c->file_path[0])
        return missing(err, "sink.file", "path", "an enabled file sink needs a path");
    if (gs_sinks_config_on(&c->serial_sw, false) && !c->serial.device[0])
        return missing(err, "sink.serial", "device", "an enabled serial sink needs a device");
    if (gs_sinks_config_on(&c->tcp_client_sw, false)) {
        if (!c->tcp_client.host[0])
            return missing(err, "sink.tcp_client", "host", "an enabled TCP client sink needs a host");
        if (!c->tcp_client.port)
            return missing(err, "sink.tcp_client", "port", "an enabled TCP client sink needs a port");
        if (c->tcp_client.backoff_min_s > c->tcp_client.backoff_max_s) {
            missing(err, "sink.tcp_client", "backoff_max_s", "backoff_max_s below backoff_min_s");
            return GS_ERANGE;
        }
    }
    if (gs_sinks_config_on(&c->udp_sw, false)) {
        if (!c->udp.host[0])
            return missing(err, "sink.udp", "host", "an enabled UDP sink needs a host");
        if (!c->udp.port)
            return missing(err, "sink.udp", "port", "an enabled UDP sink needs a port");
    }
    if (gs_sinks_config_on(&c->mqtt_sw, false)) {
        const gs_sink_mqtt_cfg *m = &c->mqtt;
        if (!m->host[0])
            return missing(err, "sink.mqtt", "host", "an enabled MQTT sink needs a host");
        if (m->backoff_min_s > m->backoff_max_s) {
            missing(err, "sink.mqtt", "backoff_max_s", "backoff_max_s below backoff_min_s");
            return GS_ERANGE;
        }
        if (m->tls && !m->ca_file[0] && !m->ca_path[0])
            return missing(err, "sink.mqtt", "ca_file", "tls = yes needs ca_file or ca_path (the broker's CA)");
        if (!m->tls && (m->ca_file[0] || m->ca_path[0] || m->cert_file[0] || m->key_file[0] || m->tls_insecure))
            return missing(err, "sink.mqtt", "tls", "TLS keys are set but tls is not yes");
        if (!m->cert_file[0] != !m->key_file[0])
            return missing(err, "sink.mqtt", m->cert_file[0] ? "key_file" : "cert_file",
                           "a client certificate needs both cert_file and key_file");
        if (m->password[0] && m->password_file[0])
            return missing(err, "sink.mqtt", "password_file", "password and password_file are both set");
        if ((m->password[0] || m->password_file[0]) && !m->username[0])
            return missing(err, "sink.mqtt", "username", "a password needs a username");
    }
    memset(err, 0, sizeof *err);
    return GS_OK;
}

/* -------------------------------------------------------------------- open */

int gs_sinkset_open_config(gs_sinkset *set, const gs_sinks_config *c, double now_s, char *err, size_t cap)
{
    gs_sinkset_init(set);
    gs_sink s;
    int rc = 0;
    if (rc == 0 && gs_sinks_config_on(&c->stdout_sw, true))
        rc = gs_sink_fd_open(&s, STDOUT_FILENO, "stdout", err, cap) || gs_sinkset_add(set, &s);
    if (rc == 0 && gs_sinks_config_on(&c->file_sw, false))
        rc = gs_sink_file_open(&s, c->file_path, err, cap) || gs_sinkset_add(set, &s);
    if (rc == 0 && gs_sinks_config_on(&c->serial_sw, false))
        rc = gs_sink_serial_open(&s, &c->serial, now_s, err, cap) || gs_sinkset_add(set, &s);
    if (rc == 0 && gs_sinks_config_on(&c->tcp_sw, false))
        rc = gs_sink_tcp_open(&s, &c->tcp, err, cap) || gs_sinkset_add(set, &s);
    if (rc == 0 && gs_sinks_config_on(&c->tcp_client_sw, false))
        rc = gs_sink_tcp_client_open(&s, &c->tcp_client, now_s, err, cap) || gs_sinkset_add(set, &s);
    if (rc == 0 && gs_sinks_config_on(&c->udp_sw, false))
        rc = gs_sink_udp_open(&s, &c->udp, err, cap) || gs_sinkset_add(set, &s);
    if (rc == 0 && gs_sinks_config_on(&c->mqtt_sw, false))
        rc = gs_sink_mqtt_open(&s, &c->mqtt, now_s, err, cap) || gs_sinkset_add(set, &s);
    if (rc != 0) {
        gs_sinkset_close(set);
        return -1;
    }
    return 0;
}
