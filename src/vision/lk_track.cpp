// lk_track.cpp - cv::calcOpticalFlowPyrLK's tracking loop (lkpyramid.cpp,
// LKTrackerInvoker) with AVX2's sixteen-pixel integer interpolation: the same
// weights, shifts and window values, and the same float sums in the same order
// (OpenCV's four-lane accumulators chunk by chunk, its scalar sums over the
// columns past the chunks, its lane reductions), so the same points and status.
#include "lk_track.hpp"
#include "cpu_avx2.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <opencv2/video/tracking.hpp>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define GS_LK_TRACK_X86 1
#else
#define GS_LK_TRACK_X86 0
#endif

namespace gs {

namespace {

void opencv_track(const std::vector<cv::Mat> &prev_pyr, const std::vector<cv::Mat> &next_pyr,
                  const std::vector<cv::Point2f> &from, std::vector<cv::Point2f> &to, std::vector<uchar> &status,
                  cv::Size win, int max_level)
{
    cv::calcOpticalFlowPyrLK(prev_pyr, next_pyr, from, to, status, cv::noArray(), win, max_level);
}

#if GS_LK_TRACK_X86

constexpr int kWin = 21;             // the window this loop is written for
constexpr int kBody = 16;            // columns OpenCV interpolates eight at a time
constexpr int kTail = kWin - kBody;  // columns OpenCV interpolates one at a time
constexpr int kWBits = 14;           // bilinear weights' fraction bits
constexpr int kImgShift = kWBits - 5;  // images keep 5 fraction bits
constexpr float kFltScale = 1.f / (1 << 20);
constexpr int kMaxCount = 30;                 // TermCriteria COUNT
constexpr double kEps2 = 0.01 * 0.01;         // TermCriteria EPS, squared as OpenCV squares it
constexpr float kMinEig = static_cast<float>(1e-4);

// (x, y) of a level, which may lie in its border (Mat::ptr asserts rows inside)
inline const uchar *pixel(const cv::Mat &m, int x, int y)
{
    return m.data + static_cast<ptrdiff_t>(y) * static_cast<ptrdiff_t>(m.step) + x;
}

inline const short *deriv_pixel(const cv::Mat &m, int x, int y)
{
    return reinterpret_cast<const short *>(pixel(m, 0, y)) + 2 * x;
}

struct Weights {
    int w00, w01, w10, w11;
};

// OpenCV's 14-bit bilinear weights of the fractions a (x) and b (y)
inline Weights bilinear(float a, float b)
{
    Weights w;
    w.w00 = cvRound((1.f - a) * (1.f - b) * (1 << kWBits));
    w.w01 = cvRound(a * (1.f - b) * (1 << kWBits));
    w.w10 = cvRound((1.f - a) * b * (1 << kWBits));
    w.w11 = (1 << kWBits) - w.w00 - w.w01 - w.w10;
    return w;
}

// The previous image's window at one point and level, as the iterations read it
struct PrevWindow {
    alignas(32) int16_t img[kWin][kBody];  // interpolated image (5 fraction bits), body columns
    alignas(32) int16_t d10[kWin][kBody];  // body derivatives in the order the b sums pair them
    alignas(32) int16_t d11[kWin][kBody];
    alignas(32) int32_t tail_img[kWin][8];  // tail columns (5 used)
    alignas(32) int32_t tail_dx[kWin][8];   // 16 bits each, upper halves zero
    alignas(32) int32_t tail_dy[kWin][8];
    float a11, a12, a22;
};

struct PairWeights {
    __m256i w0, w1;  // (w00, w01) and (w10, w11) as madd's word pairs
};

__attribute__((target("avx2"))) inline PairWeights pair_weights(const Weights &w)
{
    PairWeights p;
    p.w0 = _mm256_set1_epi32(static_cast<int>(static_cast<uint16_t>(w.w00) | static_cast<uint32_t>(static_cast<uint16_t>(w.w01)) << 16));
    p.w1 = _mm256_set1_epi32(static_cast<int>(static_cast<uint16_t>(w.w10) | static_cast<uint32_t>(static_cast<uint16_t>(w.w11)) << 16));
    return p;
}

// sixteen interpolated image pixels (5 fraction bits) from row p and the row below
__attribute__((target("avx2"))) inline __m256i image16(const uchar *p, size_t step, const PairWeights &w)
{
    const __m256i a0 = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i *>(p)));
    const __m256i a1 = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i *>(p + 1)));
    const __m256i b0 = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i *>(p + step)));
    const __m256i b1 = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i *>(p + step + 1)));
    const __m256i delta = _mm256_set1_epi32(1 << (kImgShift - 1));
    __m256i lo = _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(a0, a1), w.w0), delta);
    lo = _mm256_add_epi32(lo, _mm256_madd_epi16(_mm256_unpacklo_epi16(b0, b1), w.w1));
    __m256i hi = _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(a0, a1), w.w0), delta);
    hi = _mm256_add_epi32(hi, _mm256_madd_epi16(_mm256_unpackhi_epi16(b0, b1), w.w1));
    return _mm256_packs_epi32(_mm256_srai_epi32(lo, kImgShift), _mm256_srai_epi32(hi, kImgShift));
}

