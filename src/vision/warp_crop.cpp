// warp_crop.cpp - cv::warpAffine's bilinear BGR crop (replicated border) with
// its pixels: eight positions at a time, one multiply-add per pixel and row pair,
// the source lines of the output row two rows ahead prefetched (a rotated ROI
// reads across many source rows, which the hardware prefetcher does not follow);
// and blobFromImage's float RGB planes of the crop in one pass.
#include "warp_crop.hpp"
#include "cpu_avx2.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include <opencv2/imgproc.hpp>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define GS_WARP_CROP_X86 1
#else
#define GS_WARP_CROP_X86 0
#endif

namespace gs {

#if GS_WARP_CROP_X86
namespace {

// OpenCV's warpAffine (imgwarp.cpp): positions in 1/2^10 pixel rounded to 1/32,
// bilinear weights in 1/2^15 (initInterTab2D: each product of the two 1-D
// weights, saturated to a short: 32767 where OpenCV's table has it)
constexpr int kAbBits = 10, kAbScale = 1 << kAbBits, kInterBits = 5, kTab = 1 << kInterBits;
constexpr int kRoundDelta = kAbScale / kTab / 2, kCoefBits = 15;

struct WeightTable {
    short w[kTab * kTab][4];
    uint32_t pair01[kTab * kTab], pair23[kTab * kTab];  // (w0, w1) and (w2, w3) as madd's word pairs
    WeightTable()
    {
        for (int i = 0; i < kTab; i++)
            for (int j = 0; j < kTab; j++) {
                const float ky[2] = {1.f - i * (1.f / kTab), i * (1.f / kTab)};
                const float kx[2] = {1.f - j * (1.f / kTab), j * (1.f / kTab)};
                short *t = w[i * kTab + j];
                for (int a = 0; a < 2; a++)
                    for (int b = 0; b < 2; b++)
                        t[a * 2 + b] = cv::saturate_cast<short>(ky[a] * kx[b] * (1 << kCoefBits));
                pair01[i * kTab + j] = static_cast<uint16_t>(t[0]) | static_cast<uint32_t>(static_cast<uint16_t>(t[1])) << 16;
                pair23[i * kTab + j] = static_cast<uint16_t>(t[2]) | static_cast<uint32_t>(static_cast<uint16_t>(t[3])) << 16;
            }
    }
};

const WeightTable &weights()
{
    static const WeightTable t;
    return t;
}

inline int clip(int v, int n) { return v >= 0 ? (v < n ? v : n - 1) : 0; }

// one BGR pixel's three bytes, read without touching the byte after them
inline uint64_t pixel(const uchar *p) { return p[0] | static_cast<uint64_t>(p[1]) << 8 | static_cast<uint64_t>(p[2]) << 16; }

// Output rows ahead whose source lines are prefetched: a rotated ROI makes one
// output row read a few pixels from each of ~80 source rows, a pattern the
// hardware prefetcher does not foresee, so the loads would wait on memory
// (1 to 8 rows ahead measure alike: one row takes ~3 us, far longer than a
// memory access).
constexpr int kAheadRows = 2;

// Prefetches the cache lines of one source row that eight taps start in, each
// line once: lines are numbered from the 64-byte boundary at or below the
// image's first byte, and a lane is fetched where its line differs from the
// lane before it (lane 0: from the previous call's last line).
struct RowPrefetcher {
    const uchar *base;  // the 64-byte boundary at or below the image's first byte
    int last = -1;      // the line fetched last

    __attribute__((target("avx2"))) void fetch(__m256i line)
    {
        const __m256i prev = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(line, _mm256_setr_epi32(7, 0, 1, 2, 3, 4, 5, 6)),
                                                _mm256_set1_epi32(last), 1);
        unsigned fresh = ~static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(line, prev)))) & 0xffu;
        alignas(32) int lines[8];
        _mm256_store_si256(reinterpret_cast<__m256i *>(lines), line);
        last = lines[7];
        for (; fresh; fresh &= fresh - 1)
            _mm_prefetch(reinterpret_cast<const char *>(base + static_cast<size_t>(lines[__builtin_ctz(fresh)]) * 64), _MM_HINT_T0);
    }
};

