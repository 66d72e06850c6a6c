/* gs_profile.c - the sections of a profile that a program leaves to others. */
#include "gs_profile.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const k_all[GS_PROFILE_SECTIONS] = {
    "core", "cam", "ball", "pose", "sink.stdout", "sink.file", "sink.serial",
    "sink.tcp", "sink.tcp_client", "sink.udp", "sink.mqtt", "status", "kiosk"};

gs_status gs_profile_skip_key(void *ctx, const char *key, size_t key_len, const char *value,
                              size_t value_len, char *msg, size_t cap)
{
    (void)ctx, (void)key, (void)key_len, (void)value, (void)value_len, (void)msg, (void)cap;
    return GS_OK;
}

size_t gs_profile_foreign_sections(const char *const *own, size_t n_own, gs_cfg_section *out, size_t cap)
{
    size_t n = 0;
    for (size_t i = 0; i < GS_PROFILE_SECTIONS; i++) {
        int mine = 0;
        for (size_t j = 0; j < n_own; j++)
            mine |= strcmp(own[j], k_all[i]) == 0;
        if (mine)
            continue;
        if (n == cap)
            return 0;
        out[n].name = k_all[i];
        out[n].fn = gs_profile_skip_key;
        out[n].ctx = NULL;
        n++;
    }
    return n;
}

char *gs_profile_read(const char *prog, const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "%s: %s: cannot open config: %s\n", prog, path, strerror(errno));
        return NULL;
    }
    char *text = malloc(GS_PROFILE_MAX_BYTES + 1); /* one byte more tells a file that is too large */
    *n = text ? fread(text, 1, GS_PROFILE_MAX_BYTES + 1, f) : 0;
    bool bad = !text || ferror(f);
    fclose(f);
    if (bad) {
        fprintf(stderr, "%s: %s: cannot read config\n", prog, path);
    } else if (*n > GS_PROFILE_MAX_BYTES) {
        fprintf(stderr, "%s: %s: config larger than %u bytes\n", prog, path, (unsigned)GS_PROFILE_MAX_BYTES);
        bad = true;
    }
    if (bad) {
        free(text);
        return NULL;
    }
    return text;
}

void gs_profile_print_error(const char *prog, const char *path, const gs_cfg_error *e)
{
    fprintf(stderr, "%s: %s:", prog, path);
    if (e->line > 0)
        fprintf(stderr, "%u:", (unsigned)e->line);
    if (e->section[0])
        fprintf(stderr, " [%s]", e->section);
    if (e->key[0])
        fprintf(stderr, " key '%s'", e->key);
    fprintf(stderr, "%s %s\n", (e->section[0] || e->key[0]) ? ":" : "",
            e->msg[0] ? e->msg : "invalid configuration");
}
