// camera_motion.cpp - background corners tracked by pyramidal Lucas-Kanade,
// a RANSAC similarity per frame pair, chained to the first frame.
#include "camera_motion.hpp"
#include "cpu_avx2.hpp"
#include "lk_track.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace gs {

namespace {

cv::Matx23d compose(const cv::Matx23d &a, const cv::Matx23d &b)  // a after b
{
    cv::Matx33d A(a(0, 0), a(0, 1), a(0, 2), a(1, 0), a(1, 1), a(1, 2), 0, 0, 1);
    cv::Matx33d B(b(0, 0), b(0, 1), b(0, 2), b(1, 0), b(1, 1), b(1, 2), 0, 0, 1);
    cv::Matx33d C = A * B;
    return cv::Matx23d(C(0, 0), C(0, 1), C(0, 2), C(1, 0), C(1, 1), C(1, 2));
}

cv::Point2d apply(const cv::Matx23d &m, cv::Point2d p)
{
    return {m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2), m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2)};
}

// OpenCV's area table along one axis (resize.cpp, computeResizeAreaTab): for
// each output index, the source indices and weights in the order it sums them
struct AreaTab {
    std::vector<int> first;   // entries of output i: [first[i], first[i + 1])
    std::vector<int> src;
    std::vector<float> alpha;
};

AreaTab area_tab(int ssize, int dsize, double scale)
{
    AreaTab t;
    for (int dx = 0; dx < dsize; dx++) {
        t.first.push_back(static_cast<int>(t.src.size()));
        double fsx1 = dx * scale;
        double fsx2 = fsx1 + scale;
        double cell = std::min(scale, ssize - fsx1);
        int sx1 = cvCeil(fsx1), sx2 = cvFloor(fsx2);
        sx2 = std::min(sx2, ssize - 1);
        sx1 = std::min(sx1, sx2);
        if (sx1 - fsx1 > 1e-3) {
            t.src.push_back(sx1 - 1);
            t.alpha.push_back(static_cast<float>((sx1 - fsx1) / cell));
        }
        for (int sx = sx1; sx < sx2; sx++) {
            t.src.push_back(sx);
            t.alpha.push_back(static_cast<float>(1.0 / cell));
        }
        if (fsx2 - sx2 > 1e-3) {
            t.src.push_back(sx2);
            t.alpha.push_back(static_cast<float>(std::min(std::min(fsx2 - sx2, 1.), cell) / cell));
        }
    }
    t.first.push_back(static_cast<int>(t.src.size()));
    return t;
}

bool inside_any(const std::vector<cv::Rect> &rs, cv::Point2f p)
{
    for (const cv::Rect &r : rs)
        if (r.contains(cv::Point((int)p.x, (int)p.y))) return true;
    return false;
}

}  // namespace

namespace {

#if defined(__SSE2__) && !defined(__FMA__)
constexpr bool kExactAreaSums = true;
#else
constexpr bool kExactAreaSums = false;
#endif

// one source row (as floats) summed across into the w output columns, k weights each
template <int K>
inline void sum_across(const float *row, const int *ix, const float *al, int w, float *buf)
{
    for (int dx = 0; dx < w; dx++, ix += K, al += K) {
        float v = 0.0f;
        for (int e = 0; e < K; e++) v += row[ix[e]] * al[e];
        buf[dx] = v;
    }
}

// two entries per output column: where four columns in a row take four source
// columns in a row and the four after them (a reduction by less than 2, such as
// 720 -> 640 px), the same products and sums four at a time (run[q]: the first
// source column of group q, -1 where the group does not follow that pattern)
inline void sum_across_2(const float *row, const int *ix, const float *al, const float *al0, const float *al1,
                         const int *run, int w, float *buf)
{
    int dx = 0;
#ifdef __SSE2__
    for (int q = 0; dx + 4 <= w; q++, dx += 4) {
        if (run[q] >= 0) {
            const __m128 p0 = _mm_mul_ps(_mm_loadu_ps(row + run[q]), _mm_loadu_ps(al0 + dx));
            const __m128 p1 = _mm_mul_ps(_mm_loadu_ps(row + run[q] + 1), _mm_loadu_ps(al1 + dx));
            _mm_storeu_ps(buf + dx, _mm_add_ps(p0, p1));
        } else {
            sum_across<2>(row, ix + 2 * dx, al + 2 * dx, 4, buf + dx);
        }
    }
#else
    (void)al0;
    (void)al1;
    (void)run;
#endif
    sum_across<2>(row, ix + 2 * dx, al + 2 * dx, w - dx, buf + dx);
}

inline void sum_across_k(const float *row, const int *ix, const float *al, int w, int k, float *buf)
{
    for (int dx = 0; dx < w; dx++, ix += k, al += k) {
        float v = 0.0f;
        for (int e = 0; e < k; e++) v += row[ix[e]] * al[e];
        buf[dx] = v;
    }
}

}  // namespace