// the tail's five interpolated image pixels (5 fraction bits, 32-bit lanes 0..4)
// from row p and the row below; reads columns kBody - 2 .. kWin only
__attribute__((target("avx2"))) inline __m256i image_tail(const uchar *p, size_t step, const PairWeights &w)
{
    const __m128i a0 = _mm_cvtepu8_epi16(_mm_srli_si128(_mm_loadl_epi64(reinterpret_cast<const __m128i *>(p + kBody - 2)), 2));
    const __m128i b0 = _mm_cvtepu8_epi16(
        _mm_srli_si128(_mm_loadl_epi64(reinterpret_cast<const __m128i *>(p + step + kBody - 2)), 2));
    const __m256i a = _mm256_set_m128i(_mm_unpackhi_epi16(a0, _mm_srli_si128(a0, 2)), _mm_unpacklo_epi16(a0, _mm_srli_si128(a0, 2)));
    const __m256i b = _mm256_set_m128i(_mm_unpackhi_epi16(b0, _mm_srli_si128(b0, 2)), _mm_unpacklo_epi16(b0, _mm_srli_si128(b0, 2)));
    __m256i v = _mm256_add_epi32(_mm256_madd_epi16(a, w.w0), _mm256_set1_epi32(1 << (kImgShift - 1)));
    v = _mm256_add_epi32(v, _mm256_madd_epi16(b, w.w1));
    return _mm256_srai_epi32(v, kImgShift);
}

// eight interpolated derivative pairs from derivative row d and the row below:
// lo = (dx, dy) of pixels 0, 1 | 4, 5 and hi = of pixels 2, 3 | 6, 7, 32 bits each
__attribute__((target("avx2"))) inline void deriv8(const short *d, size_t dstep, const PairWeights &w, __m256i &lo,
                                                  __m256i &hi)
{
    const __m256i a0 = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(d));
    const __m256i a1 = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(d + 2));
    const __m256i b0 = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(d + dstep));
    const __m256i b1 = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(d + dstep + 2));
    const __m256i delta = _mm256_set1_epi32(1 << (kWBits - 1));
    lo = _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(a0, a1), w.w0), delta);
    lo = _mm256_srai_epi32(_mm256_add_epi32(lo, _mm256_madd_epi16(_mm256_unpacklo_epi16(b0, b1), w.w1)), kWBits);
    hi = _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(a0, a1), w.w0), delta);
    hi = _mm256_srai_epi32(_mm256_add_epi32(hi, _mm256_madd_epi16(_mm256_unpackhi_epi16(b0, b1), w.w1)), kWBits);
}

