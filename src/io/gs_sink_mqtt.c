/* gs_sink_mqtt.c - the MQTT sink over libmosquitto (Debian's libmosquitto-dev),
 * driven without its thread: gs_sinkset_poll runs mosquitto_loop with a zero
 * timeout, connects and reconnects with backoff, and hands queued lines to
 * mosquitto_publish only while connected, so the bound on what waits for a
 * broker is this sink's own queue of whole lines (libmosquitto would queue
 * QoS 1 messages without limit). Messages libmosquitto holds unacknowledged
 * when a connection drops are sent again by it after the reconnect. */
#include "gs_sink.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#if defined(GS_HAVE_MOSQUITTO)
#include <mosquitto.h>

#define CONNECT_TIMEOUT_S 10.0 /* no CONNACK this long after a connect started: retry */
#define EVENT_NAME_MAX 32

typedef struct {
    gs_sink_mqtt_cfg cfg;
    struct mosquitto *m;
    gs_lineq q;
    gs_lineq_reader r;
    gs_sink_state st;
    int last_errno;
    bool started;              /* mosquitto_connect_async was called once (later: reconnect_async) */
    double now_s, next_try_s, backoff_s, connect_start_s;
    uint64_t connects;
    uint64_t handed, done;     /* event messages given to libmosquitto / sent (QoS 0) or acknowledged */
    uint64_t not_json;         /* lines that are not JSON events: dropped */
    int online_mid;            /* the availability message (not an event) */
    char device[64];
    char base[200];            /* <prefix>/<device> */
    char target[160];
} mqtt_sink;

static int lib_users; /* mosquitto_lib_init / cleanup pairs (one thread: the daemon's loop) */

bool gs_sink_mqtt_available(void) { return true; }

/* the event name of a JSON event line: {"event":"NAME",... ; false for anything else */
static bool event_name(const char *line, size_t len, char *name, size_t cap)
{
    static const char head[] = "{\"event\":\"";
    const size_t hl = sizeof head - 1;
    if (len < hl + 2 || memcmp(line, head, hl) != 0)
        return false;
    size_t i = hl, n = 0;
    while (i < len && line[i] != '"') {
        char c = line[i++];
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_') || n + 1 >= cap || n >= EVENT_NAME_MAX)
            return false;
        name[n++] = c;
    }
    name[n] = '\0';
    return n > 0 && i < len;
}

static void schedule(mqtt_sink *s, int err)
{
    s->st = GS_SINK_RETRYING;
    if (err)
        s->last_errno = err;
    s->next_try_s = s->now_s + s->backoff_s;
    s->backoff_s *= 2.0;
    if (s->backoff_s > s->cfg.backoff_max_s)
        s->backoff_s = s->cfg.backoff_max_s;
}

/* libmosquitto's return codes as an errno for the status line */
static int rc_errno(int rc)
{
    switch (rc) {
    case MOSQ_ERR_ERRNO: return errno ? errno : EIO;
    case MOSQ_ERR_NOMEM: return ENOMEM;
    case MOSQ_ERR_CONN_REFUSED: return ECONNREFUSED;
    case MOSQ_ERR_AUTH: return EACCES;
    case MOSQ_ERR_TLS: return EPROTO;
    case MOSQ_ERR_NO_CONN:
    case MOSQ_ERR_CONN_LOST: return ECONNRESET;
    default: return EIO;
    }
}

static void on_connect(struct mosquitto *m, void *obj, int rc)
{
    mqtt_sink *s = obj;
    if (rc != 0) { /* refused by the broker: bad credentials, client id, protocol */
        schedule(s, rc == 4 || rc == 5 ? EACCES : ECONNREFUSED);
        mosquitto_disconnect(m);
        return;
    }
    s->st = GS_SINK_UP;
    s->connects++;
    s->backoff_s = s->cfg.backoff_min_s;
    char topic[220];
    snprintf(topic, sizeof topic, "%s/status", s->base);
    int mid = 0;
    if (mosquitto_publish(m, &mid, topic, 6, "online", 1, true) == MOSQ_ERR_SUCCESS)
        s->online_mid = mid;
}

