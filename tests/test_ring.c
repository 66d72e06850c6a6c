/* test_ring.c - gs_ring: init validation, wrap of slots and of the absolute
 * index (also across the 2^32 boundary), eviction of the oldest, NULL for
 * evicted/future indices, and canary slots around the caller's storage. */
#include <math.h>
#include <string.h>

#include "unity.h"
#include "gravscale/gs_ring.h"

/* Compile-time check of the storage helper: a bad capacity would not build. */
GS_RING_STORAGE(g_static_store, 16);

#define CAP 16u
#define CANARY_BYTE 0xA5

static gs_sample g_mem[CAP + 2];  /* [0] and [CAP+1] are canaries */
static gs_ring g_r;

void setUp(void)
{
    memset(g_mem, CANARY_BYTE, sizeof g_mem);
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&g_r, &g_mem[1], CAP));
}

void tearDown(void) {}

/* A sample that encodes its absolute index so a wrong slot is detected. */
static gs_sample_full mk(uint64_t i)
{
    gs_sample_full s;
    s.t_us = (int64_t)i;  /* one microsecond apart: the index is the time */
    s.x_px = (float)(i % 65536u);
    s.y_px = (float)((i * 7u) % 65536u);
    s.w = 1.0f;
    s.size_px = NAN;
    s.up_x = 0.0f;
    s.up_y = -1.0f;
    s.upright = 1.0f;
    return s;
}

static void assert_canaries(void)
{
    const unsigned char *a = (const unsigned char *)&g_mem[0];
    const unsigned char *b = (const unsigned char *)&g_mem[CAP + 1];
    for (size_t k = 0; k < sizeof(gs_sample); k++) {
        TEST_ASSERT_EQUAL_HEX8(CANARY_BYTE, a[k]);
        TEST_ASSERT_EQUAL_HEX8(CANARY_BYTE, b[k]);
    }
}

/* Every index in [oldest, head) resolves to its own sample, the rest to NULL. */
static void assert_window(uint64_t oldest, uint64_t head)
{
    TEST_ASSERT_TRUE(gs_ring_head(&g_r) == head);
    TEST_ASSERT_TRUE(gs_ring_oldest(&g_r) == oldest);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(head - oldest), gs_ring_count(&g_r));
    for (uint64_t i = oldest; i < head; i++) {
        gs_sample_full s;
        TEST_ASSERT_NOT_NULL(gs_ring_at(&g_r, i));
        TEST_ASSERT_TRUE(gs_ring_get(&g_r, i, &s));
        TEST_ASSERT_TRUE(s.t_us == (int64_t)i);
        TEST_ASSERT_EQUAL_FLOAT((float)(i % 65536u), s.x_px);
    }
    TEST_ASSERT_NULL(gs_ring_at(&g_r, head));
    TEST_ASSERT_NULL(gs_ring_at(&g_r, head + 1u));
    TEST_ASSERT_NULL(gs_ring_at(&g_r, UINT64_MAX));
    if (oldest > 0) {
        TEST_ASSERT_NULL(gs_ring_at(&g_r, oldest - 1u));
        TEST_ASSERT_NULL(gs_ring_at(&g_r, 0));
    }
}

static void test_init_rejects_bad_args(void)
{
    static const struct { uint32_t cap; gs_status want; } rows[] = {
        {0u, GS_EINVAL}, {1u, GS_EINVAL}, {2u, GS_EINVAL}, {4u, GS_EINVAL},
        {7u, GS_EINVAL}, {8u, GS_OK}, {12u, GS_EINVAL}, {15u, GS_EINVAL},
        {16u, GS_OK}, {24u, GS_EINVAL}, {1000u, GS_EINVAL}, {1024u, GS_OK},
        {0x80000000u, GS_OK}, {0x80000001u, GS_EINVAL}, {0xFFFFFFFFu, GS_EINVAL},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        gs_ring r;
        /* Init never touches storage, so a small buffer is fine for any capacity. */
        TEST_ASSERT_EQUAL_INT_MESSAGE(rows[k].want, gs_ring_init(&r, &g_mem[1], rows[k].cap), "capacity row");
    }
    gs_ring r;
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_init(NULL, &g_mem[1], 16));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_init(&r, NULL, 16));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, g_static_store, 16));
    assert_canaries();
}

