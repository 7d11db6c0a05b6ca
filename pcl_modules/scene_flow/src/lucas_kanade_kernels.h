// SPDX-License-Identifier: BSD-3-Clause
// The window kernels of trackLucasKanade (internal to the scene flow module). The 256-bit
// ones are compiled with -mavx2 in their own file (lucas_kanade_avx2.cpp, which includes
// nothing else that could be inlined elsewhere) and called only on a CPU that has AVX2.
#pragma once

#include <cstddef>
#include <cstdint>

namespace dynvo::detail::lk {

/// OpenCV's fixed point: bilinear weights in 14 bits, grey levels kept x 32.
constexpr int W_BITS = 14;
/// The normal matrix and the mismatch are summed in units of 2^20 (OpenCV's FLT_SCALE).
constexpr float FLT_SCALE = 1.0f / (1 << 20);

/// Bilinear weights of a window's fractional offset, in W_BITS fixed point.
struct Weights {
  int w00, w01, w10, w11;
};

/// A window of an image: its top-left element and the row step (elements).
template <typename T> struct Rows {
  const T* origin;
  std::ptrdiff_t step;
};

/// The normal matrix of a template's gradients, scaled by FLT_SCALE.
struct Normal {
  float A11, A12, A22;
};

/// The mismatch of a template against the other image, sum (J - I) * gradient, scaled.
struct Mismatch {
  float b1, b2;
};

#if defined(DYNVO_LK_AVX2)
/** \brief The template of a window whose side is a multiple of 16, with 256-bit integer
 * arithmetic; the same values and the same order of the float sums as the 128-bit kernel.
 * \param[in] image the grey image from the window's top-left pixel
 * \param[in] gradient the image's interleaved Scharr gradients, from the same pixel
 * \param[out] grey window x window grey levels x 32
 * \param[out] window_gradient window x window interleaved gradients
 */
Normal makeTemplate256(Rows<std::uint8_t> image,
                       Rows<short> gradient,
                       const Weights& w,
                       int window,
                       short* grey,
                       short* window_gradient);

/// The mismatch of a template (makeTemplate256's) at the window of `image`, the same way.
Mismatch mismatch256(Rows<std::uint8_t> image,
                     const Weights& w,
                     int window,
                     const short* grey,
                     const short* window_gradient);
#endif

} // namespace dynvo::detail::lk
