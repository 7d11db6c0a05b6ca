// SPDX-License-Identifier: BSD-3-Clause
// Depth-camera noise: per-point 3D covariance from depth and viewing ray.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>

#include <Eigen/Core>

namespace dynvo {

/** \brief Noise of a structured-light depth camera (Kinect v1, Xtion) as seen by the grid
 * scene flow: a point measured at depth z has a Gaussian error with standard deviation
 * sigma_z(z) = axial_base + axial_quadratic (z - axial_offset)^2 along its viewing ray
 * (Khoshelham & Elberink 2012, Nguyen et al. 2012) and z * lateral_pixels / f across it
 * (tracking error of the flow, in pixels). axial_scale multiplies sigma_z: below 1 where
 * the scene flow's depth window averages several pixels.
 *
 * The transfer error e = R a + t - b of a static point seen as a in one frame and b in the
 * next has covariance about Sigma(a) + Sigma(b) (R is close to identity frame to frame), so
 * e^T (Sigma(a) + Sigma(b))^-1 e is chi-square with 3 degrees of freedom for a static point.
 * Defaults: the published Kinect v1 axial model and 0.6 px, the median lateral error measured
 * on TUM fr1/xyz (pcl_modules/motion_segmentation/NOTES.md); docs/algorithm.md §2.
 */
struct DYNVO_EXPORTS SensorNoiseModel {
  float axial_base = 1.2e-3f;      ///< sigma_0 (metres, > 0): axial sigma at axial_offset
  float axial_quadratic = 1.9e-3f; ///< k (m^-1, >= 0): growth of sigma_z with (z - z_0)^2
  float axial_offset = 0.4f;       ///< z_0 (metres, >= 0)
  float axial_scale = 1.0f;        ///< (> 0): factor on sigma_z (depth averaging)
  float lateral_pixels = 0.6f;     ///< sigma_px (px, > 0): error across the ray

  /// Names, units and ranges of the fields above, in file order (ParameterTable).
  static const ParameterTable<SensorNoiseModel>& table();

  /// \throws std::invalid_argument naming the first field out of the range stated above
  void validate() const;

  /// sigma_z at depth z (metres).
  float axialSigma(float z) const
  {
    const float d = z - axial_offset;
    return axial_scale * (axial_base + axial_quadratic * d * d);
  }

  /// Lateral sigma at depth z (metres) for focal length focal (px).
  float lateralSigma(float z, float focal) const { return z * lateral_pixels / focal; }

  /// Axial and lateral variances (m^2) of the transfer error between a and b: the sums of
  /// both points' sigma^2 (see transferInformation()).
  struct TransferVariance {
    float axial;
    float lateral;
  };
  TransferVariance transferVariance(const Eigen::Vector3f& a,
                                    const Eigen::Vector3f& b,
                                    float focal) const
  {
    const float axial_a = axialSigma(a.z()), axial_b = axialSigma(b.z());
    const float lateral_a = lateralSigma(a.z(), focal), lateral_b = lateralSigma(b.z(), focal);
    return {axial_a * axial_a + axial_b * axial_b, lateral_a * lateral_a + lateral_b * lateral_b};
  }

  /** \brief Information matrix of the transfer error between two measurements a and b
   * (metres) of one point taken with focal length focal (px): the inverse of
   * Sigma(a) + Sigma(b) with both rays taken along b's, and the axial and lateral
   * variances multiplied by axial_gain^2 and lateral_gain^2 (scales fitted to data).
   */
  Eigen::Matrix3f transferInformation(const Eigen::Vector3f& a,
                                      const Eigen::Vector3f& b,
                                      float focal,
                                      float axial_gain = 1.0f,
                                      float lateral_gain = 1.0f) const;
};

} // namespace dynvo
