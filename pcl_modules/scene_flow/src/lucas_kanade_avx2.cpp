// SPDX-License-Identifier: BSD-3-Clause
// The 256-bit window kernels (compiled with -mavx2; called only on a CPU with AVX2). Each
// row of 16 pixels is interpolated at once; the float sums are then added to four 128-bit
// lanes in the order the 128-bit kernel adds them (8 pixels, then the next 8), so the
// results are the same bit for bit. Only intrinsics and this module's kernel header are
// included: nothing compiled here with AVX2 can be picked by the linker for other files.
#include "lucas_kanade_kernels.h"

#include <immintrin.h>

namespace dynvo::detail::lk {

namespace {

/// (w00, w01) and (w10, w11) in every pair of 16-bit lanes, for _mm256_madd_epi16.
struct PairWeights {
  __m256i top, bottom;
};

PairWeights
pairWeights(const Weights& w)
{
  return {_mm256_set1_epi32((w.w00 & 0xffff) | (w.w01 << 16)),
          _mm256_set1_epi32((w.w10 & 0xffff) | (w.w11 << 16))};
}

/// 16 grey levels x 32 at a row of an 8-bit image, bilinear, in natural order.
__m256i
greyRow(const std::uint8_t* row, std::ptrdiff_t step, const PairWeights& w)
{
  const auto load = [](const std::uint8_t* p) {
    return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
  };
  const __m256i v00 = load(row), v01 = load(row + 1);
  const __m256i v10 = load(row + step), v11 = load(row + step + 1);
  const __m256i round = _mm256_set1_epi32(1 << (W_BITS - 5 - 1));
  // Within each 128-bit lane: pixels 0-3 (then 8-11) low, 4-7 (12-15) high.
  const __m256i low = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(v00, v01), w.top),
                       round),
      _mm256_madd_epi16(_mm256_unpacklo_epi16(v10, v11), w.bottom));
  const __m256i high = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(v00, v01), w.top),
                       round),
      _mm256_madd_epi16(_mm256_unpackhi_epi16(v10, v11), w.bottom));
  return _mm256_packs_epi32(_mm256_srai_epi32(low, W_BITS - 5),
                            _mm256_srai_epi32(high, W_BITS - 5));
}

/// sum += low half, then += high half (the 128-bit kernel's order over 2 x 4 lanes).
__m128
addHalves(__m128 sum, __m256 v)
{
  return _mm_add_ps(_mm_add_ps(sum, _mm256_castps256_ps128(v)),
                    _mm256_extractf128_ps(v, 1));
}

/// OpenCV's v_reduce_sum of 4 floats: (a0 + a2) + (a1 + a3).
float
reduceSum(__m128 a)
{
  const __m128 pairs = _mm_add_ps(a, _mm_movehl_ps(a, a));
  return _mm_cvtss_f32(_mm_add_ss(pairs, _mm_shuffle_ps(pairs, pairs, 1)));
}

} // namespace

Normal
makeTemplate256(Rows<std::uint8_t> image,
                Rows<short> gradient,
                const Weights& w,
                int window,
                short* grey,
                short* window_gradient)
{
  const PairWeights pw = pairWeights(w);
  const __m256i round = _mm256_set1_epi32(1 << (W_BITS - 1));
  // A window at half a pixel in both directions (a grid cell's centre with an even window,
  // on every level) weighs its four pixels 2^12 each. Its values are then sums: a grey
  // level 2^12 s / 2^9 = 8 s exactly, a gradient (2^12 s + 2^13) >> 14 = (s + 2) >> 2, with
  // s the sum of the four pixels (at most 4 x 255 and 4 x 4080 in magnitude: 16 bits hold
  // them). The same values as the weighted path, for a third of its work.
  const bool half_pixel = w.w00 == 1 << (W_BITS - 2) && w.w01 == 1 << (W_BITS - 2) &&
                          w.w10 == 1 << (W_BITS - 2);
  __m128 A11 = _mm_setzero_ps(), A12 = _mm_setzero_ps(), A22 = _mm_setzero_ps();
  for (int y = 0; y < window; ++y) {
    const std::uint8_t* src = image.origin + y * image.step;
    const short* dsrc = gradient.origin + y * gradient.step;
    short* out = grey + y * window;
    short* dout = window_gradient + y * window * 2;
    for (int x = 0; x < window; x += 16) {
      __m256i row;
      if (half_pixel) {
        const auto load = [](const std::uint8_t* p) {
          return _mm256_cvtepu8_epi16(
              _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
        };
        const std::uint8_t* p = src + x;
        row = _mm256_slli_epi16(
            _mm256_add_epi16(
                _mm256_add_epi16(load(p), load(p + 1)),
                _mm256_add_epi16(load(p + image.step), load(p + image.step + 1))),
            3);
      }
      else
        row = greyRow(src + x, image.step, pw);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + x), row);
      // The gradients of 8 pixels at a time: pixels 0-3 in the low lane, 4-7 in the high.
      __m256i parts[2];
      for (int part = 0; part < 2; ++part, dsrc += 16) {
        const auto load = [](const short* p) {
          return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
        };
        const __m256i d00 = load(dsrc), d01 = load(dsrc + 2);
        const __m256i d10 = load(dsrc + gradient.step),
                      d11 = load(dsrc + gradient.step + 2);
        __m256i g;
        if (half_pixel) {
          const __m256i sum =
              _mm256_add_epi16(_mm256_add_epi16(d00, d01), _mm256_add_epi16(d10, d11));
          g = _mm256_srai_epi16(_mm256_add_epi16(sum, _mm256_set1_epi16(2)), 2);
        }
        else {
          const __m256i low = _mm256_add_epi32(
              _mm256_add_epi32(
                  _mm256_madd_epi16(_mm256_unpacklo_epi16(d00, d01), pw.top), round),
              _mm256_madd_epi16(_mm256_unpacklo_epi16(d10, d11), pw.bottom));
          const __m256i high = _mm256_add_epi32(
              _mm256_add_epi32(
                  _mm256_madd_epi16(_mm256_unpackhi_epi16(d00, d01), pw.top), round),
              _mm256_madd_epi16(_mm256_unpackhi_epi16(d10, d11), pw.bottom));
          g = _mm256_packs_epi32(_mm256_srai_epi32(low, W_BITS),
                                 _mm256_srai_epi32(high, W_BITS)); // Ix Iy ...
        }
        parts[part] = g;
        const __m256 fx =
            _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(g, 16), 16));
        const __m256 fy = _mm256_cvtepi32_ps(_mm256_srai_epi32(g, 16));
        // The products are exact (|gradient| < 2^12), so multiply-then-add is the
        // 128-bit kernel's multiply-add.
        A22 = addHalves(A22, _mm256_mul_ps(fy, fy));
        A12 = addHalves(A12, _mm256_mul_ps(fx, fy));
        A11 = addHalves(A11, _mm256_mul_ps(fx, fx));
      }
      // Kept in the order mismatch256() pairs them with the grey levels: for pixels 0-7 in
      // the low lane and 8-15 in the high, (Ix_k, Ix_k+4, Iy_k, Iy_k+4) for k = 0, 1, then
      // for k = 2, 3 (the 128-bit kernel's pairs), so that its steps need not shuffle them.
      const __m256i first = _mm256_permute2x128_si256(parts[0], parts[1], 0x20);
      const __m256i second = _mm256_permute2x128_si256(parts[0], parts[1], 0x31);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(dout),
                          _mm256_unpacklo_epi16(first, second));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(dout + 16),
                          _mm256_unpackhi_epi16(first, second));
      dout += 32;
    }
  }
  return {reduceSum(A11) * FLT_SCALE, reduceSum(A12) * FLT_SCALE,
          reduceSum(A22) * FLT_SCALE};
}

