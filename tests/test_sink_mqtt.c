/* test_sink_mqtt.c - the MQTT sink against a real Mosquitto broker (Debian's
 * `mosquitto`) that the test starts on a free loopback port, with a libmosquitto
 * subscriber whose session the broker keeps (persistence on): every event
 * arrives once, in order, on <prefix>/<device>/<event>, jump and summary at QoS 1;
 * the retained status is "online" after a connect and "offline" after a clean
 * close or, through the last will, after the publisher dies; a broker restart
 * loses nothing that was queued while it was down; a full queue drops whole
 * oldest lines and counts them; NMEA lines are refused; TLS with a CA made
 * here by openssl; configuration errors name the key. */
#include "gs_sink.h"
#include "gs_sink_config.h"
#include "unity.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pwd.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#if defined(GS_HAVE_MOSQUITTO)
#include <mosquitto.h>
#endif

#define EQ_U64(a, b) TEST_ASSERT_EQUAL_UINT64((uint64_t)(a), (uint64_t)(b))

void setUp(void) {}
static void broker_stop(void);
void tearDown(void) { broker_stop(); } /* a failed test leaves no broker behind */

#if defined(GS_HAVE_MOSQUITTO)

static char g_dir[128];   /* broker config, persistence, certificates */
static uint16_t g_port;
static pid_t g_broker = -1;

static uint16_t free_port(void)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    TEST_ASSERT_EQUAL_INT(0, bind(fd, (struct sockaddr *)&a, sizeof a));
    socklen_t l = sizeof a;
    TEST_ASSERT_EQUAL_INT(0, getsockname(fd, (struct sockaddr *)&a, &l));
    close(fd);
    return ntohs(a.sin_port);
}

static bool port_open(uint16_t port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bool ok = connect(fd, (struct sockaddr *)&a, sizeof a) == 0;
    close(fd);
    return ok;
}

/* the broker: plain on g_port, persistence in g_dir (fresh: none kept from before);
 * extra lines for TLS */
static void broker_start_with(const char *extra, bool fresh)
{
    char conf[512], text[2048];
    /* started as root, the broker would switch to its own user and lose our files */
    const struct passwd *pw = getpwuid(getuid());
    if (fresh) {
        snprintf(conf, sizeof conf, "%s/mosquitto.db", g_dir);
        unlink(conf);
    }
    snprintf(conf, sizeof conf, "%s/mosquitto.conf", g_dir);
    snprintf(text, sizeof text,
             "user %s\nper_listener_settings false\nallow_anonymous true\npersistence true\n"
             "persistence_location %s/\nlog_dest file %s/broker.log\n%s",
             pw ? pw->pw_name : "root", g_dir, g_dir, extra && extra[0] ? extra : "");
    if (!extra || !extra[0]) {
        char l[64];
        snprintf(l, sizeof l, "listener %u 127.0.0.1\n", (unsigned)g_port);
        strncat(text, l, sizeof text - strlen(text) - 1);
    }
    FILE *f = fopen(conf, "w");
    TEST_ASSERT_NOT_NULL(f);
    fputs(text, f);
    fclose(f);
    g_broker = fork();
    TEST_ASSERT_TRUE(g_broker >= 0);
    if (g_broker == 0) {
        int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, 1);
        dup2(devnull, 2);
        execl(GS_MOSQUITTO_BIN, "mosquitto", "-c", conf, (char *)NULL);
        _exit(127);
    }
    for (int i = 0; i < 500 && !port_open(g_port); i++)
        poll(NULL, 0, 10);
    TEST_ASSERT_TRUE_MESSAGE(port_open(g_port), "the broker did not start");
}

static void broker_start(const char *extra) { broker_start_with(extra, false); }
static void broker_start_fresh(void) { broker_start_with(NULL, true); }

static void broker_stop(void)
{
    if (g_broker <= 0)
        return;
    kill(g_broker, SIGTERM); /* it saves its sessions and queued messages */
    int st;
    waitpid(g_broker, &st, 0);
    g_broker = -1;
}

