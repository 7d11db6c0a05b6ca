// SPDX-License-Identifier: BSD-3-Clause
// Depth-map clean-up before scene flow: range limits, flying pixels, narrow holes.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>

#include <cstdint>
#include <vector>

namespace dynvo {

/** \brief Depth preprocessing of docs/algorithm.md §1.1 (Lee, Son & Kim, IROS 2019: "narrow holes
 * are filled from nearby similar values, abnormally high or low depths are removed").
 *
 * Works on a row-major float depth map in metres where NaN means "no measurement", in three steps:
 * 1. range: depths outside [min_depth, max_depth] (and non-finite or non-positive ones) become NaN;
 * 2. flying pixels: a pixel becomes NaN when |z - m| > flying_pixel_tolerance * m, where m is the
 *    median of its valid 8 neighbours (the upper middle element when their count is even); pixels
 *    with fewer than 5 valid neighbours are kept as they are;
 * 3. narrow holes: a row pass, then a column pass. A run of at most max_hole_width NaN pixels with
 *    valid ends zL, zR is filled by linear interpolation when |zL - zR| <= hole_fill_tolerance *
 *    min(zL, zR); otherwise it is a depth discontinuity and stays NaN.
 * Cost O(width * height) (timings: pcl_modules/scene_flow/NOTES.md).
 * \code
 * dynvo::DepthPreprocessing preprocessing;          // docs/algorithm.md §9 defaults
 * std::vector<float> clean;
 * preprocessing.apply(depth_metres, 640, 480, clean);
 * \endcode
 */
class DYNVO_EXPORTS DepthPreprocessing {
public:
  /// Knobs of docs/algorithm.md §1.1 / §9.
  struct Parameters {
    float min_depth = 0.3f; ///< z_min (metres, > 0): nearer depths are invalid
    float max_depth = 5.0f; ///< z_max (metres, > min_depth): farther depths are invalid
    /// tau_fly (relative, in (0, 1)): allowed deviation from the 3x3 median.
    float flying_pixel_tolerance = 0.05f;
    /// w_hole (px, >= 0; 0 disables filling): longest run of NaN that is filled.
    int max_hole_width = 5;
    /// tau_fill (relative, >= 0): largest |zL - zR| / min(zL, zR) that is filled.
    float hole_fill_tolerance = 0.05f;

    /// Names, units and ranges of the fields above, in file order (ParameterTable).
    static const ParameterTable<Parameters>& table();

    /// \throws std::invalid_argument when a value is out of the range stated above or
    ///         max_depth <= min_depth
    void validate() const;
  };

  DepthPreprocessing() = default;

  /// \throws std::invalid_argument when parameters.validate() fails
  explicit DepthPreprocessing(const Parameters& parameters);

  /// \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters);

  const Parameters& getParameters() const { return params_; }

  /** \brief Threads used by apply() (default 1); the result does not depend on it.
   * \throws std::invalid_argument when threads is 0
   */
  void setNumberOfThreads(unsigned threads);

  unsigned getNumberOfThreads() const { return threads_; }

  /** \brief Clean one depth map.
   * \param[in] depth width * height depths (metres, row-major), NaN or 0 = no measurement
   * \param[in] width columns (px)
   * \param[in] height rows (px)
   * \param[out] out the cleaned map (metres, NaN = invalid), resized to width * height; must not
   *             alias depth
   * \throws std::invalid_argument when depth.size() != width * height or out aliases depth
   */
  void apply(const std::vector<float>& depth,
             std::uint32_t width,
             std::uint32_t height,
             std::vector<float>& out) const;

  /** \brief apply() in two parts, for a caller with other work to run beside the second:
   * applyRows() makes steps 1, 2 and the row pass of step 3 (each row's pass right after the
   * row's flying pixels: it reads that row only), applyColumns() the column pass on the map
   * applyRows() made. apply() is the two in turn. Arguments and exceptions as apply()'s;
   * applyColumns() throws when out does not hold width * height values.
   */
  void applyRows(const std::vector<float>& depth,
                 std::uint32_t width,
                 std::uint32_t height,
                 std::vector<float>& out) const;

  /// The second part of apply(): see applyRows().
  void applyColumns(std::uint32_t width, std::uint32_t height, std::vector<float>& out) const;

private:
  Parameters params_;    ///< validated knobs
  unsigned threads_ = 1; ///< worker threads (>= 1)
};

} // namespace dynvo