namespace {

// cv::resize's INTER_AREA by a factor of at least 1 on both axes, not whole on
// both (resize.cpp, resizeArea): 8-bit, any number of channels
void area_reduce(const cv::Mat &src, cv::Mat &dst, cv::Size ds, double scale_x, double scale_y)
{
    const int cn = src.channels();
    const AreaTab xt = area_tab(src.cols, ds.width, scale_x), yt = area_tab(src.rows, ds.height, scale_y);
    // the entries of one output column padded to k with weight 0: adding S x 0 = +0 leaves a sum >= 0 as it is
    int k = 0;
    for (int dx = 0; dx < ds.width; dx++) k = std::max(k, xt.first[dx + 1] - xt.first[dx]);
    // output value j = dx * cn + c (channels interleaved) sums channel c of its source columns
    const int w = ds.width * cn;
    std::vector<int> xi(static_cast<size_t>(k) * w);
    std::vector<float> xa(xi.size(), 0.0f);
    for (int dx = 0; dx < ds.width; dx++) {
        const int a = xt.first[dx], n = xt.first[dx + 1] - a;
        for (int c = 0; c < cn; c++) {
            const size_t j = static_cast<size_t>(dx) * cn + c;
            for (int e = 0; e < k; e++) {
                xi[j * k + e] = xt.src[a + std::min(e, n - 1)] * cn + c;
                if (e < n) xa[j * k + e] = xt.alpha[a + e];
            }
        }
    }
    std::vector<float> xa0(w), xa1(w);
    std::vector<int> run(static_cast<size_t>(w / 4), -1);
    if (k == 2) {
        for (int dx = 0; dx < w; dx++) {
            xa0[dx] = xa[2 * static_cast<size_t>(dx)];
            xa1[dx] = xa[2 * static_cast<size_t>(dx) + 1];
        }
        for (size_t q = 0; q < run.size(); q++) {
            const int *ix = &xi[8 * q];
            bool in_row = true;
            for (int l = 0; l < 4; l++) in_row = in_row && ix[2 * l] == ix[0] + l && ix[2 * l + 1] == ix[0] + l + 1;
            if (in_row) run[q] = ix[0];
        }
    }
    cv::Mat out = dst.data == src.data ? cv::Mat() : dst;  // dst's own memory unless it is src's
    out.create(ds, src.type());
    const int src_w = src.cols * cn;
    std::vector<float> row(src_w), buf(w), sum(w);
    int buf_row = -1;
    for (int dy = 0; dy < ds.height; dy++) {
        for (int j = yt.first[dy]; j < yt.first[dy + 1]; j++) {
            const int sy = yt.src[j];
            if (sy != buf_row) {  // a source row shared by two output rows is summed across once
                const uchar *S = src.ptr<uchar>(sy);
                int x = 0;
#ifdef __SSE2__
                const __m128i z = _mm_setzero_si128();
                for (; x + 16 <= src_w; x += 16) {
                    __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i *>(S + x));
                    __m128i lo = _mm_unpacklo_epi8(v, z), hi = _mm_unpackhi_epi8(v, z);
                    _mm_storeu_ps(&row[x], _mm_cvtepi32_ps(_mm_unpacklo_epi16(lo, z)));
                    _mm_storeu_ps(&row[x + 4], _mm_cvtepi32_ps(_mm_unpackhi_epi16(lo, z)));
                    _mm_storeu_ps(&row[x + 8], _mm_cvtepi32_ps(_mm_unpacklo_epi16(hi, z)));
                    _mm_storeu_ps(&row[x + 12], _mm_cvtepi32_ps(_mm_unpackhi_epi16(hi, z)));
                }
#endif
                for (; x < src_w; x++) row[x] = S[x];
                if (k == 3)
                    sum_across<3>(row.data(), xi.data(), xa.data(), w, buf.data());
                else if (k == 4)
                    sum_across<4>(row.data(), xi.data(), xa.data(), w, buf.data());
                else if (k == 2)
                    sum_across_2(row.data(), xi.data(), xa.data(), xa0.data(), xa1.data(), run.data(), w, buf.data());
                else
                    sum_across_k(row.data(), xi.data(), xa.data(), w, k, buf.data());
                buf_row = sy;
            }
            const float beta = yt.alpha[j];
            int dx = 0;
            if (j == yt.first[dy]) {
#ifdef __SSE2__
                const __m128 b4 = _mm_set1_ps(beta);
                for (; dx + 4 <= w; dx += 4) _mm_storeu_ps(&sum[dx], _mm_mul_ps(b4, _mm_loadu_ps(&buf[dx])));
#endif
                for (; dx < w; dx++) sum[dx] = beta * buf[dx];
            } else {
#ifdef __SSE2__
                const __m128 b4 = _mm_set1_ps(beta);
                for (; dx + 4 <= w; dx += 4)
                    _mm_storeu_ps(&sum[dx], _mm_add_ps(_mm_loadu_ps(&sum[dx]), _mm_mul_ps(b4, _mm_loadu_ps(&buf[dx]))));
#endif
                for (; dx < w; dx++) sum[dx] += beta * buf[dx];
            }
        }
        uchar *D = out.ptr<uchar>(dy);
        int dx = 0;
#ifdef __SSE2__
        // cvRound's rounding (to nearest, ties to even) and saturation, 8 at a time
        for (; dx + 8 <= w; dx += 8) {
            __m128i a = _mm_cvtps_epi32(_mm_loadu_ps(&sum[dx])), b = _mm_cvtps_epi32(_mm_loadu_ps(&sum[dx + 4]));
            _mm_storel_epi64(reinterpret_cast<__m128i *>(D + dx), _mm_packus_epi16(_mm_packs_epi32(a, b), a));
        }
#endif
        for (; dx < w; dx++) D[dx] = cv::saturate_cast<uchar>(sum[dx]);
    }
    dst = out;
}

}  // namespace

void resize_area_grey(const cv::Mat &src, cv::Mat &dst, double f)
{
    CV_Assert(src.type() == CV_8UC1 && f > 0.0 && f <= 1.0);
    // cv::resize's output size and its scale (from f, not from the sizes)
    cv::Size ds(cv::saturate_cast<int>(src.cols * f), cv::saturate_cast<int>(src.rows * f));
    const double scale = 1.0 / f;
    const int iscale = cv::saturate_cast<int>(scale);
    // OpenCV's own path: a copy, a whole factor, or a CPU whose compiler may fuse a
    // multiply and an add (FMA), which rounds once where OpenCV's sums round twice
    if (!kExactAreaSums || ds == src.size() || std::abs(scale - iscale) < DBL_EPSILON || ds.width <= 0 ||
        ds.height <= 0) {
        cv::resize(src, dst, cv::Size(), f, f, cv::INTER_AREA);
        return;
    }
    area_reduce(src, dst, ds, scale, scale);
}

