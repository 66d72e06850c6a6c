/* gs_profile.c - the sections of a profile that a program leaves to others. */
#include "gs_profile.h"

#include <string.h>

static const char *const k_all[GS_PROFILE_SECTIONS] = {
    "core", "cam", "ball", "pose", "sink.stdout", "sink.file", "sink.serial",
    "sink.tcp", "sink.tcp_client", "sink.udp", "status"};

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