/* ---------------------------------------------------------------- subscriber */

#define MAX_MSGS 512
typedef struct {
    char topic[160];
    char payload[1024];
    int qos;
    bool retain;
} msg;

typedef struct {
    struct mosquitto *m;
    msg msgs[MAX_MSGS];
    int n;
    bool connected, subscribed;
} sub;

static void sub_on_connect(struct mosquitto *m, void *obj, int rc)
{
    sub *s = obj;
    TEST_ASSERT_EQUAL_INT(0, rc);
    s->connected = true;
    mosquitto_subscribe(m, NULL, "t/#", 2);
}
static void sub_on_subscribe(struct mosquitto *m, void *obj, int mid, int n, const int *q)
{
    (void)m, (void)mid, (void)n, (void)q;
    ((sub *)obj)->subscribed = true;
}
static void sub_on_disconnect(struct mosquitto *m, void *obj, int rc)
{
    (void)m, (void)rc;
    ((sub *)obj)->connected = false;
}
static void sub_on_message(struct mosquitto *m, void *obj, const struct mosquitto_message *mm)
{
    (void)m;
    sub *s = obj;
    TEST_ASSERT_TRUE(s->n < MAX_MSGS);
    msg *x = &s->msgs[s->n++];
    snprintf(x->topic, sizeof x->topic, "%s", mm->topic);
    snprintf(x->payload, sizeof x->payload, "%.*s", mm->payloadlen, (const char *)mm->payload);
    x->qos = mm->qos;
    x->retain = mm->retain;
}

/* a durable session (clean_session false): the broker keeps what arrives while it is away */
static void sub_open(sub *s, const char *id)
{
    memset(s, 0, sizeof *s);
    s->m = mosquitto_new(id, false, s);
    TEST_ASSERT_NOT_NULL(s->m);
    mosquitto_connect_callback_set(s->m, sub_on_connect);
    mosquitto_subscribe_callback_set(s->m, sub_on_subscribe);
    mosquitto_disconnect_callback_set(s->m, sub_on_disconnect);
    mosquitto_message_callback_set(s->m, sub_on_message);
    TEST_ASSERT_EQUAL_INT(MOSQ_ERR_SUCCESS, mosquitto_connect(s->m, "127.0.0.1", g_port, 30));
    for (int i = 0; i < 300 && !s->subscribed; i++)
        mosquitto_loop(s->m, 10, 1);
    TEST_ASSERT_TRUE(s->subscribed);
}

static void sub_close(sub *s)
{
    mosquitto_disconnect(s->m);
    mosquitto_destroy(s->m);
    s->m = NULL;
}

/* run the sink and the subscriber until pred or timeout_s */
static void run_until(gs_sink *k, sub *s, double timeout_s, bool (*pred)(const sub *, const gs_sink *))
{
    double t0 = gs_sink_now_s();
    while (gs_sink_now_s() - t0 < timeout_s) {
        if (k)
            k->poll(k->state, gs_sink_now_s());
        if (s) {
            int rc = mosquitto_loop(s->m, 5, 1);
            if (rc == MOSQ_ERR_NO_CONN || rc == MOSQ_ERR_CONN_LOST) {
                mosquitto_reconnect(s->m); /* the broker came back */
            }
        } else {
            poll(NULL, 0, 5);
        }
        if (pred && pred(s, k))
            return;
    }
}

static int g_want;
static bool have_want(const sub *s, const gs_sink *k)
{
    (void)k;
    return s->n >= g_want;
}
static bool sink_up(const sub *s, const gs_sink *k)
{
    (void)s;
    gs_sink_info in;
    k->info(k->state, &in);
    return in.state == GS_SINK_UP;
}
static bool sink_retrying(const sub *s, const gs_sink *k)
{
    (void)s;
    gs_sink_info in;
    k->info(k->state, &in);
    return in.state == GS_SINK_RETRYING;
}