// Prefetches the source lines that an output row's taps will read, eight
// positions at a time: the pixel (clamped into the image) in both tap rows.
struct TapPrefetcher {
    const double *M;
    const int *adelta, *bdelta;
    __m256i w_last, h_last, step, lead;  // clamps, row stride, the image's offset from its first line
    RowPrefetcher upper, lower;
    __m256i x0, y0;  // the row's start in 1/1024 pixel

    __attribute__((target("avx2"))) TapPrefetcher(const cv::Mat &src, const double *m, const int *ad, const int *bd)
        : M(m), adelta(ad), bdelta(bd), upper{first_line(src.data)}, lower{first_line(src.data)}
    {
        w_last = _mm256_set1_epi32(src.cols - 1);
        h_last = _mm256_set1_epi32(src.rows - 2);
        step = _mm256_set1_epi32(static_cast<int>(src.step));
        lead = _mm256_set1_epi32(static_cast<int>(src.data - upper.base));
    }
    static const uchar *first_line(const uchar *p) { return reinterpret_cast<const uchar *>(reinterpret_cast<uintptr_t>(p) & ~uintptr_t(63)); }

    __attribute__((target("avx2"))) void row(int y)
    {
        x0 = _mm256_set1_epi32(cv::saturate_cast<int>((M[1] * y + M[2]) * kAbScale) + kRoundDelta);
        y0 = _mm256_set1_epi32(cv::saturate_cast<int>((M[4] * y + M[5]) * kAbScale) + kRoundDelta);
    }
    // positions x .. x + 7 of the row set by row()
    __attribute__((target("avx2"))) void block(int x)
    {
        const __m256i zero = _mm256_setzero_si256();
        const __m256i ad = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(adelta + x));
        const __m256i bd = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(bdelta + x));
        const __m256i px = _mm256_min_epi32(_mm256_max_epi32(_mm256_srai_epi32(_mm256_add_epi32(x0, ad), kAbBits), zero), w_last);
        const __m256i py = _mm256_min_epi32(_mm256_max_epi32(_mm256_srai_epi32(_mm256_add_epi32(y0, bd), kAbBits), zero), h_last);
        const __m256i at = _mm256_add_epi32(_mm256_add_epi32(_mm256_mullo_epi32(py, step), _mm256_mullo_epi32(px, _mm256_set1_epi32(3))), lead);
        upper.fetch(_mm256_srli_epi32(at, 6));
        lower.fetch(_mm256_srli_epi32(_mm256_add_epi32(at, step), 6));
    }
    // a whole row: the first rows, before the crop reaches them
    __attribute__((target("avx2"))) void whole_row(int y, int side)
    {
        row(y);
        for (int x = 0; x + 8 <= side; x += 8) block(x);
    }
};

