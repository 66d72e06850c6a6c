/* gs_profile.h - one profile file serves every program: `gravscale cam` reads
 * all of its sections, `replay` only [core], `video` [core] and [ball]. A
 * program skips the sections that belong to the others (their keys are checked
 * by the program that uses them) and still rejects a section nobody knows. */
#ifndef GS_PROFILE_H
#define GS_PROFILE_H

#include "gravscale/gs_config.h"

/* Every section a profile may hold: core, cam, ball, pose, sink.stdout,
 * sink.file, sink.serial, sink.tcp, sink.tcp_client, sink.udp, sink.mqtt,
 * status, kiosk. */
#define GS_PROFILE_SECTIONS 13

/* Fill out with skipping handlers for every profile section not named in
 * own[0..n_own); returns how many (0 if cap is too small). */
size_t gs_profile_foreign_sections(const char *const *own, size_t n_own, gs_cfg_section *out, size_t cap);

/* A handler that accepts any key (for a section another program reads). */
gs_status gs_profile_skip_key(void *ctx, const char *key, size_t key_len, const char *value,
                              size_t value_len, char *msg, size_t cap);

/* A profile is read whole; larger ones are refused. */
#define GS_PROFILE_MAX_BYTES (1u << 20)

/* The whole file at path in a new buffer (free it), its length in *n; NULL after
 * an error line "PROG: PATH: ..." on stderr (cannot open, cannot read, too large). */
char *gs_profile_read(const char *prog, const char *path, size_t *n);

/* "PROG: PATH:LINE: [section] key 'k': message" on stderr. */
void gs_profile_print_error(const char *prog, const char *path, const gs_cfg_error *e);

#endif