// the tail's derivative taps from p (column kBody): pixels 16, 17 | 18, 19 and 20
// as madd's pairs of neighbours
__attribute__((target("avx2"))) inline void taps(const short *p, __m256i &four, __m128i &one)
{
    const __m128i v0 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(p));
    const __m128i v1 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(p + 2));
    const __m128i v2 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(p + 4));
    four = _mm256_set_m128i(_mm_unpackhi_epi16(v0, v1), _mm_unpacklo_epi16(v0, v1));
    one = _mm_unpackhi_epi16(v2, _mm_srli_si128(v2, 4));
}

// the tail's five interpolated derivative pairs from derivative row d and the row
// below: dx and dy in 32-bit lanes 0..4, zeros above; reads columns kBody .. kWin only
__attribute__((target("avx2"))) inline void deriv_tail(const short *d, size_t dstep, const PairWeights &w, __m256i &dx,
                                                      __m256i &dy)
{
    __m256i a4, b4;
    __m128i a1, b1;
    taps(d + 2 * kBody, a4, a1);
    taps(d + dstep + 2 * kBody, b4, b1);
    __m256i four = _mm256_add_epi32(_mm256_madd_epi16(a4, w.w0), _mm256_set1_epi32(1 << (kWBits - 1)));
    four = _mm256_srai_epi32(_mm256_add_epi32(four, _mm256_madd_epi16(b4, w.w1)), kWBits);
    __m128i one = _mm_add_epi32(_mm_madd_epi16(a1, _mm256_castsi256_si128(w.w0)), _mm_set1_epi32(1 << (kWBits - 1)));
    one = _mm_srai_epi32(_mm_add_epi32(one, _mm_madd_epi16(b1, _mm256_castsi256_si128(w.w1))), kWBits);
    // (dx16, dy16, dx17, dy17 | dx18, ...) to (dx16..dx19 | dy16..dy19)
    const __m256i split = _mm256_permutevar8x32_epi32(four, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
    dx = _mm256_set_m128i(_mm_cvtsi32_si128(_mm_cvtsi128_si32(one)), _mm256_castsi256_si128(split));
    dy = _mm256_set_m128i(_mm_cvtsi32_si128(_mm_extract_epi32(one, 1)), _mm256_extracti128_si256(split, 1));
}

// OpenCV's v_reduce_sum of four floats: (l0 + l2) + (l1 + l3)
__attribute__((target("avx2"))) inline float reduce_sum(__m128 v)
{
    v = _mm_add_ps(v, _mm_castsi128_ps(_mm_srli_si128(_mm_castps_si128(v), 8)));
    v = _mm_add_ps(v, _mm_castsi128_ps(_mm_srli_si128(_mm_castps_si128(v), 4)));
    return _mm_cvtss_f32(v);
}

// The previous image's window and derivatives at (x, y) (the window's corner,
// weights w) and the sums of the derivatives' products A11, A12, A22
__attribute__((target("avx2"))) void sample_prev(const cv::Mat &img, const cv::Mat &deriv, int x, int y,
                                                 const Weights &w, PrevWindow &pw)
{
    const PairWeights pwt = pair_weights(w);
    const size_t step = img.step, dstep = deriv.step / sizeof(short);
    __m128 q11 = _mm_setzero_ps(), q12 = _mm_setzero_ps(), q22 = _mm_setzero_ps();
    __m128 tail = _mm_setzero_ps();  // the tail's sums A11, A12, A22, column after column
    for (int r = 0; r < kWin; r++) {
        const uchar *src = pixel(img, x, y + r);
        const short *d = deriv_pixel(deriv, x, y + r);
        _mm256_store_si256(reinterpret_cast<__m256i *>(pw.img[r]), image16(src, step, pwt));
        __m256i packed[2];
        for (int half = 0; half < 2; half++) {  // pixels 0..7, then 8..15
            __m256i lo, hi;
            deriv8(d + 16 * half, dstep, pwt, lo, hi);
            packed[half] = _mm256_packs_epi32(lo, hi);
            const __m256 flo = _mm256_cvtepi32_ps(lo), fhi = _mm256_cvtepi32_ps(hi);
            const __m256 fx = _mm256_shuffle_ps(flo, fhi, _MM_SHUFFLE(2, 0, 2, 0));  // dx of 0..3 | 4..7
            const __m256 fy = _mm256_shuffle_ps(flo, fhi, _MM_SHUFFLE(3, 1, 3, 1));
            const __m256 xx = _mm256_mul_ps(fx, fx), xy = _mm256_mul_ps(fx, fy), yy = _mm256_mul_ps(fy, fy);
            // OpenCV's order: four pixels, then the next four
            q22 = _mm_add_ps(_mm256_castps256_ps128(yy), q22);
            q12 = _mm_add_ps(_mm256_castps256_ps128(xy), q12);
            q11 = _mm_add_ps(_mm256_castps256_ps128(xx), q11);
            q22 = _mm_add_ps(_mm256_extractf128_ps(yy, 1), q22);
            q12 = _mm_add_ps(_mm256_extractf128_ps(xy, 1), q12);
            q11 = _mm_add_ps(_mm256_extractf128_ps(xx, 1), q11);
        }
        // the b sums' pairing: pixels k and k + 4 of each eight side by side
        const __m256i first = _mm256_permute2x128_si256(packed[0], packed[1], 0x20);
        const __m256i second = _mm256_permute2x128_si256(packed[0], packed[1], 0x31);
        _mm256_store_si256(reinterpret_cast<__m256i *>(pw.d10[r]), _mm256_unpacklo_epi16(first, second));
        _mm256_store_si256(reinterpret_cast<__m256i *>(pw.d11[r]), _mm256_unpackhi_epi16(first, second));
        // OpenCV's scalar columns: the same integers, then its sums column after column
        _mm256_store_si256(reinterpret_cast<__m256i *>(pw.tail_img[r]), image_tail(src, step, pwt));
        __m256i dx, dy;
        deriv_tail(d, dstep, pwt, dx, dy);
        // the differences' products take madd's: 16-bit derivatives, upper halves zero
        const __m256i low16 = _mm256_set1_epi32(0xffff);
        _mm256_store_si256(reinterpret_cast<__m256i *>(pw.tail_dx[r]), _mm256_and_si256(dx, low16));
        _mm256_store_si256(reinterpret_cast<__m256i *>(pw.tail_dy[r]), _mm256_and_si256(dy, low16));
        const __m256 fx = _mm256_cvtepi32_ps(dx), fy = _mm256_cvtepi32_ps(dy);
        // exact products (below 2^24), as OpenCV's integer ones converted
        const __m256 xx = _mm256_mul_ps(fx, fx), xy = _mm256_mul_ps(fx, fy), yy = _mm256_mul_ps(fy, fy);
        // per column [xx, xy, yy, 0]: the three sums in one register, added in OpenCV's order
        __m128 c0 = _mm256_castps256_ps128(xx), c1 = _mm256_castps256_ps128(xy), c2 = _mm256_castps256_ps128(yy),
               c3 = _mm_setzero_ps();
        _MM_TRANSPOSE4_PS(c0, c1, c2, c3);
        const __m128 c4 = _mm_movelh_ps(_mm_unpacklo_ps(_mm256_extractf128_ps(xx, 1), _mm256_extractf128_ps(xy, 1)),
                                        _mm_unpacklo_ps(_mm256_extractf128_ps(yy, 1), _mm_setzero_ps()));
        tail = _mm_add_ps(tail, c0);
        tail = _mm_add_ps(tail, c1);
        tail = _mm_add_ps(tail, c2);
        tail = _mm_add_ps(tail, c3);
        tail = _mm_add_ps(tail, c4);
    }
    alignas(16) float t[4];
    _mm_store_ps(t, tail);
    float t11 = t[0], t12 = t[1], t22 = t[2];
    t11 += reduce_sum(q11);
    t12 += reduce_sum(q12);
    t22 += reduce_sum(q22);
    pw.a11 = t11 * kFltScale;
    pw.a12 = t12 * kFltScale;
    pw.a22 = t22 * kFltScale;
}

// OpenCV's mismatch sums b1, b2 of the next image's window at (x, y) (weights w)
// One window row's terms of the b sums against the next image at (x, y + r):
// p0, p1 the first sixteen columns' products paired as OpenCV pairs them
// (k, k + 4, k, k + 4, k + 1, k + 5, ...), dx and dy the last columns' products
// (madd's: the derivatives' upper halves are zero); all exact integers
struct RowTerms {
    __m256i p0, p1, dx, dy;
};

__attribute__((target("avx2"))) inline RowTerms row_terms(const uchar *src, size_t step, const PairWeights &pwt,
                                                          const PrevWindow &pw, int r)
{
    const __m256i pair0 = _mm256_setr_epi8(0, 1, 8, 9, 0, 1, 8, 9, 2, 3, 10, 11, 2, 3, 10, 11,  //
                                           0, 1, 8, 9, 0, 1, 8, 9, 2, 3, 10, 11, 2, 3, 10, 11);
    const __m256i pair1 = _mm256_setr_epi8(4, 5, 12, 13, 4, 5, 12, 13, 6, 7, 14, 15, 6, 7, 14, 15,  //
                                           4, 5, 12, 13, 4, 5, 12, 13, 6, 7, 14, 15, 6, 7, 14, 15);
    const __m256i diff = _mm256_subs_epi16(image16(src, step, pwt),
                                           _mm256_load_si256(reinterpret_cast<const __m256i *>(pw.img[r])));
    const __m256i td = _mm256_sub_epi32(image_tail(src, step, pwt),
                                        _mm256_load_si256(reinterpret_cast<const __m256i *>(pw.tail_img[r])));
    RowTerms t;
    t.p0 = _mm256_madd_epi16(_mm256_shuffle_epi8(diff, pair0), _mm256_load_si256(reinterpret_cast<const __m256i *>(pw.d10[r])));
    t.p1 = _mm256_madd_epi16(_mm256_shuffle_epi8(diff, pair1), _mm256_load_si256(reinterpret_cast<const __m256i *>(pw.d11[r])));
    t.dx = _mm256_madd_epi16(td, _mm256_load_si256(reinterpret_cast<const __m256i *>(pw.tail_dx[r])));
    t.dy = _mm256_madd_epi16(td, _mm256_load_si256(reinterpret_cast<const __m256i *>(pw.tail_dy[r])));
    return t;
}

__attribute__((target("avx2"))) void mismatch(const cv::Mat &img, int x, int y, const Weights &w, const PrevWindow &pw,
                                              float &b1, float &b2)
{
    const PairWeights pwt = pair_weights(w);
    const size_t step = img.step;
    __m128 qb0 = _mm_setzero_ps(), qb1 = _mm_setzero_ps();
    float s1 = 0.f, s2 = 0.f;  // the tail's sums, column after column
    alignas(32) float tx[8], ty[8];
    for (int r = 0; r < kWin; r++) {
        const RowTerms t = row_terms(pixel(img, x, y + r), step, pwt, pw, r);
        const __m256 f0 = _mm256_cvtepi32_ps(t.p0), f1 = _mm256_cvtepi32_ps(t.p1);
        // OpenCV's order: the first eight, then the second
        qb0 = _mm_add_ps(qb0, _mm256_castps256_ps128(f0));
        qb1 = _mm_add_ps(qb1, _mm256_castps256_ps128(f1));
        qb0 = _mm_add_ps(qb0, _mm256_extractf128_ps(f0, 1));
        qb1 = _mm_add_ps(qb1, _mm256_extractf128_ps(f1, 1));
        _mm256_store_ps(tx, _mm256_cvtepi32_ps(t.dx));
        _mm256_store_ps(ty, _mm256_cvtepi32_ps(t.dy));
        for (int c = 0; c < kTail; c++) {
            s1 += tx[c];
            s2 += ty[c];
        }
    }
    // OpenCV's reduction: (qb0 + qb1) lanes 0 and 2 to b1, lanes 1 and 3 to b2, each with zeros
    alignas(16) float q[4];
    _mm_store_ps(q, _mm_add_ps(qb0, qb1));
    s1 += (q[0] + 0.f) + (q[2] + 0.f);
    s2 += (q[1] + 0.f) + (q[3] + 0.f);
    b1 = s1 * kFltScale;
    b2 = s2 * kFltScale;
}

// the running sums of eight terms, one after the other, plus the sum before them
__attribute__((target("avx2"))) inline __m256i running8(__m256i v, __m256i before)
{
    v = _mm256_add_epi32(v, _mm256_slli_si256(v, 4));
    v = _mm256_add_epi32(v, _mm256_slli_si256(v, 8));
    const __m256i low_total = _mm256_shuffle_epi32(v, 0xff);  // terms 0..3's sum, in the upper four lanes below
    return _mm256_add_epi32(_mm256_add_epi32(v, _mm256_permute2x128_si256(low_total, low_total, 0x08)), before);
}

// mismatch's sums when every term and every partial sum along OpenCV's order is an
// integer below 2^24 in magnitude: each float addition is then exact, and integer
// sums give OpenCV's floats. False, with b1 and b2 untouched, otherwise.
__attribute__((target("avx2"))) bool mismatch_exact(const cv::Mat &img, int x, int y, const Weights &w,
                                                    const PrevWindow &pw, float &b1, float &b2)
{
    const PairWeights pwt = pair_weights(w);
    const size_t step = img.step;
    const __m256i last = _mm256_set1_epi32(7);
    __m128i sum0 = _mm_setzero_si128(), sum1 = sum0;  // OpenCV's four-lane accumulators, as integers
    __m256i sumx = _mm256_setzero_si256(), sumy = sumx;  // the tail's sums, in every lane
    // every magnitude met, or'ed: below 2^24 if and only if each is
    __m128i seen = _mm_setzero_si128();
    __m256i seen8 = _mm256_setzero_si256();
    for (int r = 0; r < kWin; r++) {
        const RowTerms t = row_terms(pixel(img, x, y + r), step, pwt, pw, r);
        const __m256i p0 = t.p0, p1 = t.p1;
        seen8 = _mm256_or_si256(seen8, _mm256_or_si256(_mm256_abs_epi32(p0), _mm256_abs_epi32(p1)));
        sum0 = _mm_add_epi32(sum0, _mm256_castsi256_si128(p0));
        sum1 = _mm_add_epi32(sum1, _mm256_castsi256_si128(p1));
        seen = _mm_or_si128(seen, _mm_or_si128(_mm_abs_epi32(sum0), _mm_abs_epi32(sum1)));
        sum0 = _mm_add_epi32(sum0, _mm256_extracti128_si256(p0, 1));
        sum1 = _mm_add_epi32(sum1, _mm256_extracti128_si256(p1, 1));
        seen = _mm_or_si128(seen, _mm_or_si128(_mm_abs_epi32(sum0), _mm_abs_epi32(sum1)));
        const __m256i px = t.dx, py = t.dy;
        const __m256i run_x = running8(px, sumx), run_y = running8(py, sumy);
        seen8 = _mm256_or_si256(seen8, _mm256_or_si256(_mm256_abs_epi32(px), _mm256_abs_epi32(py)));
        seen8 = _mm256_or_si256(seen8, _mm256_or_si256(_mm256_abs_epi32(run_x), _mm256_abs_epi32(run_y)));
        sumx = _mm256_permutevar8x32_epi32(run_x, last);
        sumy = _mm256_permutevar8x32_epi32(run_y, last);
    }
    seen = _mm_or_si128(seen, _mm_or_si128(_mm256_castsi256_si128(seen8), _mm256_extracti128_si256(seen8, 1)));
    const __m128i big = _mm_srli_epi32(seen, 24);
    if (!_mm_testz_si128(big, big)) return false;
    alignas(16) float q[4];
    _mm_store_ps(q, _mm_add_ps(_mm_cvtepi32_ps(sum0), _mm_cvtepi32_ps(sum1)));
    float s1 = static_cast<float>(_mm256_cvtsi256_si32(sumx)), s2 = static_cast<float>(_mm256_cvtsi256_si32(sumy));
    s1 += (q[0] + 0.f) + (q[2] + 0.f);
    s2 += (q[1] + 0.f) + (q[3] + 0.f);
    b1 = s1 * kFltScale;
    b2 = s2 * kFltScale;
    return true;
}

// one point at one level: LKTrackerInvoker's body for a 21x21 window
void track_point(const cv::Mat &prev, const cv::Mat &deriv, const cv::Mat &next, cv::Point2f from, cv::Point2f &to,
                 uchar &status, int level, int max_level, PrevWindow &pw)
{
    const cv::Point2f half_win((kWin - 1) * 0.5f, (kWin - 1) * 0.5f);
    cv::Point2f prev_pt = from * static_cast<float>(1. / (1 << level));
    cv::Point2f next_pt = level == max_level ? prev_pt : to * 2.f;
    to = next_pt;

    prev_pt -= half_win;
    const int px = cvFloor(prev_pt.x), py = cvFloor(prev_pt.y);
    if (px < -kWin || px >= deriv.cols || py < -kWin || py >= deriv.rows) {
        if (level == 0) status = false;
        return;
    }
    sample_prev(prev, deriv, px, py, bilinear(prev_pt.x - px, prev_pt.y - py), pw);
    const float a11 = pw.a11, a12 = pw.a12, a22 = pw.a22;
    float det = a11 * a22 - a12 * a12;
    const float min_eig =
        (a22 + a11 - std::sqrt((a11 - a22) * (a11 - a22) + 4.f * a12 * a12)) / (2 * kWin * kWin);
    if (min_eig < kMinEig || det < FLT_EPSILON) {
        if (level == 0) status = false;
        return;
    }
    det = 1.f / det;

    next_pt -= half_win;
    cv::Point2f prev_delta;
    for (int j = 0; j < kMaxCount; j++) {
        const int nx = cvFloor(next_pt.x), ny = cvFloor(next_pt.y);
        if (nx < -kWin || nx >= next.cols || ny < -kWin || ny >= next.rows) {
            if (level == 0) status = false;
            break;
        }
        float b1, b2;
        const Weights w = bilinear(next_pt.x - nx, next_pt.y - ny);
        if (!mismatch_exact(next, nx, ny, w, pw, b1, b2)) mismatch(next, nx, ny, w, pw, b1, b2);
        const cv::Point2f delta(static_cast<float>((a12 * b2 - a22 * b1) * det),
                                static_cast<float>((a12 * b1 - a11 * b2) * det));
        next_pt += delta;
        to = next_pt + half_win;
        if (delta.ddot(delta) <= kEps2) break;
        if (j > 0 && std::abs(delta.x + prev_delta.x) < 0.01 && std::abs(delta.y + prev_delta.y) < 0.01) {
            to -= delta * 0.5f;
            break;
        }
        prev_delta = delta;
    }
}

// asks for the cache lines a point's windows will read, one point ahead: the
// previous image's and derivatives' around p, the next image's around its first guess q
void prefetch_window(const cv::Mat &img, const cv::Mat &deriv, const cv::Mat &next, cv::Point2f p, cv::Point2f q)
{
    const int x = cvFloor(p.x - (kWin - 1) * 0.5f), y = cvFloor(p.y - (kWin - 1) * 0.5f);
    if (x >= -kWin && x < img.cols && y >= -kWin && y < img.rows)
        for (int r = 0; r <= kWin; r++) {
            const uchar *i = pixel(img, x, y + r);
            const short *d = deriv_pixel(deriv, x, y + r);
            __builtin_prefetch(i);
            __builtin_prefetch(i + kWin);
            __builtin_prefetch(d);
            __builtin_prefetch(d + kWin);
            __builtin_prefetch(d + 2 * kWin + 1);
        }
    if (!(std::fabs(q.x) < 1e6f && std::fabs(q.y) < 1e6f)) return;  // far outside (or NaN): never read
    const int nx = cvFloor(q.x - (kWin - 1) * 0.5f), ny = cvFloor(q.y - (kWin - 1) * 0.5f);
    if (nx >= -kWin && nx < next.cols && ny >= -kWin && ny < next.rows)
        for (int r = 0; r <= kWin; r++) {
            const uchar *j = pixel(next, nx, ny + r);
            __builtin_prefetch(j);
            __builtin_prefetch(j + kWin);
        }
}

// a level's image has the window's border around it (the loads reach into it)
bool bordered(const cv::Mat &m, cv::Size win)
{
    cv::Size whole;
    cv::Point ofs;
    m.locateROI(whole, ofs);
    return ofs.x >= win.width && ofs.y >= win.height && ofs.x + m.cols + win.width <= whole.width &&
           ofs.y + m.rows + win.height <= whole.height;
}

// calcOpticalFlowPyrLK's levels for pyramids this loop takes: prev_pyr with
// derivatives, next_pyr without; -1 for any other
int usable_levels(const std::vector<cv::Mat> &prev_pyr, const std::vector<cv::Mat> &next_pyr, cv::Size win,
                  int max_level)
{
    if (prev_pyr.size() < 2 || prev_pyr.size() % 2 != 0 || next_pyr.empty()) return -1;
    const int prev_levels = static_cast<int>(prev_pyr.size()) / 2 - 1;
    const int next_levels = static_cast<int>(next_pyr.size()) - 1;
    if (next_levels % 2 == 1 && next_pyr[1].channels() == 2) return -1;  // next with derivatives
    const int levels = std::min(max_level, std::min(prev_levels, next_levels));
    for (int l = 0; l <= levels; l++) {
        const cv::Mat &img = prev_pyr[2 * l], &deriv = prev_pyr[2 * l + 1], &next = next_pyr[l];
        if (img.type() != CV_8UC1 || deriv.type() != CV_16SC2 || next.type() != CV_8UC1) return -1;
        if (img.size() != deriv.size() || img.size() != next.size()) return -1;
        if (!bordered(img, win) || !bordered(deriv, win) || !bordered(next, win)) return -1;
    }
    return levels;
}

#endif  // GS_LK_TRACK_X86

}  // namespace

