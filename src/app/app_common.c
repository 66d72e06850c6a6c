/* app_common.c - option splitting, usage errors and config files for the commands. */
#include "app_common.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int gs_app_usage_error(const char *cmd, const char *fmt, const char *arg)
{
    fprintf(stderr, "gravscale: %s: ", cmd);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (see gravscale %s --help)\n", cmd);
    return GS_EXIT_USAGE;
}

int gs_app_option(const char *cmd, int argc, char **argv, int *i, const char *const *known, size_t n_known,
                  char *name, size_t name_cap, const char **val)
{
    const char *a = argv[*i];
    const char *eq = strchr(a, '=');
    size_t nl = eq ? (size_t)(eq - a) : strlen(a);
    bool ok = nl < name_cap;
    if (ok) {
        memcpy(name, a, nl);
        name[nl] = '\0';
        ok = false;
        for (size_t k = 0; k < n_known; k++)
            ok = ok || strcmp(name, known[k]) == 0;
    }
    if (!ok) {
        /* the name alone when it fits (a value may be long), else the whole argument */
        return gs_app_usage_error(cmd, "unknown option '%s'", nl < name_cap ? name : a);
    }
    if (eq) {
        *val = eq + 1;
    } else if (*i + 1 >= argc) {
        return gs_app_usage_error(cmd, "option '%s' needs a value", name);
    } else {
        *val = argv[++*i];
    }
    return -1;
}

void gs_app_print_cfg_error(const char *path, const gs_cfg_error *e)
{
    fprintf(stderr, "gravscale: %s:", path);
    if (e->line > 0)
        fprintf(stderr, "%u:", (unsigned)e->line);
    if (e->section[0])
        fprintf(stderr, " [%s]", e->section);
    if (e->key[0])
        fprintf(stderr, " key '%s'", e->key);
    fprintf(stderr, "%s %s\n", (e->section[0] || e->key[0]) ? ":" : "",
            e->msg[0] ? e->msg : "invalid configuration");
}

char *gs_app_read_config(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "gravscale: %s: cannot open config: %s\n", path, strerror(errno));
        return NULL;
    }
    char *text = malloc(GS_APP_CONFIG_MAX_BYTES + 1); /* one byte more tells a file that is too large */
    *n = text ? fread(text, 1, GS_APP_CONFIG_MAX_BYTES + 1, f) : 0;
    bool bad = !text || ferror(f);
    fclose(f);
    if (bad) {
        fprintf(stderr, "gravscale: %s: cannot read config\n", path);
    } else if (*n > GS_APP_CONFIG_MAX_BYTES) {
        fprintf(stderr, "gravscale: %s: config larger than %u bytes\n", path, (unsigned)GS_APP_CONFIG_MAX_BYTES);
        bad = true;
    }
    if (bad) {
        free(text);
        return NULL;
    }
    return text;
}