__attribute__((target("avx2"))) void crop_avx2(const cv::Mat &src, const double *M, int side, cv::Mat &dst)
{
    const WeightTable &wt = weights();
    std::vector<int> adelta(side), bdelta(side);
    for (int x = 0; x < side; x++) {
        adelta[x] = cv::saturate_cast<int>(M[0] * x * kAbScale);
        bdelta[x] = cv::saturate_cast<int>(M[3] * x * kAbScale);
    }
    const int W = src.cols, H = src.rows;
    const size_t step = src.step;
    const uchar *S0 = src.data;
    // the two taps of each channel side by side as 16-bit words: B G R of row 0, then of row 1
    const __m128i take0 = _mm_setr_epi8(0, -1, 3, -1, 1, -1, 4, -1, 2, -1, 5, -1, -1, -1, -1, -1);
    const __m128i take1 = _mm_setr_epi8(8, -1, 11, -1, 9, -1, 12, -1, 10, -1, 13, -1, -1, -1, -1, -1);
    const __m128i half = _mm_set1_epi32(1 << (kCoefBits - 1));
    const __m256i frac = _mm256_set1_epi32(kTab - 1);
    const __m256i w_fast = _mm256_set1_epi32(W - 2), h_fast = _mm256_set1_epi32(H - 1);
    const __m256i step8 = _mm256_set1_epi32(static_cast<int>(step)), three = _mm256_set1_epi32(3);
    TapPrefetcher ahead(src, M, adelta.data(), bdelta.data());
    for (int y = 0; y < std::min(kAheadRows, side); y++) ahead.whole_row(y, side);
    alignas(32) int sxs[8], sys[8], as[8], offs[8];
    for (int y = 0; y < side; y++) {
        const int X0 = cv::saturate_cast<int>((M[1] * y + M[2]) * kAbScale) + kRoundDelta;
        const int Y0 = cv::saturate_cast<int>((M[4] * y + M[5]) * kAbScale) + kRoundDelta;
        const __m256i x0v = _mm256_set1_epi32(X0), y0v = _mm256_set1_epi32(Y0);
        const bool prefetch = y + kAheadRows < side;
        if (prefetch) ahead.row(y + kAheadRows);
        uchar *D = dst.ptr<uchar>(y);
        for (int x = 0; x < side; x += 8) {
            if (prefetch && x + 8 <= side) ahead.block(x);
            // eight positions at once: the source pixel (saturated to shorts as OpenCV's map),
            // the weights' index, whether the 8-byte reads of both rows stay inside the image
            const int n = std::min(8, side - x);
            __m256i X, Y;
            if (n == 8) {
                X = _mm256_srai_epi32(_mm256_add_epi32(x0v, _mm256_loadu_si256(reinterpret_cast<const __m256i *>(&adelta[x]))), kAbBits - kInterBits);
                Y = _mm256_srai_epi32(_mm256_add_epi32(y0v, _mm256_loadu_si256(reinterpret_cast<const __m256i *>(&bdelta[x]))), kAbBits - kInterBits);
            } else {
                alignas(32) int xa[8] = {0}, ya[8] = {0};
                for (int i = 0; i < n; i++) {
                    xa[i] = adelta[x + i];
                    ya[i] = bdelta[x + i];
                }
                X = _mm256_srai_epi32(_mm256_add_epi32(x0v, _mm256_load_si256(reinterpret_cast<const __m256i *>(xa))), kAbBits - kInterBits);
                Y = _mm256_srai_epi32(_mm256_add_epi32(y0v, _mm256_load_si256(reinterpret_cast<const __m256i *>(ya))), kAbBits - kInterBits);
            }
            // saturation to shorts: pack with signed saturation and widen back
            const __m256i sx = _mm256_cvtepi16_epi32(_mm_packs_epi32(_mm256_castsi256_si128(_mm256_srai_epi32(X, kInterBits)),
                                                                     _mm256_extracti128_si256(_mm256_srai_epi32(X, kInterBits), 1)));
            const __m256i sy = _mm256_cvtepi16_epi32(_mm_packs_epi32(_mm256_castsi256_si128(_mm256_srai_epi32(Y, kInterBits)),
                                                                     _mm256_extracti128_si256(_mm256_srai_epi32(Y, kInterBits), 1)));
            const __m256i av = _mm256_or_si256(_mm256_slli_epi32(_mm256_and_si256(Y, frac), kInterBits), _mm256_and_si256(X, frac));
            // unsigned compare sx < W - 2 and sy < H - 1: both >= 0 and below
            const __m256i in_x = _mm256_and_si256(_mm256_cmpgt_epi32(w_fast, sx), _mm256_cmpgt_epi32(sx, _mm256_set1_epi32(-1)));
            const __m256i in_y = _mm256_and_si256(_mm256_cmpgt_epi32(h_fast, sy), _mm256_cmpgt_epi32(sy, _mm256_set1_epi32(-1)));
            const int inside = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_and_si256(in_x, in_y)));
            _mm256_store_si256(reinterpret_cast<__m256i *>(offs), _mm256_add_epi32(_mm256_mullo_epi32(sy, step8), _mm256_mullo_epi32(sx, three)));
            _mm256_store_si256(reinterpret_cast<__m256i *>(as), av);
            _mm256_store_si256(reinterpret_cast<__m256i *>(sxs), sx);
            _mm256_store_si256(reinterpret_cast<__m256i *>(sys), sy);
            for (int i = 0; i < n; i++, D += 3) {
                __m128i rows;
                if (inside >> i & 1) {
                    // 8 bytes read from the pixel on: 2 past the pair, still inside the row
                    const uchar *p = S0 + offs[i];
                    rows = _mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i *>(p)),
                                              _mm_loadl_epi64(reinterpret_cast<const __m128i *>(p + step)));
                } else {
                    // at the border: the taps clipped into the image (BORDER_REPLICATE), as OpenCV
                    const int x0 = clip(sxs[i], W) * 3, x1 = clip(sxs[i] + 1, W) * 3;
                    const uchar *r0 = S0 + clip(sys[i], H) * step, *r1 = S0 + clip(sys[i] + 1, H) * step;
                    rows = _mm_unpacklo_epi64(_mm_cvtsi64_si128(static_cast<long long>(pixel(r0 + x0) | pixel(r0 + x1) << 24)),
                                              _mm_cvtsi64_si128(static_cast<long long>(pixel(r1 + x0) | pixel(r1 + x1) << 24)));
                }
                const int a = as[i];
                __m128i s = _mm_add_epi32(
                    _mm_madd_epi16(_mm_shuffle_epi8(rows, take0), _mm_set1_epi32(static_cast<int>(wt.pair01[a]))),
                    _mm_madd_epi16(_mm_shuffle_epi8(rows, take1), _mm_set1_epi32(static_cast<int>(wt.pair23[a]))));
                s = _mm_srai_epi32(_mm_add_epi32(s, half), kCoefBits);
                s = _mm_packus_epi16(_mm_packs_epi32(s, s), s);
                const uint32_t v = static_cast<uint32_t>(_mm_cvtsi128_si32(s));
                if (x + i + 1 < side) {
                    std::memcpy(D, &v, 4);  // the fourth byte is the next pixel's, written next
                } else {
                    D[0] = static_cast<uchar>(v);
                    D[1] = static_cast<uchar>(v >> 8);
                    D[2] = static_cast<uchar>(v >> 16);
                }
            }
        }
    }
}

