/* app_common.h - what the gravscale commands (replay, video, cam) share: the
 * exit codes, option splitting and the usage error line (the config file:
 * gs_profile.h). */
#ifndef GS_APP_COMMON_H
#define GS_APP_COMMON_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Exit codes of every command (README): 1 is bad input data (cam: the source failed). */
enum { GS_EXIT_OK = 0, GS_EXIT_DATA = 1, GS_EXIT_USAGE = 2, GS_EXIT_IO = 3 };

/* "gravscale: CMD: <fmt with arg> (see gravscale CMD --help)" on stderr; returns GS_EXIT_USAGE. */
int gs_app_usage_error(const char *cmd, const char *fmt, const char *arg);

/* argv[*i] is "--name value" or "--name=value" with name one of known[0..n_known):
 * the name goes to name[0..name_cap), the value to *val (the next argument, *i
 * advanced, unless given with '='). Returns -1 to go on, else GS_EXIT_USAGE
 * after the usage error line (unknown option, missing value). */
int gs_app_option(const char *cmd, int argc, char **argv, int *i, const char *const *known, size_t n_known,
                  char *name, size_t name_cap, const char **val);

#ifdef __cplusplus
}
#endif

#endif
