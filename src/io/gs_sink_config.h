/* gs_sink_config.h - the [sink.*] and [status] sections of a profile, parsed by
 * the core's gs_cfg_parse through handlers that live here at the edge, and the
 * sink set opened from them. A sink section turns its sink on as soon as it has
 * a key (`enabled = no` turns it off again); [sink.stdout] is on by default. */
#ifndef GS_SINK_CONFIG_H
#define GS_SINK_CONFIG_H

#include "gs_sink.h"
#include "gravscale/gs_config.h"

typedef struct {
    bool present;           /* some key of the section was given */
    int enabled;            /* -1 not written, 0 no, 1 yes */
} gs_sink_switch;

typedef struct {
    gs_sink_switch stdout_sw;
    gs_sink_switch file_sw;
    char file_path[128];
    gs_sink_switch serial_sw;
    gs_sink_serial_cfg serial;
    gs_sink_switch tcp_sw;
    gs_sink_tcp_cfg tcp;
    gs_sink_switch tcp_client_sw;
    gs_sink_tcp_client_cfg tcp_client;
    gs_sink_switch udp_sw;
    gs_sink_udp_cfg udp;
    gs_sink_switch mqtt_sw;
    gs_sink_mqtt_cfg mqtt;
    double status_interval_s; /* [status] interval_s; 0 = no status lines */
} gs_sinks_config;

void gs_sinks_config_default(gs_sinks_config *c);

/* Fill out[0..) with the sections sink.stdout, sink.file, sink.serial, sink.tcp,
 * sink.tcp_client, sink.udp, sink.mqtt and status bound to c; returns how many
 * (8), 0 if cap is smaller. Append them to the caller's table for gs_cfg_parse. */
#define GS_SINKS_CONFIG_SECTIONS 8
size_t gs_sinks_config_sections(gs_sinks_config *c, gs_cfg_section *out, size_t cap);

/* After parsing: every enabled sink has what it needs (a device, a host and a
 * port), backoff_min_s <= backoff_max_s, MQTT's TLS and credential keys go
 * together. Line 0, section and key named. */
gs_status gs_sinks_config_check(const gs_sinks_config *c, gs_cfg_error *err);

/* Is each sink on after parsing? */
bool gs_sinks_config_on(const gs_sink_switch *sw, bool default_on);

/* Open every enabled sink into set (stdout: STDOUT_FILENO). On the first
 * failure the sinks opened so far are closed and err holds one line naming the
 * sink and the reason (a missing device, a port in use). 0 or -1. */
int gs_sinkset_open_config(gs_sinkset *set, const gs_sinks_config *c, double now_s, char *err, size_t cap);

#endif