// Sixteen bytes as floats times scale: one rounding of the product, as the scalar code
__attribute__((target("avx2"))) inline void store_scaled(__m128i v, __m256 scale, float *out)
{
    _mm256_storeu_ps(out, _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(v)), scale));
    _mm256_storeu_ps(out + 8, _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_srli_si128(v, 8))), scale));
}

// One row's pixels as three float planes in R, G, B order, each byte times scale.
__attribute__((target("avx2"))) void row_planes_avx2(const uchar *bgr, int n, float scale, float *r, float *g, float *b)
{
    // byte positions of one channel in three 16-byte loads, 16 pixels a time
    const __m128i b0 = _mm_setr_epi8(0, 3, 6, 9, 12, 15, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i b1 = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, 2, 5, 8, 11, 14, -1, -1, -1, -1, -1);
    const __m128i b2 = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 1, 4, 7, 10, 13);
    const __m128i g0 = _mm_setr_epi8(1, 4, 7, 10, 13, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i g1 = _mm_setr_epi8(-1, -1, -1, -1, -1, 0, 3, 6, 9, 12, 15, -1, -1, -1, -1, -1);
    const __m128i g2 = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 2, 5, 8, 11, 14);
    const __m128i r0 = _mm_setr_epi8(2, 5, 8, 11, 14, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i r1 = _mm_setr_epi8(-1, -1, -1, -1, -1, 1, 4, 7, 10, 13, -1, -1, -1, -1, -1, -1);
    const __m128i r2 = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 3, 6, 9, 12, 15);
    const __m256 s = _mm256_set1_ps(scale);
    int x = 0;
    for (; x + 16 <= n; x += 16, bgr += 48) {
        const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i *>(bgr));
        const __m128i m = _mm_loadu_si128(reinterpret_cast<const __m128i *>(bgr + 16));
        const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i *>(bgr + 32));
        store_scaled(_mm_or_si128(_mm_or_si128(_mm_shuffle_epi8(a, r0), _mm_shuffle_epi8(m, r1)), _mm_shuffle_epi8(c, r2)), s, r + x);
        store_scaled(_mm_or_si128(_mm_or_si128(_mm_shuffle_epi8(a, g0), _mm_shuffle_epi8(m, g1)), _mm_shuffle_epi8(c, g2)), s, g + x);
        store_scaled(_mm_or_si128(_mm_or_si128(_mm_shuffle_epi8(a, b0), _mm_shuffle_epi8(m, b1)), _mm_shuffle_epi8(c, b2)), s, b + x);
    }
    for (; x < n; x++, bgr += 3) {
        b[x] = static_cast<float>(bgr[0]) * scale;
        g[x] = static_cast<float>(bgr[1]) * scale;
        r[x] = static_cast<float>(bgr[2]) * scale;
    }
}

}  // namespace
#endif