static gs_sink_mqtt_cfg base_cfg(void)
{
    gs_sinks_config c;
    gs_sinks_config_default(&c);
    gs_sink_mqtt_cfg m = c.mqtt;
    snprintf(m.host, sizeof m.host, "127.0.0.1");
    m.port = g_port;
    snprintf(m.device, sizeof m.device, "dev1");
    snprintf(m.topic_prefix, sizeof m.topic_prefix, "t");
    snprintf(m.client_id, sizeof m.client_id, "gs-test-pub");
    m.backoff_min_s = 0.05;
    m.backoff_max_s = 0.2;
    return m;
}

static size_t ev_line(char *buf, size_t cap, const char *ev, unsigned i)
{
    int w = snprintf(buf, cap, "{\"event\":\"%s\",\"i\":%u}\n", ev, i);
    return (size_t)w;
}

static void write_ok(gs_sink *k, const char *ev, unsigned i)
{
    char line[128];
    size_t n = ev_line(line, sizeof line, ev, i);
    TEST_ASSERT_EQUAL_INT(0, k->write_line(k->state, line, n));
}

/* the messages of s from index from on: topics and payloads of events i0..i1-1 */
static void check_events(const sub *s, int from, unsigned i0, unsigned i1, const char *ev)
{
    int k = 0;
    for (int j = from; j < s->n; j++) {
        const msg *x = &s->msgs[j];
        if (strncmp(x->topic, "t/dev1/status", 13) == 0 && strcmp(x->topic, "t/dev1/status") == 0)
            continue;  /* availability */
        char want_t[64], want_p[128];
        snprintf(want_t, sizeof want_t, "t/dev1/%s", ev);
        ev_line(want_p, sizeof want_p, ev, i0 + (unsigned)k);
        want_p[strlen(want_p) - 1] = '\0';
        TEST_ASSERT_EQUAL_STRING(want_t, x->topic);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(want_p, x->payload, "an event lost, repeated or out of order");
        k++;
    }
    EQ_U64(i1 - i0, k);
}

static int count_topic(const sub *s, const char *topic, const char *payload)
{
    int c = 0;
    for (int j = 0; j < s->n; j++)
        if (strcmp(s->msgs[j].topic, topic) == 0 && (!payload || strcmp(s->msgs[j].payload, payload) == 0))
            c++;
    return c;
}

/* ---------------------------------------------------------------------- tests */

