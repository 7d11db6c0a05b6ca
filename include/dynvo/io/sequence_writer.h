// SPDX-License-Identifier: BSD-3-Clause
// Writes RGB-D sequences with ground truth in the TUM folder layout (dynvo_synthesize).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/image.h>
#include <dynvo/common/trajectory.h>

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace dynvo {

/// Pose of one object at one frame, as written to objects.txt.
struct ObjectPose {
  int id = 0; ///< object id (its label value)
  Eigen::Isometry3d T_world_object = Eigen::Isometry3d::Identity(); ///< object-to-world
  bool moving = false; ///< the pose changed since the previous frame
};

/// Stamps and object poses of one frame of a written sequence.
struct SequenceIndexEntry {
  double rgb_stamp = 0.0;          ///< colour stamp (s)
  double depth_stamp = 0.0;        ///< depth stamp (s)
  std::vector<ObjectPose> objects; ///< every object, in id order
};

/** \brief Writes a sequence folder: rgb/, depth/, labels/ (PNGs named "<stamp %.6f>.png",
 * labels by the colour stamp), then rgb.txt, depth.txt, objects.txt and groundtruth.txt.
 *
 * objects.txt has one line per frame and object: "timestamp id tx ty tz qx qy qz qw
 * moving" (object-to-world, metres; moving 0 or 1). Frames may be written from several
 * threads at once (each call writes its own files only).
 */
class DYNVO_EXPORTS SequenceWriter {
public:
  /** \brief Creates rgb/, depth/ and labels/ in folder.
   * \param[in] folder must not exist or be empty; nothing existing is overwritten
   * \param[in] depth_scale raw depth units per metre of the depth PNGs (stated in depth.txt)
   * \throws pcl::IOException when the folder is not empty or cannot be created
   */
  SequenceWriter(const std::string& folder, double depth_scale);

  /// rgb/<rgb stamp>.png, depth/<depth stamp>.png, labels/<rgb stamp>.png.
  /// \throws pcl::IOException when a file cannot be written or sizes disagree
  void writeFrame(double rgb_stamp,
                  double depth_stamp,
                  const ColorImage& color,
                  const RawDepthImage& depth,
                  const LabelImage& labels) const;

  /** \brief rgb.txt, depth.txt, objects.txt (from the entries) and groundtruth.txt.
   * \param[in] origin comment lines ("# ...\n") naming where the sequence came from
   * \throws pcl::IOException when a file cannot be written
   */
  void writeIndex(const std::string& origin,
                  const std::vector<SequenceIndexEntry>& entries,
                  const Trajectory& groundtruth) const;

private:
  std::string folder_;
  double depth_scale_;
};

} // namespace dynvo
