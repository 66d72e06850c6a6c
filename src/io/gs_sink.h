/* gs_sink.h - where emitted lines go: stdout or a file, a serial port, a TCP
 * server, a TCP client, UDP. Every sink is a callback table plus its state
 * (nanopb style) and follows the same rules:
 *   - write_line never blocks: the line is sent now if the device takes it,
 *     else queued in a bounded queue of whole lines; full -> the oldest line
 *     is dropped and counted;
 *   - only whole lines reach a peer (a new connection or a reopened device
 *     starts at a line boundary);
 *   - no threads: the caller runs gs_sinkset_poll(set, now_s) once a frame,
 *     which sends queued lines, accepts clients, reconnects and reopens;
 *   - sockets are written with MSG_NOSIGNAL (SO_NOSIGPIPE where it exists);
 *     stdout to a closed pipe still raises SIGPIPE, so the program ignores it
 *     (gs_sink_ignore_sigpipe).
 * Creation may fail (a missing device, a port in use, a bad address) with one
 * message in err; after that, trouble is reported through the state and the
 * counters, never by stopping the pipeline. */
#ifndef GS_SINK_H
#define GS_SINK_H

#include "gs_lineq.h"
#include "gravscale/gs_emit.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum {
    GS_SINK_UP = 0,     /* open / connected / listening */
    GS_SINK_CONNECTING, /* TCP client: a connect is in progress */
    GS_SINK_RETRYING,   /* device gone or connection lost: waiting to reopen/reconnect */
    GS_SINK_FAILED      /* stopped for good (stdout/file write error); lines are dropped */
} gs_sink_state;

const char *gs_sink_state_name(gs_sink_state s);

typedef struct {
    uint64_t lines_in;      /* lines given to write_line */
    uint64_t lines_sent;    /* whole lines handed to the kernel (TCP server: summed over clients) */
    uint64_t lines_dropped; /* whole lines lost: queue full, too long, sink failed, a client's cut line */
    uint64_t bytes_sent;
    uint64_t lines_queued;  /* waiting now (TCP server: the largest client backlog) */
    uint32_t clients;       /* TCP server: connected clients */
    uint64_t reopens;       /* serial reopened / TCP client connections made / clients accepted */
    uint64_t refused;       /* TCP server: clients turned away because max_clients were connected */
} gs_sink_counters;

typedef struct {
    const char *kind;       /* "stdout", "file", "serial", "tcp", "tcp_client", "udp" */
    char target[160];       /* device path, address:port, file path */
    gs_sink_state state;
    int last_errno;         /* most recent error, 0 none */
    gs_sink_counters c;
} gs_sink_info;

typedef struct {
    void *state;
    /* line[0..len) is one whole line ending in '\n'. 0 taken (sent or queued), -1 dropped. */
    int (*write_line)(void *state, const char *line, size_t len);
    /* Send what is queued, accept, reconnect, reopen; now_s is any monotonic clock in seconds. */
    void (*poll)(void *state, double now_s);
    void (*info)(const void *state, gs_sink_info *out);
    /* Close descriptors and free the state. */
    void (*close)(void *state);
    /* Takes JSON event lines only (MQTT: one JSON message per event); a daemon
     * writing NMEA gives such sinks the JSON form (gs_sinkset_write_pair). */
    bool json_only;
} gs_sink;

/* ------------------------------------------------------------- sink configs */

/* stdout or an already open descriptor (not owned), or a file created/truncated. */
/* For a sink with one queue and one reader (serial, TCP client): its intake,
 * sent, dropped (evicted, refused) and queued lines and its bytes. */
void gs_sink_counters_fill(gs_sink_counters *c, const gs_lineq *q, const gs_lineq_reader *r);

int gs_sink_fd_open(gs_sink *s, int fd, const char *name, char *err, size_t cap);
int gs_sink_file_open(gs_sink *s, const char *path, char *err, size_t cap);

typedef struct {
    char device[128];       /* tty path */
    uint32_t baud;          /* 9600 19200 38400 57600 115200 230400 460800 921600 */
    double reopen_s;        /* retry interval after the device went away */
    uint32_t queue_lines;
} gs_sink_serial_cfg;

/* true when baud is one of the supported rates */
bool gs_sink_serial_baud_ok(uint32_t baud);
int gs_sink_serial_open(gs_sink *s, const gs_sink_serial_cfg *cfg, double now_s, char *err, size_t cap);

typedef struct {
    char bind[64];          /* numeric address; default 127.0.0.1 */
    bool allow_remote;      /* a non-loopback bind is refused unless this is set (the config sets it
                               only when `bind` is written out) */
    uint16_t port;          /* 0: the system picks one (see gs_sink_tcp_port) */
    uint32_t max_clients;
    uint32_t queue_lines;   /* per client backlog bound */
    uint32_t sndbuf_bytes;  /* 0: the system default */
} gs_sink_tcp_cfg;