static void test_events_topics_qos_and_status(void)
{
    broker_start_fresh();
    sub s;
    sub_open(&s, "gs-test-sub-a");
    gs_sink_mqtt_cfg c = base_cfg();
    gs_sink k;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_mqtt_open(&k, &c, gs_sink_now_s(), err, sizeof err), err);
    TEST_ASSERT_TRUE(k.json_only);
    run_until(&k, &s, 5.0, sink_up);
    const char *evs[] = {"start", "session", "jump", "height", "jump", "summary", "status"};
    char line[128];
    for (unsigned i = 0; i < 7; i++) {
        size_t n = ev_line(line, sizeof line, evs[i], i);
        TEST_ASSERT_EQUAL_INT(0, k.write_line(k.state, line, n));
    }
    /* an NMEA sentence and a line that is not an event: refused, counted, never published */
    TEST_ASSERT_EQUAL_INT(-1, k.write_line(k.state, "$GSSTA,0.1.0,30.000*7E\r\n", 24));
    TEST_ASSERT_EQUAL_INT(-1, k.write_line(k.state, "{\"i\":1}\n", 8));
    g_want = 8; /* online + 7 */
    run_until(&k, &s, 5.0, have_want);
    run_until(&k, &s, 0.3, NULL);
    TEST_ASSERT_EQUAL_INT(8, s.n);
    TEST_ASSERT_EQUAL_STRING("t/dev1/status", s.msgs[0].topic);
    TEST_ASSERT_EQUAL_STRING("online", s.msgs[0].payload);
    TEST_ASSERT_EQUAL_INT(1, s.msgs[0].qos);
    for (unsigned i = 0; i < 7; i++) {
        const msg *x = &s.msgs[1 + i];
        char want_t[64], want_p[128];
        snprintf(want_t, sizeof want_t, strcmp(evs[i], "status") == 0 ? "t/dev1/status/daemon" : "t/dev1/%s", evs[i]);
        ev_line(want_p, sizeof want_p, evs[i], i);
        want_p[strlen(want_p) - 1] = '\0';
        TEST_ASSERT_EQUAL_STRING(want_t, x->topic);
        TEST_ASSERT_EQUAL_STRING(want_p, x->payload);
        bool q1 = strcmp(evs[i], "jump") == 0 || strcmp(evs[i], "summary") == 0;
        TEST_ASSERT_EQUAL_INT_MESSAGE(q1 ? 1 : 0, x->qos, x->topic);
        TEST_ASSERT_FALSE(x->retain);
    }
    gs_sink_info in;
    k.info(k.state, &in);
    TEST_ASSERT_EQUAL_STRING("mqtt", in.kind);
    EQ_U64(9, in.c.lines_in);
    EQ_U64(7, in.c.lines_sent);
    EQ_U64(2, in.c.lines_dropped);
    EQ_U64(0, in.c.lines_queued);
    EQ_U64(1, in.c.reopens);
    /* a clean close says offline itself (no will is sent then) */
    k.close(k.state);
    g_want = 9;
    run_until(NULL, &s, 3.0, have_want);
    TEST_ASSERT_EQUAL_INT(9, s.n);
    TEST_ASSERT_EQUAL_STRING("t/dev1/status", s.msgs[8].topic);
    TEST_ASSERT_EQUAL_STRING("offline", s.msgs[8].payload);
    sub_close(&s);
    /* a late subscriber gets the retained availability */
    sub late;
    sub_open(&late, "gs-test-late");
    g_want = 1;
    run_until(NULL, &late, 3.0, have_want);
    TEST_ASSERT_EQUAL_INT(1, count_topic(&late, "t/dev1/status", "offline"));
    TEST_ASSERT_TRUE(late.msgs[0].retain);
    sub_close(&late);
    broker_stop();
}

static void test_broker_restart_loses_nothing(void)
{
    broker_start_fresh();
    sub s;
    sub_open(&s, "gs-test-sub-b");
    gs_sink_mqtt_cfg c = base_cfg();
    c.qos = 1;
    gs_sink k;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_mqtt_open(&k, &c, gs_sink_now_s(), err, sizeof err), err);
    run_until(&k, &s, 5.0, sink_up);
    for (unsigned i = 0; i < 10; i++)
        write_ok(&k, "jump", i);
    g_want = 11;
    run_until(&k, &s, 5.0, have_want);
    run_until(&k, &s, 0.3, NULL); /* the subscriber's acknowledgements reach the broker */
    TEST_ASSERT_EQUAL_INT(11, s.n);
    broker_stop();
    run_until(&k, &s, 3.0, sink_retrying);
    gs_sink_info in;
    k.info(k.state, &in);
    TEST_ASSERT_EQUAL_INT(GS_SINK_RETRYING, in.state);
    for (unsigned i = 10; i < 25; i++) /* while the broker is away */
        write_ok(&k, "jump", i);
    k.info(k.state, &in);
    EQ_U64(15, in.c.lines_queued);
    broker_start(NULL);
    g_want = 11 + 1 + 15; /* online again, then the queued events */
    run_until(&k, &s, 10.0, have_want);
    run_until(&k, &s, 0.3, NULL);
    TEST_ASSERT_EQUAL_INT(2, count_topic(&s, "t/dev1/status", "online"));
    check_events(&s, 0, 0, 25, "jump");
    k.info(k.state, &in);
    EQ_U64(25, in.c.lines_sent);
    EQ_U64(0, in.c.lines_dropped);
    EQ_U64(0, in.c.lines_queued);
    EQ_U64(2, in.c.reopens);
    k.close(k.state);
    sub_close(&s);
    broker_stop();
}