static void on_disconnect(struct mosquitto *m, void *obj, int rc)
{
    (void)m;
    mqtt_sink *s = obj;
    if (s->st != GS_SINK_RETRYING) /* not asked for here: the connection was lost */
        schedule(s, rc ? ECONNRESET : 0);
}

static void on_publish(struct mosquitto *m, void *obj, int mid)
{
    (void)m;
    mqtt_sink *s = obj;
    if (mid == s->online_mid && s->online_mid != 0) {
        s->online_mid = 0;
        return;
    }
    s->done++;
}

static void start_connect(mqtt_sink *s)
{
    s->connect_start_s = s->now_s;
    errno = 0;
    int rc = s->started ? mosquitto_reconnect_async(s->m)
                        : mosquitto_connect_async(s->m, s->cfg.host, s->cfg.port, (int)s->cfg.keepalive_s);
    s->started = true;
    if (rc != MOSQ_ERR_SUCCESS) {
        schedule(s, rc_errno(rc));
        return;
    }
    s->st = GS_SINK_CONNECTING;
}

static int send_line(void *ctx, const char *line, size_t len)
{
    mqtt_sink *s = ctx;
    char name[EVENT_NAME_MAX + 1], topic[260];
    if (!event_name(line, len, name, sizeof name))
        return 0; /* checked on intake: cannot happen */
    bool status = strcmp(name, "status") == 0;
    snprintf(topic, sizeof topic, status ? "%s/status/daemon" : "%s/%s", s->base, name);
    int qos = s->cfg.qos;
    if ((strcmp(name, "jump") == 0 || strcmp(name, "summary") == 0) && qos < 1)
        qos = 1;
    int rc = mosquitto_publish(s->m, NULL, topic, (int)(len - 1), line, qos, false);
    if (rc == MOSQ_ERR_SUCCESS) {
        s->handed++;
        return 0;
    }
    return rc == MOSQ_ERR_NOMEM ? EAGAIN : rc_errno(rc);
}

static void pump(mqtt_sink *s)
{
    if (s->st != GS_SINK_UP)
        return;
    int e = gs_lineq_pump_msg(&s->r, &s->q, send_line, s);
    if (e) { /* the line stays in hand for the next connection */
        mosquitto_disconnect(s->m);
        schedule(s, e);
    }
}

static int mq_write_line(void *state, const char *line, size_t len)
{
    mqtt_sink *s = state;
    char name[EVENT_NAME_MAX + 1];
    if (len == 0 || line[len - 1] != '\n' || !event_name(line, len, name, sizeof name)) {
        s->q.taken++; /* counted as taken and refused, like a line without its newline */
        s->q.refused++;
        s->not_json++;
        return -1;
    }
    if (gs_lineq_take(&s->q, line, len) != 0)
        return -1;
    pump(s);
    return 0;
}

static void mq_poll(void *state, double now_s)
{
    mqtt_sink *s = state;
    s->now_s = now_s;
    if (s->st == GS_SINK_RETRYING) {
        if (now_s < s->next_try_s)
            return;
        start_connect(s);
        if (s->st == GS_SINK_RETRYING)
            return;
    }
    errno = 0;
    int rc = mosquitto_loop(s->m, 0, 1);
    if (rc != MOSQ_ERR_SUCCESS && s->st != GS_SINK_RETRYING) {
        /* lost (libmosquitto may not call on_disconnect for a failed connect) */
        schedule(s, rc_errno(rc));
        return;
    }
    if (s->st == GS_SINK_CONNECTING && now_s - s->connect_start_s > CONNECT_TIMEOUT_S) {
        mosquitto_disconnect(s->m);
        schedule(s, ETIMEDOUT);
        return;
    }
    pump(s);
}

