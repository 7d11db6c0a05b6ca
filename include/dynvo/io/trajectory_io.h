// SPDX-License-Identifier: BSD-3-Clause
// TUM trajectory files: "timestamp tx ty tz qx qy qz qw", camera-to-world.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/trajectory.h>

#include <Eigen/Geometry>

#include <map>
#include <string>
#include <vector>

namespace dynvo {

/** \brief Read a TUM trajectory file.
 *
 * '#' comment lines and blank lines are skipped. Every other line must hold exactly 8
 * finite numbers, timestamps must increase strictly, and the quaternion norm must be
 * within 1e-3 of 1 (it is then normalised).
 * \throws pcl::IOException "<file>:<line>: <problem>" on any violation or when the file
 *         cannot be opened
 */
DYNVO_EXPORTS Trajectory readTrajectory(const std::string& path);

/** \brief Read the objects.txt of a dynvo_synthesize sequence: lines "timestamp id tx
 * ty tz qx qy qz qw moving" (object-to-world, metres; moving 0 or 1), with the checks
 * of readTrajectory().
 * \return the poses of each object id (1..255), by increasing stamp
 * \throws pcl::IOException "<file>:<line>: <problem>" on any violation or when the file
 *         cannot be opened
 */
DYNVO_EXPORTS std::map<int, Trajectory> readObjectPoses(const std::string& path);

/** \brief Write a TUM trajectory file (timestamps "%.6f", qw >= 0).
 * The file is written beside its destination and renamed into place, so a failure never
 * leaves a truncated file.
 * \param[in] path destination
 * \param[in] trajectory the poses
 * \param[in] pose_name what the poses map, for the header line (e.g. "object-to-world")
 * \throws pcl::IOException when it cannot be written
 */
DYNVO_EXPORTS void writeTrajectory(const std::string& path,
                                   const Trajectory& trajectory,
                                   const std::string& pose_name = "camera-to-world");

/// One TUM line for a pose, without the newline.
DYNVO_EXPORTS std::string formatTumLine(const StampedPose& pose);

} // namespace dynvo
