// SPDX-License-Identifier: BSD-3-Clause
#include "lucas_kanade.h"

#include "lucas_kanade_kernels.h"

#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dynvo::detail {

using lk::FLT_SCALE;
using lk::Mismatch;
using lk::Normal;
using lk::Rows;
using lk::W_BITS;
using lk::Weights;

namespace {

/// x / 2^n rounded half up, in integers.
constexpr int
descale(int x, int n)
{
  return (x + (1 << (n - 1))) >> n;
}

/// Bilinear weights of the fractional offsets (a, b), rounded as OpenCV rounds them.
Weights
weightsOf(float a, float b)
{
  Weights w;
  w.w00 = cvRound((1.f - a) * (1.f - b) * (1 << W_BITS));
  w.w01 = cvRound(a * (1.f - b) * (1 << W_BITS));
  w.w10 = cvRound((1.f - a) * b * (1 << W_BITS));
  w.w11 = (1 << W_BITS) - w.w00 - w.w01 - w.w10;
  return w;
}

#if CV_SIMD128
/// (a, b) in every pair of 16-bit lanes, for v_dotprod.
cv::v_int16x8
pairOf(int a, int b)
{
  return cv::v_reinterpret_as_s16(cv::v_setall_u32(static_cast<unsigned>(a & 0xffff) |
                                                   static_cast<unsigned>(b) << 16));
}

/// 8 grey levels x 32 at a row of an 8-bit image, bilinear (qw0, qw1: pairOf() the weights).
cv::v_int16x8
greyRow128(const std::uint8_t* row,
           std::ptrdiff_t step,
           const cv::v_int16x8& qw0,
           const cv::v_int16x8& qw1)
{
  const cv::v_int16x8 v00 = cv::v_reinterpret_as_s16(cv::v_load_expand(row));
  const cv::v_int16x8 v01 = cv::v_reinterpret_as_s16(cv::v_load_expand(row + 1));
  const cv::v_int16x8 v10 = cv::v_reinterpret_as_s16(cv::v_load_expand(row + step));
  const cv::v_int16x8 v11 = cv::v_reinterpret_as_s16(cv::v_load_expand(row + step + 1));
  cv::v_int16x8 t00, t01, t10, t11;
  cv::v_zip(v00, v01, t00, t01);
  cv::v_zip(v10, v11, t10, t11);
  const cv::v_int32x4 round = cv::v_setall_s32(1 << (W_BITS - 5 - 1));
  const cv::v_int32x4 t0 = cv::v_dotprod(t00, qw0, round) + cv::v_dotprod(t10, qw1);
  const cv::v_int32x4 t1 = cv::v_dotprod(t01, qw0, round) + cv::v_dotprod(t11, qw1);
  return cv::v_pack(t0 >> (W_BITS - 5), t1 >> (W_BITS - 5));
}
#endif

/** The template of a window (128-bit integer arithmetic, OpenCV's code path): grey levels
 * x 32 into `grey`, interleaved gradients into `window_gradient`, and their normal matrix. */
Normal
makeTemplate128(Rows<std::uint8_t> image,
                Rows<short> gradient,
                const Weights& w,
                int window,
                short* grey,
                short* window_gradient)
{
  const std::ptrdiff_t step_i = image.step;
  const std::ptrdiff_t step_d = gradient.step;
  float iA11 = 0, iA12 = 0, iA22 = 0;
#if CV_SIMD128
  const cv::v_int16x8 qw0 = pairOf(w.w00, w.w01), qw1 = pairOf(w.w10, w.w11);
  const cv::v_int32x4 round_d = cv::v_setall_s32(1 << (W_BITS - 1));
  cv::v_float32x4 qA11 = cv::v_setzero_f32(), qA12 = cv::v_setzero_f32(),
                  qA22 = cv::v_setzero_f32();
#endif
  for (int y = 0; y < window; ++y) {
    const std::uint8_t* src = image.origin + y * step_i;
    const short* dsrc = gradient.origin + y * step_d;
    short* Iptr = grey + y * window;
    short* dIptr = window_gradient + y * window * 2;
    int x = 0;
#if CV_SIMD128
    for (; x <= window - 8; x += 8, dsrc += 16, dIptr += 16) {
      cv::v_store(Iptr + x, greyRow128(src + x, step_i, qw0, qw1));
      // The gradients of the 8 pixels, 4 at a time (OpenCV's order of the sums).
      for (int half = 0; half < 2; ++half) {
        const short* d = dsrc + half * 8;
        cv::v_int16x8 t00, t01, t10, t11;
        cv::v_zip(cv::v_load(d), cv::v_load(d + 2), t00, t01);
        cv::v_zip(cv::v_load(d + step_d), cv::v_load(d + step_d + 2), t10, t11);
        cv::v_int32x4 t0 = cv::v_dotprod(t00, qw0, round_d) + cv::v_dotprod(t10, qw1);
        cv::v_int32x4 t1 = cv::v_dotprod(t01, qw0, round_d) + cv::v_dotprod(t11, qw1);
        cv::v_int16x8 v00 =
            cv::v_pack(t0 >> W_BITS, t1 >> W_BITS); // Ix0 Iy0 Ix1 Iy1 ...
        cv::v_store(dIptr + half * 8, v00);
        v00 = cv::v_reinterpret_as_s16(cv::v_interleave_pairs(
            cv::v_reinterpret_as_s32(cv::v_interleave_pairs(v00))));
        cv::v_expand(v00, t1, t0);
        const cv::v_float32x4 fy = cv::v_cvt_f32(t0);
        const cv::v_float32x4 fx = cv::v_cvt_f32(t1);
        qA22 = cv::v_muladd(fy, fy, qA22);
        qA12 = cv::v_muladd(fx, fy, qA12);
        qA11 = cv::v_muladd(fx, fx, qA11);
      }
    }
#endif
    for (; x < window; ++x, dsrc += 2, dIptr += 2) {
      const int ival =
          descale(src[x] * w.w00 + src[x + 1] * w.w01 + src[x + step_i] * w.w10 +
                      src[x + step_i + 1] * w.w11,
                  W_BITS - 5);
      const int ixval = descale(dsrc[0] * w.w00 + dsrc[2] * w.w01 +
                                    dsrc[step_d] * w.w10 + dsrc[step_d + 2] * w.w11,
                                W_BITS);
      const int iyval = descale(dsrc[1] * w.w00 + dsrc[3] * w.w01 +
                                    dsrc[step_d + 1] * w.w10 + dsrc[step_d + 3] * w.w11,
                                W_BITS);
      Iptr[x] = static_cast<short>(ival);
      dIptr[0] = static_cast<short>(ixval);
      dIptr[1] = static_cast<short>(iyval);
      iA11 += static_cast<float>(ixval * ixval);
      iA12 += static_cast<float>(ixval * iyval);
      iA22 += static_cast<float>(iyval * iyval);
    }
  }
#if CV_SIMD128
  iA11 += cv::v_reduce_sum(qA11);
  iA12 += cv::v_reduce_sum(qA12);
  iA22 += cv::v_reduce_sum(qA22);
#endif
  return {iA11 * FLT_SCALE, iA12 * FLT_SCALE, iA22 * FLT_SCALE};
}

/// The mismatch of a template (makeTemplate128's) at a window of `image`, as OpenCV sums it.
Mismatch
mismatch128(Rows<std::uint8_t> image,
            const Weights& w,
            int window,
            const short* grey,
            const short* window_gradient)
{
  const std::ptrdiff_t step_j = image.step;
  float ib1 = 0, ib2 = 0;
#if CV_SIMD128
  const cv::v_int16x8 qw0 = pairOf(w.w00, w.w01), qw1 = pairOf(w.w10, w.w11);
  cv::v_float32x4 qb0 = cv::v_setzero_f32(), qb1 = cv::v_setzero_f32();
#endif
  for (int y = 0; y < window; ++y) {
    const std::uint8_t* Jptr = image.origin + y * step_j;
    const short* Iptr = grey + y * window;
    const short* dIptr = window_gradient + y * window * 2;
    int x = 0;
#if CV_SIMD128
    for (; x <= window - 8; x += 8, dIptr += 16) {
      cv::v_int16x8 diff1, diff2;
      const cv::v_int16x8 diff0 =
          greyRow128(Jptr + x, step_j, qw0, qw1) - cv::v_load(Iptr + x);
      cv::v_zip(diff0, diff0, diff2, diff1); // It0 It0 It1 It1 ...
      cv::v_int16x8 v00 = cv::v_load(dIptr); // Ix0 Iy0 Ix1 Iy1 ...
      cv::v_int16x8 v01 = cv::v_load(dIptr + 8), v10, v11;
      cv::v_zip(v00, v01, v10, v11);
      cv::v_zip(diff2, diff1, v00, v01);
      qb0 += cv::v_cvt_f32(cv::v_dotprod(v00, v10));
      qb1 += cv::v_cvt_f32(cv::v_dotprod(v01, v11));
    }
#endif
    for (; x < window; ++x, dIptr += 2) {
      const int diff =
          descale(Jptr[x] * w.w00 + Jptr[x + 1] * w.w01 + Jptr[x + step_j] * w.w10 +
                      Jptr[x + step_j + 1] * w.w11,
                  W_BITS - 5) -
          Iptr[x];
      ib1 += static_cast<float>(diff * dIptr[0]);
      ib2 += static_cast<float>(diff * dIptr[1]);
    }
  }
#if CV_SIMD128
  cv::v_float32x4 qf0, qf1;
  cv::v_recombine(cv::v_interleave_pairs(qb0 + qb1), cv::v_setzero_f32(), qf0, qf1);
  ib1 += cv::v_reduce_sum(qf0);
  ib2 += cv::v_reduce_sum(qf1);
#endif
  return {ib1 * FLT_SCALE, ib2 * FLT_SCALE};
}

/// A pyramid level's image (or interleaved gradients) with its row step in elements, so
/// that a window's rows cost no division.
template <typename T> struct Plane {
  const T* data;
  std::ptrdiff_t step;
  int channels;

  explicit Plane(const cv::Mat& m)
      : data(reinterpret_cast<const T*>(m.data))
      , step(static_cast<std::ptrdiff_t>(m.step / m.elemSize1()))
      , channels(m.channels())
  {
  }

  /// The rows of the window whose top-left pixel is `corner`.
  Rows<T> at(cv::Point2i corner) const
  {
    return {data + corner.y * step + corner.x * channels, step};
  }
};

/// Whether the 256-bit kernels run: built for x86-64, the CPU has AVX2, and the window's
/// rows are whole multiples of 16 pixels.
bool
wideKernels(const LucasKanadeSettings& s)
{
#if defined(DYNVO_LK_AVX2)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return s.wide && avx2 && s.window % 16 == 0;
#else
  (void)s;
  return false;
#endif
}

} // namespace