static void mq_info(const void *state, gs_sink_info *o)
{
    const mqtt_sink *s = state;
    memset(o, 0, sizeof *o);
    o->kind = "mqtt";
    snprintf(o->target, sizeof o->target, "%s", s->target);
    o->state = s->st;
    o->last_errno = s->last_errno;
    gs_sink_counters_fill(&o->c, &s->q, &s->r);
    /* sent = taken by the network (QoS 0) or acknowledged (QoS 1, 2); handed but not yet done waits */
    uint64_t waiting = s->handed - s->done;
    o->c.lines_sent = s->done;
    o->c.lines_queued += waiting;
    o->c.reopens = s->connects;
}

static void mq_close(void *state)
{
    mqtt_sink *s = state;
    if (s->st == GS_SINK_UP) { /* a clean goodbye: the broker sends no will, so say it */
        char topic[220];
        snprintf(topic, sizeof topic, "%s/status", s->base);
        int mid = 0;
        if (mosquitto_publish(s->m, &mid, topic, 7, "offline", 1, true) == MOSQ_ERR_SUCCESS) {
            s->online_mid = mid;
            double t0 = gs_sink_now_s();
            while (s->online_mid == mid && s->st == GS_SINK_UP && gs_sink_now_s() - t0 < 1.0)
                if (mosquitto_loop(s->m, 10, 1) != MOSQ_ERR_SUCCESS)
                    break;
        }
        mosquitto_disconnect(s->m);
        mosquitto_loop(s->m, 0, 1);
    }
    mosquitto_destroy(s->m);
    gs_lineq_free(&s->q);
    free(s);
    if (--lib_users == 0)
        mosquitto_lib_cleanup();
}

/* the first line of a file (a password kept out of the profile) */
static bool read_first_line(const char *path, char *dst, size_t cap)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return false;
    bool ok = fgets(dst, (int)cap, f) != NULL;
    fclose(f);
    if (!ok)
        return false;
    dst[strcspn(dst, "\r\n")] = '\0';
    return true;
}

/* a topic level from the host name: MQTT's separators and wildcards replaced */
static void device_from_host(char *dst, size_t cap)
{
    if (gethostname(dst, cap) != 0 || !dst[0])
        snprintf(dst, cap, "gravscale");
    dst[cap - 1] = '\0';
    for (char *p = dst; *p; p++)
        if (*p == '/' || *p == '+' || *p == '#')
            *p = '_';
}