static void test_full_queue_drops_oldest_whole(void)
{
    broker_start_fresh();
    gs_sink_mqtt_cfg c = base_cfg();
    c.queue_lines = 4;
    gs_sink k;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_mqtt_open(&k, &c, gs_sink_now_s(), err, sizeof err), err);
    run_until(&k, NULL, 5.0, sink_up);
    sub s;
    sub_open(&s, "gs-test-sub-c");
    broker_stop();
    run_until(&k, &s, 3.0, sink_retrying);
    for (unsigned i = 0; i < 10; i++)
        write_ok(&k, "height", i);
    gs_sink_info in;
    k.info(k.state, &in);
    EQ_U64(10, in.c.lines_in);
    EQ_U64(6, in.c.lines_dropped);
    EQ_U64(4, in.c.lines_queued);
    broker_start(NULL);
    g_want = 1 + 4;
    run_until(&k, &s, 10.0, have_want);
    run_until(&k, &s, 0.3, NULL);
    check_events(&s, 0, 6, 10, "height"); /* the newest four, whole */
    k.info(k.state, &in);
    EQ_U64(in.c.lines_in, in.c.lines_sent + in.c.lines_dropped + in.c.lines_queued);
    k.close(k.state);
    sub_close(&s);
    broker_stop();
}

static void test_last_will_when_the_publisher_dies(void)
{
    broker_start_fresh();
    sub s;
    sub_open(&s, "gs-test-sub-d");
    pid_t child = fork();
    TEST_ASSERT_TRUE(child >= 0);
    if (child == 0) {
        gs_sink_mqtt_cfg c = base_cfg();
        gs_sink k;
        char err[256];
        if (gs_sink_mqtt_open(&k, &c, gs_sink_now_s(), err, sizeof err) != 0)
            _exit(1);
        double t0 = gs_sink_now_s();
        for (;;) { /* run until killed */
            k.poll(k.state, gs_sink_now_s());
            poll(NULL, 0, 5);
            if (gs_sink_now_s() - t0 > 20)
                _exit(2);
        }
    }
    g_want = 1;
    run_until(NULL, &s, 5.0, have_want);
    TEST_ASSERT_EQUAL_INT(1, count_topic(&s, "t/dev1/status", "online"));
    kill(child, SIGKILL);
    int st;
    waitpid(child, &st, 0);
    g_want = 2;
    run_until(NULL, &s, 5.0, have_want);
    TEST_ASSERT_EQUAL_INT(1, count_topic(&s, "t/dev1/status", "offline"));
    sub_close(&s);
    broker_stop();
}