static void test_empty_ring(void)
{
    assert_window(0, 0);
    TEST_ASSERT_NULL(gs_ring_at(&g_r, 0));
    TEST_ASSERT_NULL(gs_ring_at(NULL, 0));
    TEST_ASSERT_EQUAL_UINT32(0, gs_ring_count(NULL));
    gs_ring_push(NULL, NULL);
    gs_ring_push(&g_r, NULL);  /* ignored */
    assert_window(0, 0);
}

static void test_fill_and_overwrite_oldest(void)
{
    for (uint64_t i = 0; i < 3u * CAP + 5u; i++) {
        gs_sample_full s = mk(i);
        gs_ring_push(&g_r, &s);
        uint64_t head = i + 1u;
        uint64_t oldest = head > CAP ? head - CAP : 0u;
        assert_window(oldest, head);
        assert_canaries();
    }
}

/* Start the absolute index just below a boundary and push across it. */
static void run_across(uint64_t start)
{
    setUp();
    g_r.head = start;
    /* Refill every slot so the held window contains only real samples. */
    for (uint64_t i = start; i < start + CAP; i++) {
        gs_sample_full s = mk(i);
        gs_ring_push(&g_r, &s);
    }
    for (uint64_t i = start + CAP; i < start + 3u * CAP + 3u; i++) {
        gs_sample_full s = mk(i);
        gs_ring_push(&g_r, &s);
        assert_window(i + 1u - CAP, i + 1u);
        assert_canaries();
    }
}

static void test_wrap_near_uint32_boundary(void)
{
    run_across(0xFFFFFFFFull - 20u);
    run_across(0xFFFFFFFFull - CAP);
    run_across(0x100000000ull - 1u);
    TEST_ASSERT_TRUE(gs_ring_head(&g_r) > 0xFFFFFFFFull);
}

static void test_wrap_near_uint64_large_index(void)
{
    /* Far beyond 32 bits: the slot is index & mask, the index stays exact. */
    run_across(0x0000123456789ABCull);
    run_across((1ull << 52) - 7u);
}

static void test_at_returns_null_for_evicted_and_future(void)
{
    for (uint64_t i = 0; i < CAP + 4u; i++) {
        gs_sample_full s = mk(i);
        gs_ring_push(&g_r, &s);
    }
    TEST_ASSERT_NULL(gs_ring_at(&g_r, 0));
    TEST_ASSERT_NULL(gs_ring_at(&g_r, 3));
    TEST_ASSERT_NOT_NULL(gs_ring_at(&g_r, 4));
    TEST_ASSERT_NOT_NULL(gs_ring_at(&g_r, CAP + 3u));
    TEST_ASSERT_NULL(gs_ring_at(&g_r, CAP + 4u));
    /* The evicted index 3 and the held index 3+CAP share a slot: only the held one resolves. */
    TEST_ASSERT_TRUE(gs_ring_sample_t_us(&g_r, gs_ring_at(&g_r, CAP + 3u)) == (int64_t)(CAP + 3u));
}

static void test_push_copies_sample(void)
{
    gs_sample_full s = mk(42);
    gs_ring_push(&g_r, &s);
    s.t_us = -1;  /* the caller's copy changes, the ring's does not */
    gs_sample_full g;
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, 0, &g));
    TEST_ASSERT_TRUE(g.t_us == 42);
    TEST_ASSERT_TRUE(isnan(g.size_px));
    TEST_ASSERT_FALSE(gs_ring_get(&g_r, 1, &g));
}

/* gs_ring_store (the pipeline's, after its own checks) stores as gs_ring_push does: the same
 * slots, window and eviction by time span, byte for byte. */
static void test_store_is_push_unchecked(void)
{
    static gs_sample mem[CAP];
    memset(mem, CANARY_BYTE, sizeof mem);  /* as g_mem: unwritten slots compare equal */
    gs_ring r;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, mem, CAP));
    static const int64_t t_us[] = {5, 9, 9, 400, GS_RING_SPAN_US - 3, GS_RING_SPAN_US + 7, 3 * GS_RING_SPAN_US,
                                   3 * GS_RING_SPAN_US + 1};
    for (size_t k = 0; k < sizeof t_us / sizeof t_us[0]; k++) {
        gs_sample_full s = mk(k);
        s.t_us = t_us[k];
        s.size_px = 100.0f + (float)k;
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&g_r, &s));
        gs_ring_store(&r, &s);
        TEST_ASSERT_TRUE(gs_ring_head(&r) == gs_ring_head(&g_r) && gs_ring_oldest(&r) == gs_ring_oldest(&g_r));
        TEST_ASSERT_TRUE(r.t_last_us == g_r.t_last_us);
        TEST_ASSERT_EQUAL_MEMORY(&g_mem[1], mem, sizeof mem);
    }
    TEST_ASSERT_TRUE(gs_ring_count(&r) < 8u);  /* the span evicted some */
}