void resize_area(const cv::Mat &src, cv::Mat &dst, cv::Size ds)
{
    // cv::resize's scales for a given size, and the cases it does not reduce by area sums
    const double sx = 1.0 / (static_cast<double>(ds.width) / src.cols);
    const double sy = 1.0 / (static_cast<double>(ds.height) / src.rows);
    const bool whole = std::abs(sx - cv::saturate_cast<int>(sx)) < DBL_EPSILON &&
                       std::abs(sy - cv::saturate_cast<int>(sy)) < DBL_EPSILON;
    if (!kExactAreaSums || src.depth() != CV_8U || src.empty() || ds.width <= 0 || ds.height <= 0 || !(sx >= 1.0) ||
        !(sy >= 1.0) || whole) {
        cv::resize(src, dst, ds, 0, 0, cv::INTER_AREA);
        return;
    }
    area_reduce(src, dst, ds, sx, sy);
}

namespace {

#if defined(__SSE2__) && !defined(__FMA__)
constexpr bool kExactEigen = true;  // no fused multiply-add: the floats round as OpenCV's do
#else
constexpr bool kExactEigen = false;
#endif

inline int reflect101(int i, int n)
{
    if (n == 1) return 0;
    while (i < 0 || i >= n) i = i < 0 ? -i : 2 * n - 2 - i;
    return i;
}

// the box's row sums of one row of products, in double, in OpenCV's order (RowSum)
void box_row_scalar(const float *S, int w, int block, double *D)
{
    if (block == 3)
        for (int i = 0; i < w; i++) D[i] = (double)S[i] + (double)S[i + 1] + (double)S[i + 2];
    else
        for (int i = 0; i < w; i++)
            D[i] = (double)S[i] + (double)S[i + 1] + (double)S[i + 2] + (double)S[i + 3] + (double)S[i + 4];
}

void products_scalar(const float *X, const float *Y, int w, float *A, float *B, float *C)
{
    for (int x = 0; x < w; x++) {
        const float gx = X[x], gy = Y[x];
        A[x] = gx * gx;
        B[x] = gx * gy;
        C[x] = gy * gy;
    }
}

// one output row: the column's running sums (ColumnSum) and the smaller eigenvalue (calcMinEigenVal)
// (columns from `from` on: the planes stay w apart, so a vector loop's tail starts here)
void column_eigen_scalar(double *sum, const double *P, const double *M, int w, float *E, int from = 0)
{
    double *sa = sum, *sb = sum + w, *sc = sum + 2 * w;
    const double *pa = P, *pb = P + w, *pc = P + 2 * w, *ma = M, *mb = M + w, *mc = M + 2 * w;
    for (int i = from; i < w; i++) {
        const double s0a = sa[i] + pa[i], s0b = sb[i] + pb[i], s0c = sc[i] + pc[i];
        const float a = (float)s0a * 0.5f, b = (float)s0b, c = (float)s0c * 0.5f;
        sa[i] = s0a - ma[i];
        sb[i] = s0b - mb[i];
        sc[i] = s0c - mc[i];
        const float t = a - c;
        E[i] = (a + c) - std::sqrt(t * t + b * b);
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
#define GS_EIGEN_AVX2 1
// the same sums, 4 doubles at a time (no FMA: every product and sum rounds as above)
__attribute__((target("avx2"))) void box_row_avx2(const float *S, int w, int block, double *D)
{
    int i = 0;
    for (; i + 4 <= w; i += 4) {
        __m256d v = _mm256_add_pd(_mm256_cvtps_pd(_mm_loadu_ps(S + i)), _mm256_cvtps_pd(_mm_loadu_ps(S + i + 1)));
        v = _mm256_add_pd(v, _mm256_cvtps_pd(_mm_loadu_ps(S + i + 2)));
        if (block == 5) {
            v = _mm256_add_pd(v, _mm256_cvtps_pd(_mm_loadu_ps(S + i + 3)));
            v = _mm256_add_pd(v, _mm256_cvtps_pd(_mm_loadu_ps(S + i + 4)));
        }
        _mm256_storeu_pd(D + i, v);
    }
    if (i < w) box_row_scalar(S + i, w - i, block, D + i);
}

__attribute__((target("avx2"))) void products_avx2(const float *X, const float *Y, int w, float *A, float *B, float *C)
{
    int x = 0;
    for (; x + 8 <= w; x += 8) {
        const __m256 gx = _mm256_loadu_ps(X + x), gy = _mm256_loadu_ps(Y + x);
        _mm256_storeu_ps(A + x, _mm256_mul_ps(gx, gx));
        _mm256_storeu_ps(B + x, _mm256_mul_ps(gx, gy));
        _mm256_storeu_ps(C + x, _mm256_mul_ps(gy, gy));
    }
    if (x < w) products_scalar(X + x, Y + x, w - x, A + x, B + x, C + x);
}

__attribute__((target("avx2"))) void column_eigen_avx2(double *sum, const double *P, const double *M, int w, float *E)
{
    double *sa = sum, *sb = sum + w, *sc = sum + 2 * w;
    const double *pa = P, *pb = P + w, *pc = P + 2 * w, *ma = M, *mb = M + w, *mc = M + 2 * w;
    const __m128 half = _mm_set1_ps(0.5f);
    int i = 0;
    for (; i + 4 <= w; i += 4) {
        const __m256d s0a = _mm256_add_pd(_mm256_loadu_pd(sa + i), _mm256_loadu_pd(pa + i));
        const __m256d s0b = _mm256_add_pd(_mm256_loadu_pd(sb + i), _mm256_loadu_pd(pb + i));
        const __m256d s0c = _mm256_add_pd(_mm256_loadu_pd(sc + i), _mm256_loadu_pd(pc + i));
        _mm256_storeu_pd(sa + i, _mm256_sub_pd(s0a, _mm256_loadu_pd(ma + i)));
        _mm256_storeu_pd(sb + i, _mm256_sub_pd(s0b, _mm256_loadu_pd(mb + i)));
        _mm256_storeu_pd(sc + i, _mm256_sub_pd(s0c, _mm256_loadu_pd(mc + i)));
        const __m128 a = _mm_mul_ps(_mm256_cvtpd_ps(s0a), half), b = _mm256_cvtpd_ps(s0b);
        const __m128 c = _mm_mul_ps(_mm256_cvtpd_ps(s0c), half), t = _mm_sub_ps(a, c);
        const __m128 q = _mm_add_ps(_mm_mul_ps(t, t), _mm_mul_ps(b, b));
        _mm_storeu_ps(E + i, _mm_sub_ps(_mm_add_ps(a, c), _mm_sqrt_ps(q)));
    }
    column_eigen_scalar(sum, P, M, w, E, i);
}

#endif

// the x in [x0, x1) where E[x] > thr and E[x] != 0 (a corner's first test), into xs; their count
int above_scalar(const float *E, int x0, int x1, float thr, int *xs)
{
    int n = 0;
    for (int x = x0; x < x1; x++)
        if (E[x] > thr && E[x] != 0.0f) xs[n++] = x;
    return n;
}

#ifdef GS_EIGEN_AVX2
__attribute__((target("avx2"))) int above_avx2(const float *E, int x0, int x1, float thr, int *xs)
{
    const __m256 t = _mm256_set1_ps(thr), z = _mm256_setzero_ps();
    int n = 0, x = x0;
    for (; x + 8 <= x1; x += 8) {
        const __m256 v = _mm256_loadu_ps(E + x);
        unsigned bits = static_cast<unsigned>(_mm256_movemask_ps(
            _mm256_and_ps(_mm256_cmp_ps(v, t, _CMP_GT_OQ), _mm256_cmp_ps(v, z, _CMP_NEQ_OQ))));
        while (bits) {
            xs[n++] = x + __builtin_ctz(bits);
            bits &= bits - 1;
        }
    }
    return n + above_scalar(E, x, x1, thr, xs + n);
}
#endif

// the largest of best and each E[x], x in [x0, w), where M[x] != 0 (M null: every x)
float row_max_scalar(const float *E, const uchar *M, int x0, int w, float best)
{
    for (int x = x0; x < w; x++)
        if ((!M || M[x]) && E[x] > best) best = E[x];
    return best;
}

#ifdef GS_EIGEN_AVX2
__attribute__((target("avx2"))) float row_max_avx2(const float *E, const uchar *M, int w, float best)
{
    __m256 acc = _mm256_set1_ps(best);
    int x = 0;
    for (; x + 8 <= w; x += 8) {
        __m256 v = _mm256_loadu_ps(E + x);
        if (M) {  // lanes outside the mask keep the maximum so far
            const __m256i m = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i *>(M + x)));
            v = _mm256_blendv_ps(v, acc, _mm256_castsi256_ps(_mm256_cmpeq_epi32(m, _mm256_setzero_si256())));
        }
        acc = _mm256_max_ps(acc, v);
    }
    float lanes[8];
    _mm256_storeu_ps(lanes, acc);
    for (float l : lanes) best = std::max(best, l);
    return row_max_scalar(E, M, x, w, best);
}
#endif

// cv::minMaxLoc(eig, nullptr, &max, nullptr, nullptr, mask)'s maximum: the largest
// eigenvalue under the mask, 0 when the mask is empty
double masked_max(const cv::Mat &eig, const cv::Mat &mask)
{
    float best = -FLT_MAX;
    for (int y = 0; y < eig.rows; y++) {
        const float *E = eig.ptr<float>(y);
        const uchar *M = mask.empty() ? nullptr : mask.ptr<uchar>(y);
#ifdef GS_EIGEN_AVX2
        if (have_avx2()) {
            best = row_max_avx2(E, M, eig.cols, best);
            continue;
        }
#endif
        best = row_max_scalar(E, M, 0, eig.cols, best);
    }
    return best == -FLT_MAX ? 0.0 : best;
}

// cv::cornerMinEigenVal(src, eig, block, 3, BORDER_DEFAULT) with the same floats:
// OpenCV's Sobel, then the products' unnormalised box sums (double, BORDER_REFLECT_101)
// and the smaller eigenvalue of each 2x2 sum
void min_eigen(const cv::Mat &src, int block, CornerWork &wk)
{
    const double scale = 1.0 / ((1 << 2) * block * 255.0);
    cv::Sobel(src, wk.dx, CV_32F, 1, 0, 3, scale, 0, cv::BORDER_DEFAULT);
    cv::Sobel(src, wk.dy, CV_32F, 0, 1, 3, scale, 0, cv::BORDER_DEFAULT);
    const int w = src.cols, h = src.rows, r = block / 2, bw = w + 2 * r;
    wk.eig.create(h, w, CV_32F);
    // the running sums (3 planes of w), block rows of row sums (3 planes each), one bordered row of products
    const size_t plane = static_cast<size_t>(w);
    wk.box.resize(3 * plane * (block + 1) + (3 * static_cast<size_t>(bw) + 1) / 2 + 1);
    double *sum = wk.box.data();
    double *rows = sum + 3 * plane;
    float *prod = reinterpret_cast<float *>(rows + 3 * plane * block);
    float *A = prod, *B = prod + bw, *C = prod + 2 * bw;
#ifdef GS_EIGEN_AVX2
    const bool avx2 = have_avx2();
#endif
    auto row_sums = [&](int j, double *out) {  // bordered row j, -r .. h - 1 + r
        const int y = reflect101(j, h);
        const float *X = wk.dx.ptr<float>(y), *Y = wk.dy.ptr<float>(y);
#ifdef GS_EIGEN_AVX2
        if (avx2)
            products_avx2(X, Y, w, A + r, B + r, C + r);
        else
#endif
            products_scalar(X, Y, w, A + r, B + r, C + r);
        for (int k = 1; k <= r; k++) {  // BORDER_REFLECT_101 across
            const int lx = reflect101(-k, w) + r, rx = reflect101(w - 1 + k, w) + r;
            A[r - k] = A[lx], B[r - k] = B[lx], C[r - k] = C[lx];
            A[w - 1 + k + r] = A[rx], B[w - 1 + k + r] = B[rx], C[w - 1 + k + r] = C[rx];
        }
        for (int ch = 0; ch < 3; ch++) {
#ifdef GS_EIGEN_AVX2
            if (avx2) {
                box_row_avx2(prod + ch * bw, w, block, out + ch * plane);
                continue;
            }
#endif
            box_row_scalar(prod + ch * bw, w, block, out + ch * plane);
        }
    };
    auto slot = [&](int j) { return rows + 3 * plane * static_cast<size_t>((j + r) % block); };
    std::fill(sum, sum + 3 * plane, 0.0);
    for (int j = -r; j < r; j++) {  // the first block - 1 rows
        double *R = slot(j);
        row_sums(j, R);
        for (size_t i = 0; i < 3 * plane; i++) sum[i] += R[i];
    }
    for (int y = 0; y < h; y++) {
        double *P = slot(y + r);
        row_sums(y + r, P);
        const double *M = slot(y - r);  // another slot than P's: the block holds 2r + 1 rows
        float *E = wk.eig.ptr<float>(y);
#ifdef GS_EIGEN_AVX2
        if (avx2) {
            column_eigen_avx2(sum, P, M, w, E);
            continue;
        }
#endif
        column_eigen_scalar(sum, P, M, w, E);
    }
}

}  // namespace

