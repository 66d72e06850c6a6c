/* app_common.c - option splitting and usage errors for the commands. */
#include "app_common.h"

#include <stdbool.h>
#include <stdio.h>
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