int gs_sink_mqtt_open(gs_sink *out, const gs_sink_mqtt_cfg *cfg, double now_s, char *err, size_t cap)
{
    memset(out, 0, sizeof *out);
    mqtt_sink *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, cap, "mqtt %s: out of memory", cfg->host);
        return -1;
    }
    s->cfg = *cfg;
    if (!s->cfg.port)
        s->cfg.port = cfg->tls ? 8883 : 1883;
    if (!(s->cfg.backoff_min_s > 0.0))
        s->cfg.backoff_min_s = 0.5;
    if (!(s->cfg.backoff_max_s >= s->cfg.backoff_min_s))
        s->cfg.backoff_max_s = s->cfg.backoff_min_s;
    if (!s->cfg.keepalive_s)
        s->cfg.keepalive_s = 30;
    snprintf(s->target, sizeof s->target, "%s:%u", cfg->host, (unsigned)s->cfg.port);
    if (cfg->device[0])
        snprintf(s->device, sizeof s->device, "%s", cfg->device);
    else
        device_from_host(s->device, sizeof s->device);
    snprintf(s->base, sizeof s->base, "%s/%s", cfg->topic_prefix[0] ? cfg->topic_prefix : "gravscale", s->device);
    char client_id[160];
    if (cfg->client_id[0])
        snprintf(client_id, sizeof client_id, "%s", cfg->client_id);
    else
        snprintf(client_id, sizeof client_id, "gravscale-%s", s->device);
    char password[256] = "";
    if (cfg->password_file[0] && !read_first_line(cfg->password_file, password, sizeof password)) {
        snprintf(err, cap, "mqtt %s: password_file %s: %s", s->target, cfg->password_file, strerror(errno ? errno : EIO));
        free(s);
        return -1;
    }
    if (cfg->password[0])
        snprintf(password, sizeof password, "%s", cfg->password);
    if (gs_lineq_init(&s->q, cfg->queue_lines, (size_t)cfg->queue_lines * GS_EMIT_MAX) != 0) {
        snprintf(err, cap, "mqtt %s: out of memory", s->target);
        free(s);
        return -1;
    }
    if (lib_users++ == 0)
        mosquitto_lib_init();
    /* a clean session: nothing is subscribed; unacknowledged messages are resent by the library */
    s->m = mosquitto_new(client_id, true, s);
    const char *what = NULL;
    int rc = s->m ? MOSQ_ERR_SUCCESS : MOSQ_ERR_NOMEM;
    char status_topic[220];
    snprintf(status_topic, sizeof status_topic, "%s/status", s->base);
    if (rc == MOSQ_ERR_SUCCESS && (rc = mosquitto_will_set(s->m, status_topic, 7, "offline", 1, true)) != MOSQ_ERR_SUCCESS)
        what = "last will";
    if (rc == MOSQ_ERR_SUCCESS && cfg->username[0] &&
        (rc = mosquitto_username_pw_set(s->m, cfg->username, password[0] ? password : NULL)) != MOSQ_ERR_SUCCESS)
        what = "credentials";
    if (rc == MOSQ_ERR_SUCCESS && cfg->tls) {
        rc = mosquitto_tls_set(s->m, cfg->ca_file[0] ? cfg->ca_file : NULL, cfg->ca_path[0] ? cfg->ca_path : NULL,
                               cfg->cert_file[0] ? cfg->cert_file : NULL, cfg->key_file[0] ? cfg->key_file : NULL,
                               NULL);
        if (rc != MOSQ_ERR_SUCCESS)
            what = "tls (ca_file, ca_path, cert_file, key_file readable?)";
        else if ((rc = mosquitto_tls_insecure_set(s->m, cfg->tls_insecure)) != MOSQ_ERR_SUCCESS)
            what = "tls_insecure";
    }
    memset(password, 0, sizeof password);
    if (rc != MOSQ_ERR_SUCCESS) {
        snprintf(err, cap, "mqtt %s: %s: %s", s->target, what ? what : "client", mosquitto_strerror(rc));
        if (s->m)
            mosquitto_destroy(s->m);
        gs_lineq_free(&s->q);
        free(s);
        if (--lib_users == 0)
            mosquitto_lib_cleanup();
        return -1;
    }
    mosquitto_connect_callback_set(s->m, on_connect);
    mosquitto_disconnect_callback_set(s->m, on_disconnect);
    mosquitto_publish_callback_set(s->m, on_publish);
    gs_lineq_reader_init(&s->r, &s->q);
    s->now_s = now_s;
    s->backoff_s = s->cfg.backoff_min_s;
    s->st = GS_SINK_RETRYING;
    s->next_try_s = now_s;
    start_connect(s); /* a broker that is not up yet is no error: the sink keeps trying */
    out->state = s;
    out->write_line = mq_write_line;
    out->poll = mq_poll;
    out->info = mq_info;
    out->close = mq_close;
    out->json_only = true;
    return 0;
}

#else /* built without libmosquitto */

bool gs_sink_mqtt_available(void) { return false; }

int gs_sink_mqtt_open(gs_sink *out, const gs_sink_mqtt_cfg *cfg, double now_s, char *err, size_t cap)
{
    (void)now_s;
    memset(out, 0, sizeof *out);
    snprintf(err, cap, "mqtt %s: this gravscale was built without libmosquitto (apt-get install libmosquitto-dev, "
             "then rebuild)", cfg->host);
    return -1;
}

#endif