void good_features(const cv::Mat &img, std::vector<cv::Point2f> &corners, int max_corners, double quality,
                   double min_distance, const cv::Mat &mask, int block, CornerWork &wk)
{
    if (!kExactEigen || (block != 3 && block != 5) || img.type() != CV_8UC1 || img.rows < 2 || img.cols < 2) {
        cv::goodFeaturesToTrack(img, corners, max_corners, quality, min_distance, mask, block);
        return;
    }
    corners.clear();
    min_eigen(img, block, wk);
    const cv::Mat &eig = wk.eig;
    const double max_val = masked_max(eig, mask);
    const float thr = static_cast<float>(max_val * quality);
    const int w = img.cols, h = img.rows;
    // local maxima of the image thresholded to zero (cv::threshold, cv::dilate 3x3), inside the border
    std::vector<const float *> &cand = wk.cand;
    cand.clear();
    auto kept = [thr](float v) { return v > thr ? v : 0.0f; };
    wk.xs.resize(static_cast<size_t>(w));
    for (int y = 1; y < h - 1; y++) {
        const float *E0 = eig.ptr<float>(y - 1), *E1 = eig.ptr<float>(y), *E2 = eig.ptr<float>(y + 1);
        const uchar *M = mask.empty() ? nullptr : mask.ptr<uchar>(y);
        int n;
#ifdef GS_EIGEN_AVX2
        if (have_avx2())
            n = above_avx2(E1, 1, w - 1, thr, wk.xs.data());
        else
#endif
            n = above_scalar(E1, 1, w - 1, thr, wk.xs.data());
        for (int i = 0; i < n; i++) {
            const int x = wk.xs[i];
            const float v = E1[x];
            if (M && !M[x]) continue;
            float m = v;
            for (int k = -1; k <= 1; k++)
                m = std::max(m, std::max(kept(E0[x + k]), std::max(kept(E1[x + k]), kept(E2[x + k]))));
            if (v == m) cand.push_back(E1 + x);
        }
    }
    if (cand.empty()) return;
    // OpenCV's order (greaterThanPtr): the larger value first, of equal values the later address
    auto below = [](const float *a, const float *b) { return *a < *b || (*a == *b && a < b); };
    std::make_heap(cand.begin(), cand.end(), below);
    size_t left = cand.size();
    auto next = [&](int *x, int *y) {
        std::pop_heap(cand.begin(), cand.begin() + left, below);
        const size_t ofs = static_cast<size_t>(reinterpret_cast<const uchar *>(cand[--left]) - eig.ptr());
        *y = static_cast<int>(ofs / eig.step);
        *x = static_cast<int>((ofs - *y * eig.step) / sizeof(float));
    };
    if (min_distance < 1) {
        while (left > 0 && (max_corners <= 0 || (int)corners.size() < max_corners)) {
            int x, y;
            next(&x, &y);
            corners.push_back(cv::Point2f((float)x, (float)y));
        }
        return;
    }
    const int cell = cvRound(min_distance);
    const int gw = (w + cell - 1) / cell, gh = (h + cell - 1) / cell;
    std::vector<std::vector<cv::Point2f>> &grid = wk.grid;
    if (grid.size() < static_cast<size_t>(gw) * gh) grid.resize(static_cast<size_t>(gw) * gh);
    const double md2 = min_distance * min_distance;
    while (left > 0) {
        int x, y;
        next(&x, &y);
        const int xc = x / cell, yc = y / cell;
        const int x1 = std::max(0, xc - 1), y1 = std::max(0, yc - 1);
        const int x2 = std::min(gw - 1, xc + 1), y2 = std::min(gh - 1, yc + 1);
        bool good = true;
        for (int yy = y1; yy <= y2 && good; yy++)
            for (int xx = x1; xx <= x2 && good; xx++)
                for (const cv::Point2f &q : grid[static_cast<size_t>(yy) * gw + xx]) {
                    const float ddx = x - q.x, ddy = y - q.y;
                    if (ddx * ddx + ddy * ddy < md2) {
                        good = false;
                        break;
                    }
                }
        if (!good) continue;
        grid[static_cast<size_t>(yc) * gw + xc].push_back(cv::Point2f((float)x, (float)y));
        corners.push_back(cv::Point2f((float)x, (float)y));
        if (max_corners > 0 && (int)corners.size() == max_corners) break;
    }
    for (const cv::Point2f &p : corners) grid[static_cast<size_t>(static_cast<int>(p.y) / cell) * gw + static_cast<int>(p.x) / cell].clear();
}

