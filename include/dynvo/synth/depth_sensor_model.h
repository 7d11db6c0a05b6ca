// SPDX-License-Identifier: BSD-3-Clause
// Kinect v1 / Xtion structured-light depth model applied to exact rendered depth.
#pragma once

#include <dynvo/common/export.h>

#include <cstdint>
#include <vector>

namespace dynvo {

/// What the renderer knows about the surface seen by one pixel.
struct SurfaceSample {
  float z = 0.0f; ///< exact depth along the optical axis (m); NaN = nothing hit
  /// |cos| of the angle between the viewing ray and the surface normal (1 = facing)
  float cosine = 1.0f;
  bool dark = false; ///< dark or shiny material: returns almost no structured light
};

/** \brief Depth model of a Kinect v1 / Xtion (structured light, 7.5 cm baseline).
 *
 * Applied per frame to the exact depth of a rendered scene, in this order:
 * 1. Projector shadow: the IR projector sits BASELINE to the right of the depth camera
 *    (+x). A surface point whose line of sight to the projector is blocked by a nearer
 *    surface gets no measurement, so a band on the left of every foreground object,
 *    about f B (1/z_near - 1/z_far) px wide, is empty. Decided per image row by the
 *    ordering constraint: a point is shadowed when a point to its right maps to a
 *    smaller projector column.
 * 2. Dropouts on the far side of a depth jump larger than EDGE_JUMP_RATIO of the depth
 *    (mixed pixels at depth edges).
 * 3. Grazing angles: no return when the incidence cosine is below GRAZING_COSINE_NONE,
 *    a return with probability rising linearly to 1 at GRAZING_COSINE_FULL.
 * 4. Dark or shiny surfaces return with probability DARK_RETURN_RATE.
 * 5. Speckle: DROPOUT_RATE of the pixels lose their measurement at random, and
 *    SPECKLE_RATE get a wrong depth, off by up to SPECKLE_ERROR of z.
 * 6. Axial noise with sigma_z(z) = SIGMA_CONSTANT + SIGMA_QUADRATIC (z - SIGMA_OFFSET)^2
 *    (Nguyen, Izadi and Lovell, 3DIMPVT 2012), then disparity quantisation to
 *    1/8 px (inverse depth in steps of INVERSE_DEPTH_STEP). sigma_z is the standard
 *    deviation of the *measured* depth (the paper measured real sensor output), so the
 *    Gaussian added before quantisation is reduced by the quantiser's step^2 / 12.
 * 7. No measurement when the surface or its measured depth lies outside
 *    [MIN_DEPTH, MAX_DEPTH].
 *
 * Every random number is a hash of (seed, frame, pixel, purpose): the result does not
 * depend on call order or threads.
 */
class DYNVO_EXPORTS DepthSensorModel {
public:
  static constexpr double MIN_DEPTH = 0.5;          ///< nearest measurable depth (m)
  static constexpr double MAX_DEPTH = 4.5;          ///< farthest measurable depth (m)
  static constexpr double SIGMA_CONSTANT = 1.2e-3;  ///< sigma_z at SIGMA_OFFSET (m)
  static constexpr double SIGMA_QUADRATIC = 1.9e-3; ///< sigma_z growth (1/m)
  static constexpr double SIGMA_OFFSET = 0.4;       ///< depth of the smallest noise (m)
  static constexpr double BASELINE = 0.075;         ///< projector to camera (m)
  static constexpr double DISPARITY_FOCAL = 580.0;  ///< focal of the disparity (px)
  /// Inverse-depth step (1/m): 1/8 px of disparity / (baseline * focal).
  static constexpr double INVERSE_DEPTH_STEP = 0.125 / (BASELINE * DISPARITY_FOCAL);
  static constexpr double EDGE_JUMP_RATIO = 0.05; ///< depth jump (of z) losing a pixel
  static constexpr double GRAZING_COSINE_NONE = 0.17; ///< below: no return (80 deg)
  static constexpr double GRAZING_COSINE_FULL = 0.34; ///< above: full return (70 deg)
  static constexpr double DARK_RETURN_RATE = 0.03; ///< returns on dark/shiny surfaces
  static constexpr double DROPOUT_RATE = 0.01;     ///< pixels lost at random
  static constexpr double SPECKLE_RATE = 0.001;    ///< pixels with a wrong depth
  static constexpr double SPECKLE_ERROR = 0.1;     ///< largest wrong-depth error (of z)

  /// Measured-depth standard deviation sigma_z(z) (m) at depth z (m).
  static double axialSigma(double z);

  /** \brief Measured depth of a row-major width x height image of surface samples.
   * \param[in] samples exact surfaces, one per pixel
   * \param[in] fx horizontal focal length of the depth image (px), for the shadow width
   * \param[in] seed sequence seed; \param[in] frame frame index (both key the noise)
   * \param[in] mask when non-empty, only pixels with mask != 0 are measured (the others
   *            are left as they are in depth); shadows and edges still see every sample
   * \param[in,out] depth measured depth (m, NaN = none); resized when mask is empty
   */
  static void measure(const std::vector<SurfaceSample>& samples,
                      int width,
                      int height,
                      double fx,
                      std::uint32_t seed,
                      int frame,
                      const std::vector<std::uint8_t>& mask,
                      std::vector<float>& depth);
};

} // namespace dynvo