void lk_track(const std::vector<cv::Mat> &prev_pyr, const std::vector<cv::Mat> &next_pyr,
              const std::vector<cv::Point2f> &from, std::vector<cv::Point2f> &to, std::vector<uchar> &status,
              cv::Size win, int max_level)
{
#if GS_LK_TRACK_X86
    const int levels = win == cv::Size(kWin, kWin) && have_avx2() && max_level >= 0 && !from.empty()
                           ? usable_levels(prev_pyr, next_pyr, win, max_level)
                           : -1;
    if (levels >= 0) {
        to.resize(from.size());
        status.assign(from.size(), 1);
        PrevWindow pw;
        for (int level = levels; level >= 0; level--)
            for (size_t i = 0; i < from.size(); i++) {
                if (i + 1 < from.size()) {
                    const cv::Point2f p = from[i + 1] * static_cast<float>(1. / (1 << level));
                    prefetch_window(prev_pyr[2 * level], prev_pyr[2 * level + 1], next_pyr[level], p,
                                    level == levels ? p : to[i + 1] * 2.f);
                }
                track_point(prev_pyr[2 * level], prev_pyr[2 * level + 1], next_pyr[level], from[i], to[i],
                            status[i], level, levels, pw);
            }
        return;
    }
#endif
    opencv_track(prev_pyr, next_pyr, from, to, status, win, max_level);
}

}  // namespace gs