namespace {

constexpr int kDerivSpan = 8;  // columns of a row whose derivatives are computed, and remembered, together

// the row or column Scharr takes beyond an image's edge (lkpyramid.cpp: reflect-101, 0 for one pixel)
inline int scharr_neighbour(int i, int n)
{
    if (i < 0) return n > 1 ? 1 : 0;
    if (i >= n) return n > 1 ? n - 2 : 0;
    return i;
}

}  // namespace

void LkDerivatives::reset(const std::vector<cv::Mat> &levels, cv::Size win)
{
    win_ = win;
    const size_t n = levels.size();
    bordered_.resize(n);
    done_.resize(n);
    whole_.assign(n, 0);
    pyr_.resize(2 * n);
    for (size_t l = 0; l < n; l++) {
        const cv::Mat &img = levels[l];
        cv::Mat &d = bordered_[l];
        const cv::Size whole(img.cols + 2 * win.width, img.rows + 2 * win.height);
        if (d.size() != whole || d.type() != CV_16SC2) {
            d.create(whole, CV_16SC2);
            d.setTo(cv::Scalar::all(0));  // the border stays zero (buildOpticalFlowPyramid's BORDER_CONSTANT)
        }
        pyr_[2 * l] = img;
        pyr_[2 * l + 1] = d(cv::Rect(win.width, win.height, img.cols, img.rows));
        const int spans = (img.cols + kDerivSpan - 1) / kDerivSpan;
        done_[l].assign(static_cast<size_t>(spans) * img.rows, 0);
    }
}