void bgr_to_rgb_blob(const cv::Mat &bgr, double scale, cv::Mat &blob)
{
    CV_Assert(bgr.type() == CV_8UC3 && bgr.dims == 2);
    const int rows = bgr.rows, cols = bgr.cols;
    const int shape[] = {1, 3, rows, cols};
    blob.create(4, shape, CV_32F);
    // blobFromImage converts to float, then multiplies by the scale as a float
    const float s = static_cast<float>(scale);
    const size_t plane = static_cast<size_t>(rows) * cols;
    float *R = blob.ptr<float>(), *G = R + plane, *B = G + plane;
    for (int y = 0; y < rows; y++) {
        const uchar *p = bgr.ptr<uchar>(y);
        float *r = R + static_cast<size_t>(y) * cols, *g = G + static_cast<size_t>(y) * cols, *b = B + static_cast<size_t>(y) * cols;
#if GS_WARP_CROP_X86
        if (have_avx2()) {
            row_planes_avx2(p, cols, s, r, g, b);
            continue;
        }
#endif
        for (int x = 0; x < cols; x++, p += 3) {
            b[x] = static_cast<float>(p[0]) * s;
            g[x] = static_cast<float>(p[1]) * s;
            r[x] = static_cast<float>(p[2]) * s;
        }
    }
}

void warp_crop_bgr(const cv::Mat &src, const cv::Mat &m, int side, cv::Mat &dst)
{
#if GS_WARP_CROP_X86
    // positions are shorts in OpenCV's arithmetic and offsets ints here: larger images keep its own code
    if (have_avx2() && src.type() == CV_8UC3 && src.cols >= 3 && src.rows >= 2 && src.cols < 32767 &&
        src.rows < 32767 && static_cast<double>(src.step) * src.rows < 2e9 && side > 0 && m.type() == CV_64F &&
        m.rows == 2 && m.cols == 3 && m.isContinuous() && dst.data != src.data) {
        dst.create(side, side, CV_8UC3);
        crop_avx2(src, m.ptr<double>(), side, dst);
        return;
    }
#endif
    cv::warpAffine(src, dst, m, cv::Size(side, side), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
}

}  // namespace gs