void
trackLucasKanade(const std::vector<cv::Mat>& from_pyramid,
                 const std::vector<cv::Mat>& to_pyramid,
                 const std::vector<cv::Point2f>& from,
                 const LucasKanadeSettings& s,
                 std::vector<cv::Point2f>& to,
                 std::vector<std::uint8_t>& status)
{
  const int levels =
      static_cast<int>(std::min(from_pyramid.size() / 2, to_pyramid.size() / 2));
  if (levels < 1 || to.size() != from.size())
    throw std::invalid_argument(
        "[dynvo::detail::trackLucasKanade] a pyramid without levels, or to and from of "
        "different sizes");
  const int max_level = std::min(s.max_level, levels - 1);
  const int window = s.window;
  const int max_iterations = std::clamp(s.max_iterations, 0, 100);
  double epsilon = std::clamp(s.epsilon, 0.0, 10.0);
  epsilon *= epsilon;
  const cv::Point2f half_window((window - 1) * 0.5f, (window - 1) * 0.5f);
  std::vector<short> grey(static_cast<std::size_t>(window) * window);
  std::vector<short> gradient(grey.size() * 2);
  const bool wide = wideKernels(s);

  std::vector<Plane<std::uint8_t>> images, targets;
  std::vector<Plane<short>> gradients;
  for (int level = 0; level <= max_level; ++level) {
    images.emplace_back(from_pyramid[2 * level]);
    gradients.emplace_back(from_pyramid[2 * level + 1]);
    targets.emplace_back(to_pyramid[2 * level]);
  }

  // A window whose top-left corner lies farther than a window off the level (OpenCV's rule:
  // the pyramid's border is a window wide).
  const auto offLevel = [window](cv::Point2i corner, const cv::Mat& level) {
    return corner.x < -window || corner.x >= level.cols || corner.y < -window ||
           corner.y >= level.rows;
  };
  status.assign(from.size(), 1);
  for (std::size_t i = 0; i < from.size(); ++i) {
    for (int level = max_level; level >= 0; --level) {
      const cv::Mat& dI = from_pyramid[2 * level + 1];
      const cv::Mat& J = to_pyramid[2 * level];
      cv::Point2f prev = from[i] * static_cast<float>(1. / (1 << level));
      cv::Point2f next = level == max_level
                             ? to[i] * static_cast<float>(1. / (1 << level))
                             : to[i] * 2.f;
      to[i] = next;
      prev -= half_window;
      const cv::Point2i iprev(cvFloor(prev.x), cvFloor(prev.y));
      if (offLevel(iprev, dI)) {
        if (level == 0)
          status[i] = 0;
        continue;
      }
      const Rows<std::uint8_t> image = images[level].at(iprev);
      const Rows<short> image_gradient = gradients[level].at(iprev);
      const Weights w = weightsOf(prev.x - iprev.x, prev.y - iprev.y);
      const auto [A11, A12, A22] =
          wide ? lk::makeTemplate256(image, image_gradient, w, window, grey.data(),
                                     gradient.data())
               : makeTemplate128(image, image_gradient, w, window, grey.data(),
                                 gradient.data());
      float D = A11 * A22 - A12 * A12;
      const float min_eigen =
          (A22 + A11 - std::sqrt((A11 - A22) * (A11 - A22) + 4.f * A12 * A12)) /
          (2 * window * window);
      if (min_eigen < static_cast<float>(s.min_eigen_threshold) || D < FLT_EPSILON) {
        if (level == 0)
          status[i] = 0;
        continue;
      }
      D = 1.f / D;
      next -= half_window;
      cv::Point2f previous_delta;
      for (int j = 0; j < max_iterations; ++j) {
        const cv::Point2i inext(cvFloor(next.x), cvFloor(next.y));
        if (offLevel(inext, J)) {
          if (level == 0)
            status[i] = 0;
          break;
        }
        const Rows<std::uint8_t> target = targets[level].at(inext);
        const Weights wn = weightsOf(next.x - inext.x, next.y - inext.y);
        const auto [b1, b2] =
            wide ? lk::mismatch256(target, wn, window, grey.data(), gradient.data())
                 : mismatch128(target, wn, window, grey.data(), gradient.data());
        const cv::Point2f delta(static_cast<float>((A12 * b2 - A22 * b1) * D),
                                static_cast<float>((A12 * b1 - A11 * b2) * D));
        next += delta;
        to[i] = next + half_window;
        if (delta.ddot(delta) <= epsilon)
          break;
        if (j > 0 && std::abs(delta.x + previous_delta.x) < 0.01 &&
            std::abs(delta.y + previous_delta.y) < 0.01) {
          to[i] -= delta * 0.5f;
          break;
        }
        previous_delta = delta;
      }
    }
  }
}

} // namespace dynvo::detail