void LkDerivatives::cover(const std::vector<cv::Point2f> &pts)
{
    for (int l = 0; l < static_cast<int>(done_.size()); l++) cover_level(l, pts);
}

void LkDerivatives::cover_level(int level, const std::vector<cv::Point2f> &pts)
{
    if (whole_[level]) return;
    const int w = pyr_[2 * level].cols, h = pyr_[2 * level].rows;
    const int spans = (w + kDerivSpan - 1) / kDerivSpan;
    std::vector<uchar> &done = done_[level];
    // windows that would cover 30 % of a level or more (the coarse ones): all of it in one
    // pass, row after row, costs less than the windows' rows one by one
    const double windows = static_cast<double>(pts.size()) * (win_.width + 3) * (win_.height + 3);
    if (windows >= 0.3 * w * h) {
        fill(level, 0, w, 0, h);
        whole_[level] = 1;
        return;
    }
    // LKTrackerInvoker's window at this level: the point scaled, less half the window, floored;
    // it reads the window and one column to the right and one row below (the bilinear taps)
    const float to_level = static_cast<float>(1. / (1 << level));
    const cv::Point2f half_win((win_.width - 1) * 0.5f, (win_.height - 1) * 0.5f);
    for (const cv::Point2f &p : pts) {
        const cv::Point2f q = p * to_level - half_win;
        if (!(std::fabs(q.x) < 1e6f && std::fabs(q.y) < 1e6f)) continue;  // far outside (or NaN): never read
        const int ix = cvFloor(q.x), iy = cvFloor(q.y);
        // a pixel more than read on each side, so that no rounding can leave one out
        const int x0 = std::max(ix - 1, 0), x1 = std::min(ix + win_.width + 1, w - 1);
        const int y0 = std::max(iy - 1, 0), y1 = std::min(iy + win_.height + 1, h - 1);
        if (x0 > x1 || y0 > y1) continue;
        const int s_first = x0 / kDerivSpan, s_last = x1 / kDerivSpan;
        for (int y = y0; y <= y1; y++) {
            uchar *row = &done[static_cast<size_t>(y) * spans];
            for (int s = s_first; s <= s_last;) {
                if (row[s]) {
                    s++;
                    continue;
                }
                int end = s;  // the run of spans not yet computed, computed at once
                while (end <= s_last && !row[end]) row[end++] = 1;
                fill(level, s * kDerivSpan, std::min(end * kDerivSpan, w), y, y + 1);
                s = end;
            }
        }
    }
}

// OpenCV's Scharr derivatives (lkpyramid.cpp, ScharrDerivInvoker) of columns
// [x0, x1) and rows [y0, y1) of one level: per column 3a + 10b + 3c and c - a
// down the rows above, at and below, then across the same for the columns left
// and right, in 16-bit integers, stored as (dx, dy) pairs
void LkDerivatives::fill(int level, int x0, int x1, int y0, int y1)
{
    const cv::Mat &img = pyr_[2 * level];
    cv::Mat &deriv = pyr_[2 * level + 1];
    const int w = img.cols, h = img.rows;
    for (int y = y0; y < y1; y++) {
        const uchar *a = img.ptr<uchar>(scharr_neighbour(y - 1, h)), *b = img.ptr<uchar>(y);
        const uchar *c = img.ptr<uchar>(scharr_neighbour(y + 1, h));
        short *d = deriv.ptr<short>(y);
        auto smooth = [&](int x) { return (a[x] + c[x]) * 3 + b[x] * 10; };
        auto diff = [&](int x) { return c[x] - a[x]; };
        auto one = [&](int x) {  // one column (the edges' and those the 8-column steps leave)
            const int l = scharr_neighbour(x - 1, w), r = scharr_neighbour(x + 1, w);
            d[2 * x] = static_cast<short>(smooth(r) - smooth(l));
            d[2 * x + 1] = static_cast<short>((diff(r) + diff(l)) * 3 + diff(x) * 10);
        };
        int x = x0;
        for (; x < std::min(x1, 1); x++) one(x);
#ifdef __SSE2__
        // 8 columns at a time, their neighbours' sums from loads one column to each side
        // (in registers: a row of sums stored and read back unaligned stalls on the store)
        const __m128i z = _mm_setzero_si128(), c3 = _mm_set1_epi16(3), c10 = _mm_set1_epi16(10);
        auto load8 = [z](const uchar *p) {
            return _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i *>(p)), z);
        };
        for (; x + 8 <= std::min(x1, w - 1); x += 8) {
            const __m128i al = load8(a + x - 1), am = load8(a + x), ar = load8(a + x + 1);
            const __m128i bl = load8(b + x - 1), br = load8(b + x + 1);
            const __m128i cl = load8(c + x - 1), cm = load8(c + x), cr = load8(c + x + 1);
            const __m128i sl = _mm_add_epi16(_mm_mullo_epi16(_mm_add_epi16(al, cl), c3), _mm_mullo_epi16(bl, c10));
            const __m128i sr = _mm_add_epi16(_mm_mullo_epi16(_mm_add_epi16(ar, cr), c3), _mm_mullo_epi16(br, c10));
            const __m128i side = _mm_add_epi16(_mm_sub_epi16(cl, al), _mm_sub_epi16(cr, ar));
            const __m128i dx = _mm_sub_epi16(sr, sl);
            const __m128i dy = _mm_add_epi16(_mm_mullo_epi16(side, c3), _mm_mullo_epi16(_mm_sub_epi16(cm, am), c10));
            _mm_storeu_si128(reinterpret_cast<__m128i *>(d + 2 * x), _mm_unpacklo_epi16(dx, dy));
            _mm_storeu_si128(reinterpret_cast<__m128i *>(d + 2 * x + 8), _mm_unpackhi_epi16(dx, dy));
        }