/* ---- the packed 16-byte form ------------------------------------------------------------ */

static gs_sample_full roundtrip(float size_px, float w, float upright)
{
    gs_sample_full s = mk(gs_ring_head(&g_r)), out;
    s.t_us = (int64_t)gs_ring_head(&g_r);
    s.size_px = size_px;
    s.w = w;
    s.upright = upright;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&g_r, &s));
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, gs_ring_head(&g_r) - 1u, &out));
    TEST_ASSERT_TRUE(out.x_px == s.x_px && out.y_px == s.y_px);  /* x, y stay floats */
    return out;
}

static void test_sample_layout_and_precision(void)
{
    TEST_ASSERT_EQUAL_UINT32(16, (uint32_t)sizeof(gs_sample));
    /* size: 1/16 px steps below 2048 px, 1/4 px to 10240 px, beyond or invalid unknown */
    static const float sizes[] = {0.0f, 0.03f, 7.19f, 12.3f, 549.86f, 1234.5678f, 2047.96f, 2047.99f,
                                  2048.0f, 2100.1f, 3000.3f, 8191.0f, 10239.0f};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        float tol = sizes[k] < 2047.97f ? 1.0f / 32.0f : 1.0f / 8.0f;
        gs_sample_full o = roundtrip(sizes[k], 1.0f, 1.0f);
        TEST_ASSERT_FLOAT_WITHIN(tol + 1e-4f, sizes[k], o.size_px);
    }
    TEST_ASSERT_TRUE(isnan(roundtrip(NAN, 1.0f, 1.0f).size_px));
    TEST_ASSERT_TRUE(isnan(roundtrip(-2.0f, 1.0f, 1.0f).size_px));
    TEST_ASSERT_TRUE(isnan(roundtrip(10300.0f, 1.0f, 1.0f).size_px));
    TEST_ASSERT_TRUE(isnan(roundtrip(INFINITY, 1.0f, 1.0f).size_px));
    /* w in 1/255: 0 stays 0 (unusable), a positive w never becomes 0, 1 stays exactly 1 */
    TEST_ASSERT_EQUAL_FLOAT(0.0f, roundtrip(1.0f, 0.0f, 1.0f).w);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, roundtrip(1.0f, NAN, 1.0f).w);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, roundtrip(1.0f, -0.5f, 1.0f).w);
    TEST_ASSERT_TRUE(roundtrip(1.0f, 1e-6f, 1.0f).w > 0.0f);
    TEST_ASSERT_TRUE(roundtrip(1.0f, 1.0f, 1.0f).w == 1.0f);
    TEST_ASSERT_TRUE(roundtrip(1.0f, 3.0f, 1.0f).w == 1.0f);
    for (int k = 2; k < 1000; k++) {  /* from 1/510 up; below it rounds up to 1/255 */
        float w = (float)k / 1000.0f;
        TEST_ASSERT_FLOAT_WITHIN(0.5f / 255.0f + 1e-6f, w, roundtrip(1.0f, w, 1.0f).w);
    }
    /* upright in 1/250, floored: the tenths the flight compares with decide as before */
    TEST_ASSERT_TRUE(isnan(roundtrip(1.0f, 1.0f, NAN).upright));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, roundtrip(1.0f, 1.0f, -1.0f).upright);
    TEST_ASSERT_EQUAL_FLOAT(1.0f, roundtrip(1.0f, 1.0f, 2.0f).upright);
    for (int k = 0; k <= 1000; k++) {
        float u = (float)k / 1000.0f;
        float o = roundtrip(1.0f, 1.0f, u).upright;
        TEST_ASSERT_TRUE(o <= u && u - o < 1.0f / 250.0f + 1e-6f);
        TEST_ASSERT_EQUAL_INT(u >= 0.5f, o >= 0.5f);
        TEST_ASSERT_EQUAL_INT(u >= 0.7f, o >= 0.7f);
    }
}

/* The body axis is kept for the newest sample only (it is consumed then). */
static void test_body_axis_newest_only(void)
{
    gs_sample_full s = mk(0), o;
    s.up_x = 0.6f;
    s.up_y = -0.8f;
    gs_ring_push(&g_r, &s);
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, 0, &o));
    TEST_ASSERT_EQUAL_FLOAT(0.6f, o.up_x);
    TEST_ASSERT_EQUAL_FLOAT(-0.8f, o.up_y);
    s = mk(1);
    gs_ring_push(&g_r, &s);
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, 0, &o));
    TEST_ASSERT_TRUE(isnan(o.up_x) && isnan(o.up_y));
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, 1, &o));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, o.up_x);
    TEST_ASSERT_EQUAL_FLOAT(-1.0f, o.up_y);
}

