/* fuzz_openpose.c - libFuzzer harness for the OpenPose folder reader
 * (src/io/gs_kp_openpose.c) and the core behind it. Input: a selector byte
 * (--fps, --track, core fit), then up to 6 files separated by NUL bytes; a file
 * starting with "#stem\n" is named stem_keypoints.json (stem cut to [A-Za-z0-9_]),
 * else <index>_keypoints.json. Same properties as fuzz_alphapose.c.
 * Built by tests/fuzz/run.sh (clang), not by CMake. */
#include "fuzz_kpread.h"

#include <dirent.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define MAX_FILES 6

static char g_dir[256];

static void clear_dir(void)
{
    DIR *d = opendir(g_dir);
    if (!d) return;
    struct dirent *e;
    char p[600];
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') continue;
        snprintf(p, sizeof p, "%s/%s", g_dir, e->d_name);
        unlink(p);
    }
    closedir(d);
}

static void put_file(const char *name, const uint8_t *s, size_t n)
{
    char p[600];
    snprintf(p, sizeof p, "%s/%s", g_dir, name);
    FILE *f = fopen(p, "wb");
    if (!f) {
        perror(p);
        abort();
    }
    if (n) fwrite(s, 1, n, f);
    fclose(f);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    if (!g_dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(g_dir, sizeof g_dir, "%s/gs_fuzz_op_%ld", t && t[0] ? t : "/tmp", (long)getpid());
        mkdir(g_dir, 0700);
    }
    clear_dir();
    uint8_t sel = data[0];
    static const double fps_tab[] = {30.0, 25.0, 1e-3, 1e6};
    gs_kpread_opts o;
    gs_kpread_opts_default(&o);
    o.format = GS_KPF_OPENPOSE;
    o.fps = fps_tab[sel & 3u];
    o.track = (sel >> 2) & 1u ? (long)((sel >> 3) & 3u) : -1;

    const uint8_t *p = data + 1, *e = data + size;
    for (int i = 0; i < MAX_FILES && p <= e; i++) {
        const uint8_t *z = memchr(p, 0, (size_t)(e - p));
        const uint8_t *fe = z ? z : e;
        char name[64];
        const uint8_t *body = p;
        if (fe - p > 1 && p[0] == '#') {
            const uint8_t *nl = memchr(p, '\n', (size_t)(fe - p));
            size_t w = 0;
            for (const uint8_t *q = p + 1; nl && q < nl && w < 40; q++)
                if ((*q >= 'A' && *q <= 'Z') || (*q >= 'a' && *q <= 'z') || (*q >= '0' && *q <= '9') || *q == '_')
                    name[w++] = (char)*q;
            name[w] = '\0';
            if (nl) body = nl + 1;
            snprintf(name + w, sizeof name - w, "_keypoints.json");
        } else {
            snprintf(name, sizeof name, "%06d_keypoints.json", i);
        }
        put_file(name, body, (size_t)(fe - body));
        if (!z) break;
        p = z + 1;
    }

    return fz_json_reader_run(g_dir, &o, (uint8_t)(sel >> 5), true);
}