#endif
        for (; x < x1; x++) one(x);
    }
}

CameraMotion::CameraMotion(const CameraMotionConfig &cfg) : cfg_(cfg), cur_from_ref_(1, 0, 0, 0, 1, 0) {}

void CameraMotion::process(const cv::Mat &bgr, const std::vector<cv::Rect> &exclude, CameraMotionFrame *out)
{
    *out = CameraMotionFrame();
    if (bgr.empty()) return;
    if (full_ != bgr.size()) {  // a new stream: start over
        full_ = bgr.size();
        have_ = false;
        pts_.clear();
        cur_from_ref_ = cv::Matx23d(1, 0, 0, 0, 1, 0);
    }
    frames_++;
    scale_ = std::min(1.0, cfg_.work_width_px / bgr.cols);
    // the working images and pyramids reuse their memory from frame to frame
    const cv::Mat *grey = &bgr;
    if (bgr.channels() == 3) {
        cv::cvtColor(bgr, grey_, cv::COLOR_BGR2GRAY);
        grey = &grey_;
    }
    cv::Mat &cur = cur_;
    if (scale_ < 1.0)
        resize_area_grey(*grey, cur, scale_);
    else
        grey->copyTo(cur);

    // subjects' regions at the working scale, grown by a margin (limbs swing out of boxes)
    std::vector<cv::Rect> ex;
    for (const cv::Rect &r : exclude) {
        int m = (int)std::lround(0.15 * std::max(r.width, r.height) * scale_) + 4;
        ex.push_back(cv::Rect((int)(r.x * scale_) - m, (int)(r.y * scale_) - m, (int)(r.width * scale_) + 2 * m,
                              (int)(r.height * scale_) + 2 * m));
    }

    // the pyramid of this frame, built once: it is the next frame's previous one
    // (calcOpticalFlowPyrLK given the images builds the same pyramids, both each time);
    // its derivatives only where the next frame's Lucas-Kanade passes read them (prev_deriv_)
    const cv::Size win(21, 21);
    const int levels = 3;
    std::vector<cv::Mat> &pyr = spare_pyr_;
    cv::buildOpticalFlowPyramid(cur, pyr, win, levels, false);

    bool matched = false;
    if (have_ && !pts_.empty()) {
        // a corner inside a subject's region is left out whatever its flow, so it is
        // not followed (Lucas-Kanade follows each point on its own)
        std::vector<cv::Point2f> from, next;
        for (const cv::Point2f &p : pts_)
            if (!inside_any(ex, p)) from.push_back(p);
        std::vector<uchar> st;
        // Lucas-Kanade as cv::calcOpticalFlowPyrLK without its error output (which would
        // sample every window once more), points and status bit for bit (lk_track.hpp)
        if (!from.empty()) {
            prev_deriv_.cover(from);
            lk_track(prev_deriv_.pyramid(), pyr, from, next, st, win, levels);
        }
        std::vector<cv::Point2f> a, b;
        for (size_t i = 0; i < from.size(); i++)
            if (st[i] && !inside_any(ex, next[i])) {
                a.push_back(from[i]);
                b.push_back(next[i]);
            }
        if ((int)a.size() >= cfg_.min_inliers) {
            std::vector<uchar> inl;
            cv::Mat m = cv::estimateAffinePartial2D(a, b, inl, cv::RANSAC, 1.0, 2000, 0.995, 10);
            int n_in = 0;
            for (uchar v : inl) n_in += v ? 1 : 0;
            if (!m.empty() && n_in >= cfg_.min_inliers) {
                // working -> full pixels: same linear part, translation / scale
                cv::Matx23d step(m.at<double>(0, 0), m.at<double>(0, 1), m.at<double>(0, 2) / scale_,
                                 m.at<double>(1, 0), m.at<double>(1, 1), m.at<double>(1, 2) / scale_);
                cur_from_ref_ = compose(step, cur_from_ref_);
                out->other = other_motion(pyr, ex, m);
                cv::Point2d c(0.5 * full_.width, 0.5 * full_.height);
                out->step_px = cv::norm(apply(step, c) - c);
                out->inliers = n_in;
                matched = true;
                std::vector<cv::Point2f> kept;
                for (size_t i = 0; i < b.size(); i++)
                    if (inl[i]) kept.push_back(b[i]);
                pts_.swap(kept);
            }
        }
        if (!matched) pts_.clear();
    }
    out->valid = matched || !have_;
    cv::Point2d c(0.5 * full_.width, 0.5 * full_.height);
    cv::Point2d cc = apply(cur_from_ref_, c);
    out->dx_px = cc.x - c.x;
    out->dy_px = cc.y - c.y;
    out->rot_deg = std::atan2(cur_from_ref_(1, 0), cur_from_ref_(0, 0)) * 180.0 / M_PI;
    out->scale = std::sqrt(std::fabs(cur_from_ref_(0, 0) * cur_from_ref_(1, 1) - cur_from_ref_(0, 1) * cur_from_ref_(1, 0)));
    if (!have_) out->inliers = 0;

    // refill the corners when they thin out (occlusion, leaving the view)
    if ((int)pts_.size() < cfg_.max_features / 2) {
        cv::Mat &mask = mask_;
        mask.create(cur.size(), CV_8U);
        mask.setTo(255);
        for (const cv::Rect &r : ex) mask(r & cv::Rect(0, 0, cur.cols, cur.rows)).setTo(0);
        for (const cv::Point2f &p : pts_)
            cv::circle(mask, p, (int)cfg_.min_spacing_px, cv::Scalar(0), -1);
        // per cell of a 4x4 grid, so that no textured subject can hold most of the corners
        const int grid = 4;
        int per_cell = std::max(2, cfg_.max_features / (grid * grid));
        std::vector<int> have(grid * grid, 0);
        for (const cv::Point2f &p : pts_) {
            int gx = std::min(grid - 1, (int)(p.x * grid / cur.cols)), gy = std::min(grid - 1, (int)(p.y * grid / cur.rows));
            have[gy * grid + gx]++;
        }
        for (int gy = 0; gy < grid; gy++)
            for (int gx = 0; gx < grid; gx++) {
                int want = per_cell - have[gy * grid + gx];
                if (want <= 0) continue;
                cv::Rect cell(gx * cur.cols / grid, gy * cur.rows / grid, cur.cols / grid, cur.rows / grid);
                if (cv::countNonZero(mask(cell)) == 0) continue;  // all covered: no corner can come of it
                std::vector<cv::Point2f> fresh;
                good_features(cur(cell), fresh, want, 0.01, cfg_.min_spacing_px, mask(cell), 5, corner_work_);
                for (cv::Point2f &p : fresh) pts_.push_back(p + cv::Point2f((float)cell.x, (float)cell.y));
            }
    }
    prev_pyr_.swap(pyr);
    prev_deriv_.reset(prev_pyr_, win);
    have_ = true;
}

