// SPDX-License-Identifier: BSD-3-Clause
// What an odometry run writes (trajectory, label images, object motions) and prints.
#pragma once

#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/io/partial_file.h>
#include <dynvo/io/trajectory_io.h>

#include <cstddef>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace dynvo::app {

/** \brief The files of a run. Label images are written as frames arrive (each replaced
 * whole); the trajectory and the objects file are written beside their destination
 * ("<file>.partial") and moved into place by finish(), so an interrupted run leaves
 * earlier files untouched. finish() writes nothing when no frame was added, so a run that
 * fails on its first frame replaces nothing.
 */
class DYNVO_EXPORTS RunOutputs {
public:
  /** \param[in] trajectory_path TUM trajectory ("" = none)
   * \param[in] labels_dir folder for "<stamp>.png" label images ("" = none); created if needed
   * \param[in] objects_path object-motion lines ("" = none)
   * \param[in] initial_groundtruth when set, poses start at its pose nearest the first frame
   * \throws pcl::IOException when a folder or file cannot be created
   */
  RunOutputs(const std::string& trajectory_path,
             const std::string& labels_dir,
             const std::string& objects_path,
             const Trajectory* initial_groundtruth = nullptr);

  /// Records one frame; a frame the pipeline could not process (FrameResult::error) gets a
  /// trajectory line but no label image. \throws pcl::IOException when a file cannot be
  /// written
  void add(const FrameResult& result);

  /// Writes the trajectory and moves the objects file into place, when a frame was added.
  /// \throws pcl::IOException when a file cannot be written
  void finish();

  /// Camera poses so far (camera-to-world).
  const Trajectory& trajectory() const { return trajectory_; }

private:
  std::string trajectory_path_;
  std::string labels_dir_;
  std::string objects_path_;
  const Trajectory* initial_groundtruth_;
  Eigen::Isometry3d T_world_start_ = Eigen::Isometry3d::Identity();
  std::unique_ptr<PartialFile> objects_file_; ///< removes the partial file unless moved
  std::ofstream objects_;
  Trajectory trajectory_;
};

/// Progress bar on a terminal, per-frame timings, and the closing lines of a run.
class DYNVO_EXPORTS RunReport {
public:
  /// \param[in] expected_frames frames the run will process (0 = unknown)
  explicit RunReport(std::size_t expected_frames);

  /// Records one frame (frame 0 only prepares the pipeline and is not timed).
  void add(const FrameResult& result);

  /// Frames recorded.
  std::size_t frames() const { return frames_; }

  /// Prints the per-stage medians, then `accuracy` when not empty, and last
  /// "frames=<n> lost=<n> median_ms=<x> mean_ms=<x> fps=<x>" (per frame, decoding excluded).
  void printSummary(const std::string& accuracy = "") const;

  /// The dynvo_evaluate line of the estimate against the ground truth (or why there is none).
  static std::string accuracy(const Trajectory& groundtruth,
                              const Trajectory& estimate);

private:
  std::size_t expected_frames_;
  std::size_t frames_ = 0;
  std::size_t lost_ = 0;
  bool terminal_;
  std::vector<double> total_ms_, flow_ms_, segmentation_ms_, registration_ms_;
};

} // namespace dynvo::app
