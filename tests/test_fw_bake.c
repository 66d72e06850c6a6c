/* test_fw_bake.c - tools/fw/fw_bake.c bakes a firmware profile into fw_profile.h
 * (built from tests/data/fw_bake_all.cfg, every [core] key away from its
 * default): the baked gs_core_config is field for field what the core's parser
 * gives for the file, its FW_PROFILE_TEXT parses back to the same, and a bad
 * profile gives one error line, exit 1 and no header. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "fw_profile.h"
#include "gravscale/gravscale.h"
#include "gs_profile.h"
#include "unity.h"

#ifndef FW_BAKE_PROGRAM
#error "FW_BAKE_PROGRAM: the fw_bake host program (CMake sets it)"
#endif

void setUp(void) {}
void tearDown(void) {}

typedef struct {
    const char *name;
    size_t off, size, align;
} field;

#define F(n) {#n, offsetof(gs_core_config, n), sizeof(((gs_core_config *)0)->n), _Alignof(__typeof__(((gs_core_config *)0)->n))}
/* every field of gs_core_config in order; test_field_list_is_whole fails when one is added */
static const field k_fields[] = {
    F(g_m_s2), F(latitude_deg), F(altitude_m), F(mass_table), F(stature), F(min_conf), F(fit_method),
    F(ring_capacity), F(min_flight_s), F(max_flight_s), F(min_samples), F(max_rms_rel), F(max_a_se_rel),
    F(size_min_m), F(size_max_m), F(max_gap_s), F(landing_latency_s), F(session_absence_s),
    F(session_new_body_rel), F(format),
};
#define N_FIELDS (sizeof k_fields / sizeof k_fields[0])

static const gs_core_config k_baked = FW_PROFILE_CONFIG;

/* parse text with [core] and the other programs' sections skipped */
static gs_status parse(const char *text, size_t len, gs_core_config *c, gs_cfg_error *e)
{
    gs_core_config_default(c);
    gs_cfg_section sec[1 + GS_PROFILE_SECTIONS] = {{"core", gs_core_config_set, c}};
    static const char *const own[] = {"core"};
    size_t n = 1 + gs_profile_foreign_sections(own, 1, sec + 1, GS_PROFILE_SECTIONS);
    memset(e, 0, sizeof *e);
    return gs_cfg_parse(text, len, sec, n, e);
}

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    static char buf[1 << 16];
    *n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    return buf;
}

static void assert_same_fields(const gs_core_config *a, const gs_core_config *b)
{
    for (size_t i = 0; i < N_FIELDS; i++)
        TEST_ASSERT_EQUAL_MEMORY_MESSAGE((const char *)a + k_fields[i].off, (const char *)b + k_fields[i].off,
                                         k_fields[i].size, k_fields[i].name);
}

/* the list covers the struct: no gap a field would fit in, nothing after the last */
static void test_field_list_is_whole(void)
{
    size_t end = 0;
    for (size_t i = 0; i < N_FIELDS; i++) {
        TEST_ASSERT_TRUE_MESSAGE(k_fields[i].off >= end, k_fields[i].name);
        TEST_ASSERT_TRUE_MESSAGE(k_fields[i].off - end < k_fields[i].align, k_fields[i].name);
        end = k_fields[i].off + k_fields[i].size;
    }
    TEST_ASSERT_TRUE(sizeof(gs_core_config) - end < _Alignof(gs_core_config));
}

static void test_baked_is_the_parse_of_the_file(void)
{
    size_t n;
    char *text = slurp(GS_SOURCE_DIR "/tests/data/fw_bake_all.cfg", &n);
    gs_core_config parsed;
    gs_cfg_error e;
    TEST_ASSERT_EQUAL_INT(GS_OK, parse(text, n, &parsed, &e));
    assert_same_fields(&k_baked, &parsed);
    /* and every field is away from its default: the profile exercises each one */
    gs_core_config def;
    gs_core_config_default(&def);
    for (size_t i = 0; i < N_FIELDS; i++)
        TEST_ASSERT_TRUE_MESSAGE(memcmp((const char *)&k_baked + k_fields[i].off, (const char *)&def + k_fields[i].off,
                                        k_fields[i].size) != 0,
                                 k_fields[i].name);
    TEST_ASSERT_EQUAL_STRING("fw_bake_all.cfg", FW_PROFILE_NAME);
}

static void test_text_parses_back_to_the_same(void)
{
    static const char text[] = FW_PROFILE_TEXT;
    gs_core_config back;
    gs_cfg_error e;
    TEST_ASSERT_EQUAL_INT(GS_OK, parse(text, sizeof text - 1u, &back, &e));
    assert_same_fields(&k_baked, &back);
    TEST_ASSERT_NULL(strstr(text, "[cam]"));  /* only the core's section rides along */
}

/* run fw_bake; its exit status */
static int bake(const char *profile, const char *out, const char *err_path)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "'%s' '%s' '%s' 2>'%s'", FW_BAKE_PROGRAM, profile, out, err_path);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fputs(text, f);
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

static void test_bad_profiles_write_nothing(void)
{
    char dir[] = "/tmp/gs_fw_bake_XXXXXX";
    TEST_ASSERT_NOT_NULL(mkdtemp(dir));
    char cfg[256], out[256], err[256];
    snprintf(cfg, sizeof cfg, "%s/p.cfg", dir);
    snprintf(out, sizeof out, "%s/fw_profile.h", dir);
    snprintf(err, sizeof err, "%s/err", dir);
    static const struct {
        const char *text, *want;
    } k_bad[] = {
        {"[core]\nmin_flight_s = 3\n", ":2: [core] key 'min_flight_s': must be within"},
        {"[core]\nbogus = 1\n", ":2: [core] key 'bogus': unknown key"},
        {"[core]\nmin_flight_s = 0.9\nmax_flight_s = 0.5\n", "[core] key 'max_flight_s'"},
        {"[nosuch]\n", ":1: [nosuch]"},
    };
    for (size_t i = 0; i < sizeof k_bad / sizeof k_bad[0]; i++) {
        write_file(cfg, k_bad[i].text);
        TEST_ASSERT_EQUAL_INT_MESSAGE(1, bake(cfg, out, err), k_bad[i].text);
        size_t n;
        char *msg = slurp(err, &n);
        msg[n < 65535 ? n : 65535] = '\0';
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(msg, k_bad[i].want), msg);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(msg, "fw_bake: "), msg);
        TEST_ASSERT_NULL_MESSAGE(fopen(out, "rb"), "no header after a bad profile");
    }
    /* a good one is written whole; a missing profile is an I/O error (2) */
    write_file(cfg, "[core]\nfit = plain\n");
    TEST_ASSERT_EQUAL_INT(0, bake(cfg, out, err));
    FILE *h = fopen(out, "rb");
    TEST_ASSERT_NOT_NULL(h);
    fclose(h);
    snprintf(cfg, sizeof cfg, "%s/missing.cfg", dir);
    TEST_ASSERT_EQUAL_INT(2, bake(cfg, out, err));
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    TEST_ASSERT_EQUAL_INT(0, system(cmd));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_field_list_is_whole);
    RUN_TEST(test_baked_is_the_parse_of_the_file);
    RUN_TEST(test_text_parses_back_to_the_same);
    RUN_TEST(test_bad_profiles_write_nothing);
    return UNITY_END();
}