static int sh(const char *cmd)
{
    int rc = system(cmd);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

static void test_tls(void)
{
    /* a CA and a server certificate for 127.0.0.1, made here */
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "cd %s && openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=gs-test-ca "
             "-keyout ca.key -out ca.crt >/dev/null 2>&1 && "
             "openssl req -newkey rsa:2048 -nodes -subj /CN=127.0.0.1 -keyout srv.key -out srv.csr >/dev/null 2>&1 && "
             "printf 'subjectAltName=IP:127.0.0.1\\n' > ext.cnf && "
             "openssl x509 -req -in srv.csr -CA ca.crt -CAkey ca.key -CAcreateserial -days 2 -extfile ext.cnf "
             "-out srv.crt >/dev/null 2>&1",
             g_dir);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, sh(cmd), "openssl could not make the test certificates");
    uint16_t plain = g_port, tls_port = free_port();
    char extra[1024];
    snprintf(extra, sizeof extra,
             "listener %u 127.0.0.1\nlistener %u 127.0.0.1\ncafile %s/ca.crt\ncertfile %s/srv.crt\nkeyfile %s/srv.key\n",
             (unsigned)plain, (unsigned)tls_port, g_dir, g_dir, g_dir);
    snprintf(cmd, sizeof cmd, "%s/mosquitto.db", g_dir);
    unlink(cmd);
    broker_start(extra);
    sub s;
    sub_open(&s, "gs-test-sub-e");
    gs_sink_mqtt_cfg c = base_cfg();
    c.port = tls_port;
    c.tls = true;
    snprintf(c.ca_file, sizeof c.ca_file, "%s/ca.crt", g_dir);
    gs_sink k;
    char err[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_mqtt_open(&k, &c, gs_sink_now_s(), err, sizeof err), err);
    run_until(&k, &s, 5.0, sink_up);
    write_ok(&k, "summary", 7);
    g_want = 2;
    run_until(&k, &s, 5.0, have_want);
    check_events(&s, 0, 7, 8, "summary");
    k.close(k.state);
    /* a CA that did not sign the server's certificate: never up, the reason shown */
    snprintf(cmd, sizeof cmd, "cd %s && openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=other "
             "-keyout o.key -out other.crt >/dev/null 2>&1", g_dir);
    TEST_ASSERT_EQUAL_INT(0, sh(cmd));
    snprintf(c.ca_file, sizeof c.ca_file, "%s/other.crt", g_dir);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, gs_sink_mqtt_open(&k, &c, gs_sink_now_s(), err, sizeof err), err);
    run_until(&k, NULL, 1.0, sink_up);
    gs_sink_info in;
    k.info(k.state, &in);
    TEST_ASSERT_NOT_EQUAL(GS_SINK_UP, in.state);
    k.close(k.state);
    /* a CA file that is not there: an error at open, naming it */
    snprintf(c.ca_file, sizeof c.ca_file, "%s/missing.crt", g_dir);
    TEST_ASSERT_EQUAL_INT(-1, gs_sink_mqtt_open(&k, &c, gs_sink_now_s(), err, sizeof err));
    TEST_ASSERT_NOT_NULL(strstr(err, "tls"));
    sub_close(&s);
    broker_stop();
}