int gs_sink_tcp_open(gs_sink *s, const gs_sink_tcp_cfg *cfg, char *err, size_t cap);
/* The port a TCP server sink listens on (after port = 0), 0 if s is not one. */
uint16_t gs_sink_tcp_port(const gs_sink *s);

typedef struct {
    char host[128];         /* name or address, resolved once at open */
    uint16_t port;
    double backoff_min_s, backoff_max_s; /* reconnect delay: doubles from min up to max */
    uint32_t queue_lines;
} gs_sink_tcp_client_cfg;

int gs_sink_tcp_client_open(gs_sink *s, const gs_sink_tcp_client_cfg *cfg, double now_s, char *err,
                            size_t cap);

typedef struct {
    char host[128];
    uint16_t port;
} gs_sink_udp_cfg;

int gs_sink_udp_open(gs_sink *s, const gs_sink_udp_cfg *cfg, char *err, size_t cap);

/* MQTT (libmosquitto; docs/sinks.md): every JSON event line becomes one message on
 * <topic_prefix>/<device>/<event> (the daemon's status lines on .../status/daemon),
 * jump and summary at QoS >= 1; a retained <topic_prefix>/<device>/status is
 * "online" after each connect and "offline" by the broker's last will or at close. */
typedef struct {
    char host[128];
    uint16_t port;              /* 1883 (8883 with TLS) when 0 */
    char client_id[128];        /* "gravscale-<device>" when empty */
    char device[64];            /* the host name when empty */
    char topic_prefix[128];
    uint8_t qos;                /* 0..2 for every event; jump and summary at least 1 */
    uint32_t keepalive_s;
    bool tls, tls_insecure;     /* tls_insecure: no check of the server's host name */
    char ca_file[256], ca_path[256], cert_file[256], key_file[256];
    char username[128], password[128], password_file[256];
    double backoff_min_s, backoff_max_s;
    uint32_t queue_lines;       /* lines kept while disconnected; full: the oldest go */
} gs_sink_mqtt_cfg;

/* false when this build has no libmosquitto (the sink then fails to open) */
bool gs_sink_mqtt_available(void);
int gs_sink_mqtt_open(gs_sink *s, const gs_sink_mqtt_cfg *cfg, double now_s, char *err, size_t cap);

/* ------------------------------------------------------------------ fan-out */

#define GS_SINKSET_MAX 8

typedef struct {
    gs_sink sinks[GS_SINKSET_MAX];
    size_t n;
} gs_sinkset;

void gs_sinkset_init(gs_sinkset *set);
/* Take ownership of an opened sink. 0, or -1 when the set is full (the sink is closed). */
int gs_sinkset_add(gs_sinkset *set, const gs_sink *s);
/* The same bytes to every sink; returns how many sinks dropped the line. */
size_t gs_sinkset_write(gs_sinkset *set, const char *line, size_t len);
/* line to every sink but those that take JSON only, which get json (line when
 * json is NULL); returns how many sinks dropped it. */
size_t gs_sinkset_write_pair(gs_sinkset *set, const char *line, size_t len, const char *json, size_t json_len);
/* Does any sink of the set take JSON only? */
bool gs_sinkset_wants_json(const gs_sinkset *set);
/* Emit an event in fmt and write it (events without a form in fmt are skipped). */
size_t gs_sinkset_write_event(gs_sinkset *set, gs_format fmt, const gs_event *ev);
void gs_sinkset_poll(gs_sinkset *set, double now_s);
/* Lines still queued over all sinks. */
uint64_t gs_sinkset_pending(const gs_sinkset *set);
/* At shutdown: poll until nothing is queued or timeout_s passed, waiting a few
 * ms between rounds. It polls with gs_sink_now_s(): a caller that drains
 * should give every poll that clock. Returns the lines still queued. */
uint64_t gs_sinkset_drain(gs_sinkset *set, double timeout_s);
/* The sinks as a JSON array `[{"sink":"serial","target":..,"state":..,...},...]`
 * for a status line. Returns the length, 0 if cap is too small (buf ""). */
size_t gs_sinkset_status_json(const gs_sinkset *set, char *buf, size_t cap);
void gs_sinkset_close(gs_sinkset *set);

/* One line of text for a person: "serial /dev/ttyUSB0@115200 retrying (Input/output
 * error): 40 sent, 0 dropped, 2 queued, 16212 bytes". Length, 0 if cap is too small. */
size_t gs_sink_status_text(const gs_sink *s, char *buf, size_t cap);

/* Ignore SIGPIPE for the whole process (a daemon writing to pipes must). 0 or -1. */
int gs_sink_ignore_sigpipe(void);

/* Seconds of CLOCK_MONOTONIC, for now_s. */
double gs_sink_now_s(void);

#endif