// Corners of the previous frame in a ring around the subjects' regions (not in
// them), followed into this frame: those that move against the background's
// step m (working pixels) by more than other_px belong to something else moving
// right beside a subject (a passer-by behind or next to the person).
int CameraMotion::other_motion(const std::vector<cv::Mat> &pyr, const std::vector<cv::Rect> &ex, const cv::Mat &m) const
{
    if (ex.empty() || cfg_.ring_features <= 0 || prev_pyr_.empty()) return 0;
    const cv::Mat &prev = prev_pyr_[0];  // level 0: the previous working grey frame
    cv::Rect all(0, 0, prev.cols, prev.rows);
    cv::Mat &mask = ring_mask_;
    mask.create(prev.size(), CV_8U);
    mask.setTo(0);
    for (const cv::Rect &r : ex) {
        int g = (int)std::lround(cfg_.ring_rel * std::max(r.width, r.height));
        mask(cv::Rect(r.x - g, r.y - g, r.width + 2 * g, r.height + 2 * g) & all).setTo(255);
    }
    for (const cv::Rect &r : ex) mask(r & all).setTo(0);
    // the corners are found at half the working size (a quarter of the cost; the
    // Lucas-Kanade pass below works at the full working size)
    cv::Rect box = cv::boundingRect(mask);
    box.x &= ~1;
    box.y &= ~1;
    box.width = std::min(prev.cols - box.x, (box.width + 3) & ~1);
    box.height = std::min(prev.rows - box.y, (box.height + 3) & ~1);
    if (box.width < 8 || box.height < 8) return 0;
    cv::Mat half, half_mask;
    cv::resize(prev(box), half, cv::Size(box.width / 2, box.height / 2), 0, 0, cv::INTER_AREA);
    cv::resize(mask(box), half_mask, half.size(), 0, 0, cv::INTER_NEAREST);
    std::vector<cv::Point2f> p0, p1;
    good_features(half, p0, cfg_.ring_features, 0.01, 0.25 * cfg_.min_spacing_px, half_mask, 3, corner_work_);
    if (p0.empty()) return 0;
    for (cv::Point2f &p : p0) p = cv::Point2f(2.0f * p.x + 0.5f + (float)box.x, 2.0f * p.y + 0.5f + (float)box.y);
    std::vector<uchar> st;
    prev_deriv_.cover(p0);  // both pyramids built once, the derivatives where this pass reads them
    lk_track(prev_deriv_.pyramid(), pyr, p0, p1, st, cv::Size(21, 21), 3);
    const double thr = cfg_.other_px * scale_;
    int n = 0;
    for (size_t i = 0; i < p0.size(); i++) {
        if (!st[i] || inside_any(ex, p1[i])) continue;
        double ex_x = m.at<double>(0, 0) * p0[i].x + m.at<double>(0, 1) * p0[i].y + m.at<double>(0, 2);
        double ex_y = m.at<double>(1, 0) * p0[i].x + m.at<double>(1, 1) * p0[i].y + m.at<double>(1, 2);
        if (std::hypot(p1[i].x - ex_x, p1[i].y - ex_y) > thr) n++;
    }
    return n;
}

cv::Point2d CameraMotion::to_reference(cv::Point2d p) const
{
    cv::Matx23d inv;
    cv::invertAffineTransform(cur_from_ref_, inv);
    return apply(inv, p);
}

}  // namespace gs