/* the profile's [sink.mqtt] keys and their errors */
static void test_config(void)
{
    static const struct {
        const char *text;
        gs_status st;
        const char *key, *frag;
    } bad[] = {
        {"[sink.mqtt]\nport = 1883\n", GS_EINVAL, "host", "needs a host"},
        {"[sink.mqtt]\nhost = b\nqos = 3\n", GS_ERANGE, "qos", "out of range"},
        {"[sink.mqtt]\nhost = b\ntopic_prefix = a/#\n", GS_EINVAL, "topic_prefix", "'#'"},
        {"[sink.mqtt]\nhost = b\ntopic_prefix = /a\n", GS_EINVAL, "topic_prefix", "starts"},
        {"[sink.mqtt]\nhost = b\ndevice = a/b\n", GS_EINVAL, "device", "'/'"},
        {"[sink.mqtt]\nhost = b\ntls = yes\n", GS_EINVAL, "ca_file", "needs ca_file"},
        {"[sink.mqtt]\nhost = b\nca_file = x\n", GS_EINVAL, "tls", "tls is not yes"},
        {"[sink.mqtt]\nhost = b\ntls = yes\nca_file = x\ncert_file = c\n", GS_EINVAL, "key_file", "both"},
        {"[sink.mqtt]\nhost = b\npassword = p\n", GS_EINVAL, "username", "needs a username"},
        {"[sink.mqtt]\nhost = b\nusername = u\npassword = p\npassword_file = f\n", GS_EINVAL, "password_file", "both"},
        {"[sink.mqtt]\nhost = b\nbackoff_min_s = 5\nbackoff_max_s = 1\n", GS_ERANGE, "backoff_max_s", "below"},
        {"[sink.mqtt]\nhost = b\ncolour = red\n", GS_ENOKEY, "colour", ""},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        gs_sinks_config c;
        gs_sinks_config_default(&c);
        gs_cfg_section sec[GS_SINKS_CONFIG_SECTIONS];
        size_t n = gs_sinks_config_sections(&c, sec, GS_SINKS_CONFIG_SECTIONS);
        gs_cfg_error e;
        memset(&e, 0, sizeof e);
        gs_status st = gs_cfg_parse(bad[i].text, strlen(bad[i].text), sec, n, &e);
        if (st == GS_OK)
            st = gs_sinks_config_check(&c, &e);
        TEST_ASSERT_EQUAL_INT_MESSAGE(bad[i].st, st, bad[i].text);
        TEST_ASSERT_EQUAL_STRING_MESSAGE("sink.mqtt", e.section, bad[i].text);
        TEST_ASSERT_EQUAL_STRING_MESSAGE(bad[i].key, e.key, bad[i].text);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(e.msg, bad[i].frag), e.msg);
    }
    /* every key, accepted */
    const char *good = "[sink.mqtt]\nhost = broker.lan\nport = 8883\nclient_id = cam-7\ndevice = gym-2\n"
                       "topic_prefix = site/a\nqos = 2\nkeepalive_s = 15\ntls = yes\nca_file = /etc/ca.crt\n"
                       "cert_file = c.crt\nkey_file = c.key\ntls_insecure = no\nusername = u\npassword_file = /p\n"
                       "backoff_min_s = 0.1\nbackoff_max_s = 9\nqueue_lines = 64\n";
    gs_sinks_config c;
    gs_sinks_config_default(&c);
    gs_cfg_section sec[GS_SINKS_CONFIG_SECTIONS];
    size_t n = gs_sinks_config_sections(&c, sec, GS_SINKS_CONFIG_SECTIONS);
    gs_cfg_error e;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_cfg_parse(good, strlen(good), sec, n, &e));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_sinks_config_check(&c, &e));
    TEST_ASSERT_TRUE(gs_sinks_config_on(&c.mqtt_sw, false));
    TEST_ASSERT_EQUAL_STRING("site/a", c.mqtt.topic_prefix);
    TEST_ASSERT_EQUAL_UINT(2, c.mqtt.qos);
    TEST_ASSERT_EQUAL_UINT(64, c.mqtt.queue_lines);
    TEST_ASSERT_TRUE(c.mqtt.tls);
    /* a password file that cannot be read: an error at open naming it */
    gs_sink_mqtt_cfg m = base_cfg();
    snprintf(m.username, sizeof m.username, "u");
    snprintf(m.password_file, sizeof m.password_file, "%s/no-such-file", g_dir);
    gs_sink k;
    char err[256];
    TEST_ASSERT_EQUAL_INT(-1, gs_sink_mqtt_open(&k, &m, gs_sink_now_s(), err, sizeof err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err, "no-such-file"), err);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/gs_mqtt_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    g_port = free_port();
    UNITY_BEGIN();
    RUN_TEST(test_config);
    RUN_TEST(test_events_topics_qos_and_status);
    RUN_TEST(test_broker_restart_loses_nothing);
    RUN_TEST(test_full_queue_drops_oldest_whole);
    RUN_TEST(test_last_will_when_the_publisher_dies);
    RUN_TEST(test_tls);
    broker_stop();
    int rc = UNITY_END();
    char cmd[300];
    snprintf(cmd, sizeof cmd, "%srm -rf %s", rc ? ": " : "", g_dir);
    if (system(cmd) != 0)
        rc |= 1;
    return rc;
}

#else

static void broker_stop(void) {}

static void test_built_with_libmosquitto(void)
{
    TEST_FAIL_MESSAGE("built without libmosquitto: tools/bootstrap.sh installs libmosquitto-dev and mosquitto");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_built_with_libmosquitto);
    return UNITY_END();
}

#endif
