/* gs_select.h - the k-th smallest of a few keys by rank, without data-dependent
 * branches: short medians, whose partitions' branches would go either way at random
 * (x86-64 hosts with AVX2 where the build optimises for speed; private to the core's files). */
#ifndef GS_SELECT_H
#define GS_SELECT_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#if !defined(__OPTIMIZE_SIZE__) && defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define GS_SELECT_AVX2 1
#define GS_AVX2 __attribute__((target("avx2,popcnt")))

/* the CPU runs the AVX2 paths */
static inline bool gs_select_avx2(void)
{
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
}

/* Keys [8j, 8j+8) of n, unsigned order made signed; lanes past n read as 0. */
GS_AVX2 static inline __m256i rank_lanes_avx2(const uint32_t *key, uint32_t n, uint32_t j)
{
    uint32_t left = n > 8u * j ? n - 8u * j : 0u;
    __m256i lanes = _mm256_cmpgt_epi32(_mm256_set1_epi32((int)left), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    return _mm256_xor_si256(_mm256_maskload_epi32((const int *)(const void *)&key[8u * j], lanes),
                            _mm256_set1_epi32(INT32_MIN));
}

/* Lanes of v below x, and above x, as bits 8j.. of *lt, *gt. */
GS_AVX2 static inline void rank_bits_avx2(__m256i x, __m256i v, uint32_t j, uint32_t *lt, uint32_t *gt)
{
    *lt |= (uint32_t)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(x, v))) << (8u * j);
    *gt |= (uint32_t)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(v, x))) << (8u * j);
}

/* Key x ranks k among the keys in v[0..nv) (valid: their lanes): at most k keys lie
 * below it and at most above = n - 1 - k above it. */
GS_AVX2 static inline bool rank_is_avx2(const __m256i *v, uint32_t nv, uint32_t x_key, uint32_t valid, uint32_t k,
                                        uint32_t above)
{
    __m256i x = _mm256_set1_epi32((int)(x_key ^ 0x80000000u));
    uint32_t lt = 0, gt = 0, j;
    for (j = 0; j < nv; j++) {
        rank_bits_avx2(x, v[j], j, &lt, &gt);
    }
    return ((uint32_t)__builtin_popcount(lt & valid) <= k) & ((uint32_t)__builtin_popcount(gt & valid) <= above);
}

/* The k-th smallest of n <= 32 keys (k < n) by rank, without data-dependent branches
 * but the one that finds it (unsigned order). *at: where to look
 * first (the last median's index: an IRLS step's median is mostly the same sample's),
 * then where it was found. */
GS_AVX2 static inline uint32_t gs_select_rank_avx2(const uint32_t *key, uint32_t n, uint32_t k, uint32_t *at)
{
    uint32_t valid = n == 32u ? ~0u : (1u << n) - 1u, above = n - 1u - k, i;
    __m256i v[4];
    v[0] = rank_lanes_avx2(key, n, 0u);
    v[1] = rank_lanes_avx2(key, n, 1u);
    if (n <= 16u) {
        if (*at < n && rank_is_avx2(v, 2u, key[*at], valid, k, above)) {
            return key[*at];
        }
        for (i = 0; i + 1u < n && !rank_is_avx2(v, 2u, key[i], valid, k, above); i++) {
        }
    } else {
        v[2] = rank_lanes_avx2(key, n, 2u);
        v[3] = rank_lanes_avx2(key, n, 3u);
        if (*at < n && rank_is_avx2(v, 4u, key[*at], valid, k, above)) {
            return key[*at];
        }
        for (i = 0; i + 1u < n && !rank_is_avx2(v, 4u, key[i], valid, k, above); i++) {
        }
    }
    *at = i; /* the last when no earlier key has rank k */
    return key[i];
}

/* A finite float's key: unsigned order of keys is the float order (-0 taken as +0). */
static inline uint32_t gs_select_float_key(float v)
{
    uint32_t b;
    v += 0.0f;
    memcpy(&b, &v, sizeof b);
    return b ^ ((uint32_t)((int32_t)b >> 31) | 0x80000000u);
}

/* the float whose key is k */
static inline float gs_select_key_float(uint32_t k)
{
    uint32_t b = k ^ ((uint32_t)((int32_t)~k >> 31) | 0x80000000u);
    float v;
    memcpy(&v, &b, sizeof v);
    return v;
}
#else
#define GS_SELECT_AVX2 0
#endif

#endif