Mismatch
mismatch256(Rows<std::uint8_t> image,
            const Weights& w,
            int window,
            const short* grey,
            const short* window_gradient)
{
  const PairWeights pw = pairWeights(w);
  // Bytes of 16-bit lanes (0, 4, 0, 4, 1, 5, 1, 5) and (2, 6, 2, 6, 3, 7, 3, 7) of each half.
  const __m256i PAIRS_01 =
      _mm256_setr_epi8(0, 1, 8, 9, 0, 1, 8, 9, 2, 3, 10, 11, 2, 3, 10, 11, 0, 1, 8, 9,
                       0, 1, 8, 9, 2, 3, 10, 11, 2, 3, 10, 11);
  const __m256i PAIRS_23 =
      _mm256_setr_epi8(4, 5, 12, 13, 4, 5, 12, 13, 6, 7, 14, 15, 6, 7, 14, 15, 4, 5, 12,
                       13, 4, 5, 12, 13, 6, 7, 14, 15, 6, 7, 14, 15);
  __m128 b0 = _mm_setzero_ps(), b1 = _mm_setzero_ps();
  for (int y = 0; y < window; ++y) {
    const std::uint8_t* src = image.origin + y * image.step;
    const short* Iptr = grey + y * window;
    const short* dIptr = window_gradient + y * window * 2;
    for (int x = 0; x < window; x += 16, dIptr += 32) {
      const __m256i diff = _mm256_subs_epi16(
          greyRow(src + x, image.step, pw),
          _mm256_loadu_si256(reinterpret_cast<const __m256i*>(Iptr + x)));
      // The 128-bit kernel's pairs, for pixels 0-7 in the low lane and 8-15 in the high:
      // (It_k, It_k+4) against the template's (Ix_k, Ix_k+4) and (Iy_k, Iy_k+4).
      const __m256i pairs_01 = _mm256_shuffle_epi8(diff, PAIRS_01);
      const __m256i pairs_23 = _mm256_shuffle_epi8(diff, PAIRS_23);
      b0 = addHalves(
          b0,
          _mm256_cvtepi32_ps(_mm256_madd_epi16(
              pairs_01, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(dIptr)))));
      b1 = addHalves(
          b1, _mm256_cvtepi32_ps(_mm256_madd_epi16(
                  pairs_23,
                  _mm256_loadu_si256(reinterpret_cast<const __m256i*>(dIptr + 16)))));
    }
  }
  // OpenCV's epilogue: lanes (x, y, x, y) of b0 + b1, each pair of x and y summed.
  const __m128 sum = _mm_add_ps(b0, b1);
  const float x = _mm_cvtss_f32(sum) + _mm_cvtss_f32(_mm_movehl_ps(sum, sum));
  const float y = _mm_cvtss_f32(_mm_shuffle_ps(sum, sum, 1)) +
                  _mm_cvtss_f32(_mm_shuffle_ps(sum, sum, 3));
  return {x * FLT_SCALE, y * FLT_SCALE};
}

} // namespace dynvo::detail::lk
