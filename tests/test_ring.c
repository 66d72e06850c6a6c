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
static gs_sample mk(uint64_t i)
{
    gs_sample s;
    s.t_s = (double)i;
    s.x_px = (float)(i % 65536u);
    s.y_px = (float)((i * 7u) % 65536u);
    s.w = 1.0f;
    s.size_px = NAN;
    s.up_x = 0.0f;
    s.up_y = -1.0f;
    s.upright = 1.0f;
    s.reserved = 0.0f;
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
        const gs_sample *s = gs_ring_at(&g_r, i);
        TEST_ASSERT_NOT_NULL(s);
        TEST_ASSERT_TRUE(s->t_s == (double)i);
        TEST_ASSERT_EQUAL_FLOAT((float)(i % 65536u), s->x_px);
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
        gs_sample s = mk(i);
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
        gs_sample s = mk(i);
        gs_ring_push(&g_r, &s);
    }
    for (uint64_t i = start + CAP; i < start + 3u * CAP + 3u; i++) {
        gs_sample s = mk(i);
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
        gs_sample s = mk(i);
        gs_ring_push(&g_r, &s);
    }
    TEST_ASSERT_NULL(gs_ring_at(&g_r, 0));
    TEST_ASSERT_NULL(gs_ring_at(&g_r, 3));
    TEST_ASSERT_NOT_NULL(gs_ring_at(&g_r, 4));
    TEST_ASSERT_NOT_NULL(gs_ring_at(&g_r, CAP + 3u));
    TEST_ASSERT_NULL(gs_ring_at(&g_r, CAP + 4u));
    /* The evicted index 3 and the held index 3+CAP share a slot: only the held one resolves. */
    TEST_ASSERT_TRUE(gs_ring_at(&g_r, CAP + 3u)->t_s == (double)(CAP + 3u));
}

static void test_push_copies_sample(void)
{
    gs_sample s = mk(42);
    gs_ring_push(&g_r, &s);
    s.t_s = -1.0;  /* the caller's copy changes, the ring's does not */
    TEST_ASSERT_TRUE(gs_ring_at(&g_r, 0)->t_s == 42.0);
    TEST_ASSERT_TRUE(isnan(gs_ring_at(&g_r, 0)->size_px));
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
    return UNITY_END();
}
