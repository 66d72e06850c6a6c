/* fuzz_sink_config.c - libFuzzer harness for a whole profile as the daemon
 * reads it: gs_cfg_parse with [core], the [sink.*] and [status] handlers
 * (src/io/gs_sink_config.c) and a stand-in [ball] section, then
 * gs_sinks_config_check. Properties: no crash, no read past the text; error
 * records NUL-terminated and explained; after an accepted text every field is
 * in its documented range and every string NUL-terminated inside its array;
 * a check failure names section and key; MQTT topic levels carry no wildcard
 * and the device no separator; the sink status line built from the
 * configured names (through a /dev/null descriptor sink) is valid JSON.
 * Nothing is opened on the network. Built by tests/fuzz/run.sh (clang). */
#include "gs_sink_config.h"
#include "fuzz_util.h"

#include <arpa/inet.h>
#include <netinet/in.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static gs_status ball_set(void *ctx, const char *key, size_t key_len, const char *value, size_t value_len,
                          char *msg, size_t cap)
{
    (void)ctx;
    (void)value;
    (void)value_len;
    if (key_len == 5 && memcmp(key, "color", 5) == 0) return GS_OK;
    if (cap) snprintf(msg, cap, "stand-in: only 'color'");
    return GS_ENOKEY;
}

static bool terminated(const char *s, size_t cap) { return memchr(s, 0, cap) != NULL; }

static void check_switch(const gs_sink_switch *sw) { FZ_CHECK(sw->enabled >= -1 && sw->enabled <= 1); }