/* ---- time: microseconds modulo 2^32 around the newest sample ------------------------------ */

static void push_t(int64_t t_us)
{
    gs_sample_full s = mk(gs_ring_head(&g_r));
    s.t_us = t_us;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&g_r, &s));
}

/* Every held sample reads back its own time, exactly. */
static void assert_times(const int64_t *t, uint64_t n_pushed)
{
    for (uint64_t i = gs_ring_oldest(&g_r); i < gs_ring_head(&g_r); i++) {
        gs_sample_full o;
        TEST_ASSERT_TRUE(gs_ring_get(&g_r, i, &o));
        TEST_ASSERT_TRUE(o.t_us == t[i % n_pushed]);
        TEST_ASSERT_TRUE(gs_ring_sample_t_us(&g_r, gs_ring_at(&g_r, i)) == t[i % n_pushed]);
    }
}

#define S_US INT64_C(1000000)
#define MIN_US (60 * S_US)

/* A daemon runs for hours: the 32-bit microsecond field wraps every 71.6 min. Start
 * just before the wrap (as ring tests of RTOS kernels do) and cross it three times. */
static void test_time_wraps_every_71_minutes(void)
{
    static int64_t t[CAP];
    const int64_t base = 100000 * S_US + 123456;  /* a boot clock far from zero */
    const int64_t wrap_us = INT64_C(1) << 32;
    push_t(base);
    t[0] = base;
    /* minute steps up to just before the first wrap: the ring spans 16 min */
    uint64_t n = 1;
    for (int64_t u = MIN_US; u < wrap_us - S_US / 2; u += MIN_US, n++) {
        t[n % CAP] = base + u;
        push_t(base + u);
    }
    for (int lap = 0; lap < 3; lap++) {
        int64_t w0 = base + wrap_us * (lap + 1);
        /* 1 ms frames (plus a jittered microsecond) across the wrap point */
        for (int k = -40; k < 40; k++, n++) {
            int64_t tk = w0 + k * 1000 + (k % 3);
            t[n % CAP] = tk;
            push_t(tk);
            assert_times(t, CAP);
        }
        /* differences inside the ring are exact through the wrap */
        gs_sample_full a, b;
        TEST_ASSERT_TRUE(gs_ring_get(&g_r, n - 1u, &b));
        TEST_ASSERT_TRUE(gs_ring_get(&g_r, n - CAP, &a));
        TEST_ASSERT_TRUE(b.t_us - a.t_us == t[(n - 1u) % CAP] - t[(n - CAP) % CAP]);
        TEST_ASSERT_INT64_WITHIN(2, (int64_t)(CAP - 1u) * 1000, b.t_us - a.t_us);
        /* minutes to the next lap */
        for (int64_t u = MIN_US; u < wrap_us - MIN_US; u += MIN_US, n++) {
            t[n % CAP] = w0 + u;
            push_t(w0 + u);
        }
        assert_times(t, CAP);
    }
    TEST_ASSERT_TRUE(gs_ring_count(&g_r) == CAP);
}

/* Samples 2^31 us (35.8 min) older than the newest leave the ring, as if overwritten. */
static void test_time_span_evicts(void)
{
    push_t(0);
    push_t(1 * S_US);
    push_t(1200 * S_US);     /* 20 min */
    TEST_ASSERT_EQUAL_UINT32(3, gs_ring_count(&g_r));
    push_t(2147 * S_US);     /* the first two are 2146 s old: still inside */
    TEST_ASSERT_EQUAL_UINT32(4, gs_ring_count(&g_r));
    push_t(GS_RING_SPAN_US - 1);  /* 0 is one microsecond short of the span: still inside */
    TEST_ASSERT_EQUAL_UINT32(5, gs_ring_count(&g_r));
    push_t(GS_RING_SPAN_US);      /* exactly the span: 0 leaves, 1 s stays */
    TEST_ASSERT_EQUAL_UINT64(1, gs_ring_oldest(&g_r));
    push_t(2149 * S_US);     /* now 1 s is past 2147.48 s */
    TEST_ASSERT_EQUAL_UINT64(2, gs_ring_oldest(&g_r));
    TEST_ASSERT_NULL(gs_ring_at(&g_r, 1));
    gs_sample_full o;
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, 2, &o));
    TEST_ASSERT_TRUE(o.t_us == 1200 * S_US);
    push_t(2149 * S_US + 40 * MIN_US);  /* a 40 min pause: nothing before it can be told apart */
    TEST_ASSERT_EQUAL_UINT32(1, gs_ring_count(&g_r));
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, gs_ring_head(&g_r) - 1u, &o));
    TEST_ASSERT_TRUE(o.t_us == 4549 * S_US);
    push_t(4 * 3600 * S_US);      /* hours later, across a wrap */
    push_t(4 * 3600 * S_US + S_US / 2);
    TEST_ASSERT_EQUAL_UINT32(2, gs_ring_count(&g_r));
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, gs_ring_oldest(&g_r), &o));
    TEST_ASSERT_TRUE(o.t_us == 14400 * S_US);
}

