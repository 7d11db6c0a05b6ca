// SPDX-License-Identifier: BSD-3-Clause
// Per-frame label images, labelled clouds and object-motion lines, as written by the
// segmentation apps.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/image.h>

#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace dynvo {

/** \brief Label image of a segmentation: the pixels of segments[s] get labels[s], every
 * other pixel 0 (no measurement). Indices are linear pixel indices (row * width + col).
 */
DYNVO_EXPORTS LabelImage paintLabelImage(const std::vector<pcl::PointIndices>& segments,
                                         const std::vector<std::uint8_t>& labels,
                                         std::uint32_t width,
                                         std::uint32_t height);

/// A timestamp as written in file names and index files: "%.6f" (seconds).
DYNVO_EXPORTS std::string formatStamp(double timestamp);

/// File name of a frame's images (colour, depth, labels): "<timestamp %.6f>.png".
DYNVO_EXPORTS std::string stampedPngName(double timestamp);

/// Writes an 8-bit single-channel PNG. \throws pcl::IOException naming the file on failure
DYNVO_EXPORTS void writeLabelImage(const std::string& path, const LabelImage& labels);

/// Reads an 8-bit single-channel PNG. \throws pcl::IOException naming the file and problem
DYNVO_EXPORTS LabelImage readLabelImage(const std::string& path);

/** \brief Writes a frame and its labels as an organized pcl::PointXYZRGBL PCD
 * (binary_compressed), which pcl_viewer colours by label. Point i is cloud[i] (NaN
 * where there is no depth) with label labels[i] (0 no label, 1 static, 2.. objects).
 * The file is written beside its destination and renamed into place (PartialFile).
 * \param[in] path destination ("<stamp>.pcd" reads back through PcdSequenceSource)
 * \param[in] cloud the organized frame (metres)
 * \param[in] labels one label per point of cloud, row-major
 * \throws std::invalid_argument when labels and cloud differ in size
 * \throws pcl::IOException naming the file when it cannot be written
 */
DYNVO_EXPORTS void writeLabelledCloud(const std::string& path,
                                      const pcl::PointCloud<pcl::PointXYZRGB>& cloud,
                                      const std::vector<std::uint8_t>& labels);

/** \brief One line of an objects file: "timestamp id n_pixels tx ty tz qx qy qz qw", where the
 * pose is the object's frame-to-frame motion T_curr_prev (metres) in the current camera frame.
 */
DYNVO_EXPORTS std::string formatObjectMotionLine(double timestamp,
                                                 int id,
                                                 std::size_t pixels,
                                                 const Eigen::Matrix4f& T_curr_prev);

} // namespace dynvo