/* the status line of a sink named name must be valid JSON whatever the name holds */
static void check_status_json(const char *name)
{
    static int devnull = -1;
    if (devnull < 0) devnull = open("/dev/null", O_WRONLY);
    FZ_CHECK(devnull >= 0);
    gs_sinkset set;
    gs_sinkset_init(&set);
    gs_sink s;
    char err[160];
    FZ_CHECK(gs_sink_fd_open(&s, devnull, name, err, sizeof err) == 0);
    FZ_CHECK(gs_sinkset_add(&set, &s) == 0);
    char buf[2048];
    size_t n = gs_sinkset_status_json(&set, buf, sizeof buf);
    FZ_CHECK(n > 0 && strlen(buf) == n);
    FZ_CHECK(fz_json_valid(buf, n, 64, true));
    gs_sinkset_close(&set);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *s = malloc(size ? size : 1);
    if (!s) return 0;
    if (size) memcpy(s, data, size);
    gs_core_config core;
    gs_core_config_default(&core);
    gs_sinks_config sc;
    gs_sinks_config_default(&sc);
    gs_cfg_section sec[2 + GS_SINKS_CONFIG_SECTIONS];
    sec[0] = (gs_cfg_section){"core", gs_core_config_set, &core};
    sec[1] = (gs_cfg_section){"ball", ball_set, NULL};
    FZ_CHECK(gs_sinks_config_sections(&sc, sec + 2, GS_SINKS_CONFIG_SECTIONS) == GS_SINKS_CONFIG_SECTIONS);
    gs_cfg_error err;
    memset(&err, 0x5a, sizeof err);
    gs_status st = gs_cfg_parse(s, size, sec, sizeof sec / sizeof sec[0], &err);
    FZ_CHECK(terminated(err.section, sizeof err.section) && terminated(err.key, sizeof err.key) &&
             terminated(err.msg, sizeof err.msg));
    if (st != GS_OK) {
        FZ_CHECK(err.msg[0] != '\0' && err.line >= 1);
        free(s);
        return 0;
    }
    FZ_CHECK(err.line == 0 && err.msg[0] == '\0');
    /* ranges after any accepted text (docs/sinks.md) */
    check_switch(&sc.stdout_sw);
    check_switch(&sc.file_sw);
    check_switch(&sc.serial_sw);
    check_switch(&sc.tcp_sw);
    check_switch(&sc.tcp_client_sw);
    check_switch(&sc.udp_sw);
    check_switch(&sc.mqtt_sw);
    const gs_sink_mqtt_cfg *m = &sc.mqtt;
    FZ_CHECK(terminated(m->host, sizeof m->host) && terminated(m->client_id, sizeof m->client_id) &&
             terminated(m->device, sizeof m->device) && terminated(m->topic_prefix, sizeof m->topic_prefix) &&
             terminated(m->ca_file, sizeof m->ca_file) && terminated(m->ca_path, sizeof m->ca_path) &&
             terminated(m->cert_file, sizeof m->cert_file) && terminated(m->key_file, sizeof m->key_file) &&
             terminated(m->username, sizeof m->username) && terminated(m->password, sizeof m->password) &&
             terminated(m->password_file, sizeof m->password_file));
    FZ_CHECK(m->qos <= 2 && m->keepalive_s >= 5 && m->keepalive_s <= 3600);
    FZ_CHECK(m->queue_lines >= 1 && m->queue_lines <= 65536);
    FZ_CHECK(m->backoff_min_s >= 0.01 && m->backoff_max_s <= 3600.0);
    /* topics: no wildcard anywhere, no separator in the device level */
    FZ_CHECK(!strpbrk(m->topic_prefix, "+#") && !strpbrk(m->device, "/+#"));
    FZ_CHECK(m->topic_prefix[0] != '/' && (!m->topic_prefix[0] || m->topic_prefix[strlen(m->topic_prefix) - 1] != '/'));
    FZ_CHECK(terminated(sc.file_path, sizeof sc.file_path));
    FZ_CHECK(terminated(sc.serial.device, sizeof sc.serial.device));
    FZ_CHECK(terminated(sc.tcp.bind, sizeof sc.tcp.bind));
    FZ_CHECK(terminated(sc.tcp_client.host, sizeof sc.tcp_client.host));
    FZ_CHECK(terminated(sc.udp.host, sizeof sc.udp.host));
    FZ_CHECK(gs_sink_serial_baud_ok(sc.serial.baud));
    FZ_CHECK(sc.serial.reopen_s >= 0.05 && sc.serial.reopen_s <= 3600.0);
    FZ_CHECK(sc.serial.queue_lines >= 1 && sc.serial.queue_lines <= 65536);
    FZ_CHECK(sc.tcp.max_clients >= 1 && sc.tcp.max_clients <= 64);
    FZ_CHECK(sc.tcp.queue_lines >= 1 && sc.tcp.queue_lines <= 65536);
    FZ_CHECK(sc.tcp.sndbuf_bytes <= 16u * 1024 * 1024);
    unsigned char a[sizeof(struct in6_addr)];
    FZ_CHECK(inet_pton(AF_INET, sc.tcp.bind, a) == 1 || inet_pton(AF_INET6, sc.tcp.bind, a) == 1);
    FZ_CHECK(sc.tcp_client.backoff_min_s >= 0.01 && sc.tcp_client.backoff_min_s <= 60.0);
    FZ_CHECK(sc.tcp_client.backoff_max_s >= 0.01 && sc.tcp_client.backoff_max_s <= 3600.0);
    FZ_CHECK(sc.tcp_client.queue_lines >= 1 && sc.tcp_client.queue_lines <= 65536);
    FZ_CHECK(sc.status_interval_s >= 0.0 && sc.status_interval_s <= 3600.0);
    memset(&err, 0x5a, sizeof err);
    gs_status cs = gs_sinks_config_check(&sc, &err);
    FZ_CHECK(terminated(err.section, sizeof err.section) && terminated(err.key, sizeof err.key) &&
             terminated(err.msg, sizeof err.msg) && err.line == 0);
    if (cs != GS_OK) FZ_CHECK(strncmp(err.section, "sink.", 5) == 0 && err.key[0] && err.msg[0]);
    else {
        /* what the daemon will open has what it needs */
        if (gs_sinks_config_on(&sc.file_sw, false)) FZ_CHECK(sc.file_path[0]);
        if (gs_sinks_config_on(&sc.serial_sw, false)) FZ_CHECK(sc.serial.device[0]);
        if (gs_sinks_config_on(&sc.tcp_client_sw, false))
            FZ_CHECK(sc.tcp_client.host[0] && sc.tcp_client.port &&
                     sc.tcp_client.backoff_min_s <= sc.tcp_client.backoff_max_s);
        if (gs_sinks_config_on(&sc.udp_sw, false)) FZ_CHECK(sc.udp.host[0] && sc.udp.port);
        if (gs_sinks_config_on(&sc.mqtt_sw, false))
            FZ_CHECK(m->host[0] && m->backoff_min_s <= m->backoff_max_s && (!m->tls || m->ca_file[0] || m->ca_path[0]) &&
                     !m->cert_file[0] == !m->key_file[0] && !(m->password[0] && m->password_file[0]) &&
                     (m->username[0] || (!m->password[0] && !m->password_file[0])));
    }
    /* names from the profile end up in status lines */
    if (sc.file_path[0]) check_status_json(sc.file_path);
    if (sc.serial.device[0]) check_status_json(sc.serial.device);
    if (sc.tcp_client.host[0]) check_status_json(sc.tcp_client.host);
    if (m->host[0]) check_status_json(m->host);
    free(s);
    return 0;
}