static void test_time_order_and_bad_times(void)
{
    gs_sample_full s = mk(0);
    s.t_us = 5 * S_US;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&g_r, &s));
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&g_r, &s));       /* equal: stored */
    s.t_us = 5 * S_US - 1;
    TEST_ASSERT_EQUAL_INT(GS_EORDER, gs_ring_push(&g_r, &s));
    s.t_us = GS_T_NONE;
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_push(&g_r, &s));
    s.t_us = GS_T_MAX_US + 1;                                     /* beyond 2^62 us */
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_push(&g_r, &s));
    s.t_us = INT64_MAX;
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_push(&g_r, &s));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_push(NULL, &s));
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_push(&g_r, NULL));
    TEST_ASSERT_EQUAL_UINT32(2, gs_ring_count(&g_r));
    s.t_us = GS_T_MAX_US;                                         /* the largest time is stored */
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&g_r, &s));
    TEST_ASSERT_EQUAL_UINT32(1, gs_ring_count(&g_r));              /* far beyond the span */
    TEST_ASSERT_TRUE(gs_ring_get(&g_r, gs_ring_head(&g_r) - 1u, &s));
    TEST_ASSERT_TRUE(s.t_us == GS_T_MAX_US);
    /* the two ends of the accepted range, 2^63 us apart: the newer is stored, reads back
     * exactly, and nothing older is held (far beyond the span) */
    gs_ring r;
    gs_sample_full b = mk(0), o_full;
    TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_init(&r, &g_mem[1], CAP));
    static const int64_t ends[] = {-GS_T_MAX_US, -GS_T_MAX_US + 1, GS_T_MAX_US - 1, GS_T_MAX_US};
    for (size_t k = 0; k < sizeof ends / sizeof ends[0]; k++) {
        b.t_us = ends[k];
        TEST_ASSERT_EQUAL_INT(GS_OK, gs_ring_push(&r, &b));
        TEST_ASSERT_EQUAL_UINT32(k % 2u ? 2u : 1u, gs_ring_count(&r));  /* 1 us after the one before: both held */
        TEST_ASSERT_TRUE(gs_ring_get(&r, gs_ring_head(&r) - 1u, &o_full));
        TEST_ASSERT_TRUE(o_full.t_us == ends[k]);
    }
    TEST_ASSERT_TRUE(gs_ring_get(&r, gs_ring_oldest(&r), &o_full));
    TEST_ASSERT_TRUE(o_full.t_us == GS_T_MAX_US - 1);
    b.t_us = GS_T_MAX_US - 2;
    TEST_ASSERT_EQUAL_INT(GS_EORDER, gs_ring_push(&r, &b));
    b.t_us = INT64_MIN + 1;
    TEST_ASSERT_EQUAL_INT(GS_EINVAL, gs_ring_push(&r, &b));
    setUp();  /* g_mem served r */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_rejects_bad_args);
    RUN_TEST(test_empty_ring);
    RUN_TEST(test_fill_and_overwrite_oldest);
    RUN_TEST(test_wrap_near_uint32_boundary);
    RUN_TEST(test_wrap_near_uint64_large_index);
    RUN_TEST(test_at_returns_null_for_evicted_and_future);
    RUN_TEST(test_push_copies_sample);
    RUN_TEST(test_sample_layout_and_precision);
    RUN_TEST(test_body_axis_newest_only);
    RUN_TEST(test_time_wraps_every_71_minutes);
    RUN_TEST(test_time_span_evicts);
    RUN_TEST(test_time_order_and_bad_times);
    RUN_TEST(test_store_is_push_unchecked);
    return UNITY_END();
}
