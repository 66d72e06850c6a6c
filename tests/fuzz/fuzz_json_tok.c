/* fuzz_json_tok.c - libFuzzer harness for the JSON pull tokenizer
 * (src/io/gs_json_tok.c) behind the AlphaPose and OpenPose readers: it accepts
 * exactly the texts an independent validator (fuzz_util.h) accepts, every token
 * lies inside the input, depth and line numbers stay consistent, errors are
 * sticky and always explained, and gs_jlex_skip lands after the value it skips.
 * Built by tests/fuzz/run.sh (clang), not by CMake. */
#include "gs_json_tok.h"
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* an exact-size heap copy lets ASan catch any read past the end */
    char *s = malloc(size ? size : 1);
    if (!s) return 0;
    if (size) memcpy(s, data, size);
    uint32_t lines = 1;
    for (size_t i = 0; i < size; i++) lines += s[i] == '\n';

    /* pass 1: the token stream */
    gs_jlex l;
    gs_jlex_init(&l, s, size);
    gs_jtok t;
    gs_jt k;
    size_t tokens = 0;
    uint32_t last_line = 1;
    int depth = 0;
    while ((k = gs_jlex_next(&l, &t)) != GS_JT_EOF && k != GS_JT_ERROR) {
        FZ_CHECK(++tokens <= size); /* every token consumes input */
        FZ_CHECK(t.s >= s && t.s + t.len <= s + size);
        FZ_CHECK(t.line >= last_line && t.line <= lines);
        last_line = t.line;
        if (k == GS_JT_OBJ || k == GS_JT_ARR) {
            FZ_CHECK(t.depth == (uint32_t)depth);
            depth++;
            FZ_CHECK(depth <= GS_JSON_MAX_DEPTH);
        } else if (k == GS_JT_OBJ_END || k == GS_JT_ARR_END) {
            depth--;
            FZ_CHECK(depth >= 0 && t.depth == (uint32_t)depth);
        } else {
            FZ_CHECK(t.depth == (uint32_t)depth);
        }
        if (k == GS_JT_NUM) {
            double d;
            /* grammar-valid numbers parse unless they overflow a double */
            if (!gs_jtok_num(&t, &d)) FZ_CHECK(t.len > 3);
            else FZ_CHECK(isfinite(d));
        }
        if (k == GS_JT_STR || k == GS_JT_KEY) FZ_CHECK(t.s > s && t.s[-1] == '"' && t.s[t.len] == '"');
    }
    bool ok = k == GS_JT_EOF;
    if (ok) FZ_CHECK(depth == 0 && tokens > 0);
    else FZ_CHECK(l.err[0] != '\0' && memchr(l.err, 0, sizeof l.err) && l.err_line >= 1 && l.err_line <= lines);
    /* sticky: the same answer again */
    gs_jtok t2;
    gs_jt k2 = gs_jlex_next(&l, &t2);
    FZ_CHECK(ok ? (k2 == GS_JT_EOF || k2 == GS_JT_ERROR) : k2 == GS_JT_ERROR);

    /* the oracle: same verdict as an independent grammar check (no UTF-8 demand: the tokenizer passes bytes) */
    bool ref = fz_json_valid(s, size, GS_JSON_MAX_DEPTH, false);
    if (ok != ref) {
        fprintf(stderr, "tokenizer %s, reference %s (%s at line %u)\n", ok ? "accepts" : "rejects",
                ref ? "accepts" : "rejects", l.err, (unsigned)l.err_line);
        abort();
    }

    /* pass 2: skip every top-level value's children; the next token must follow the skipped value */
    gs_jlex_init(&l, s, size);
    k = gs_jlex_next(&l, &t);
    if (k == GS_JT_OBJ || k == GS_JT_ARR) {
        gs_jtok c;
        gs_jt ck;
        size_t guard = 0;
        while ((ck = gs_jlex_next(&l, &c)) != GS_JT_ERROR && ck != GS_JT_EOF && ++guard <= size) {
            if (ck == GS_JT_OBJ || ck == GS_JT_ARR) {
                bool sk = gs_jlex_skip(&l, &c);
                if (sk) FZ_CHECK(l.p > c.s && l.p <= s + size && l.p[-1] == (ck == GS_JT_OBJ ? '}' : ']'));
                else break;
            }
        }
        if (ok) FZ_CHECK(ck == GS_JT_EOF);
    }
    free(s);
    return 0;
}
