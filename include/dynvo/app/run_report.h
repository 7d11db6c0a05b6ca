// SPDX-License-Identifier: BSD-3-Clause
// What an odometry run writes (trajectory, label images, labelled clouds, object
// motions and trajectories) and prints.
#pragma once

#include <dynvo/app/object_trajectories.h>
#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/io/frame.h>
#include <dynvo/io/partial_file.h>
#include <dynvo/io/trajectory_io.h>

#include <cstddef>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace dynvo::app {

/// Where a run writes ("" = not written).
struct RunOutputPaths {
  std::string trajectory;       ///< TUM trajectory of the camera
  std::string labels_dir;       ///< "<stamp>.png" label image per frame
  std::string objects;          ///< object-motion lines (formatObjectMotionLine())
  std::string clouds_dir;       ///< "<stamp>.pcd" labelled cloud (writeLabelledCloud())
  std::size_t clouds_every = 1; ///< clouds of frames 0, N, 2N, ... only (N >= 1)
  std::string objects_dir;   ///< object trajectories and summary (writeObjectsFolder())
  std::string frames_report; ///< one TSV line per frame (formatFrameReportLine())
};

/// The header line of a frames report (tab-separated column names after "# ").
DYNVO_EXPORTS std::string frameReportHeader();

/** \brief One frame of a frames report, tab-separated: stamp (s), lost (0/1), reason
 * (lostReasonName()), static cells of the fit that gave the pose, its mean squared residual
 * (m^2), keyframe (frame number of the keyframe the pose was measured against, -1 none),
 * moving share (pixels labelled 2.. over pixels with a label), then the stage times and the
 * total (ms).
 */
DYNVO_EXPORTS std::string formatFrameReportLine(const FrameResult& result);

/** \brief A text file written line by line beside its destination ("<file>.partial") and
 * moved into place by commit(); destroyed uncommitted, it leaves the destination as it was.
 */
class DYNVO_EXPORTS LineFile {
public:
  /// \throws pcl::IOException naming path when the partial file cannot be created
  LineFile(const std::string& path, const std::string& header);

  /// Appends line and a newline. \throws pcl::IOException naming the file on failure
  void write(const std::string& line);

  /// Moves the file into place. \throws pcl::IOException naming the file on failure
  void commit();

private:
  PartialFile file_;
  std::ofstream out_;
};

/** \brief The files of a run. Label images and clouds are written as frames arrive
 * (each replaced whole); the trajectory, the objects file and the objects folder are
 * written by finish() (the objects file beside its destination, "<file>.partial", until
 * then), so an interrupted run leaves earlier files untouched. finish() writes nothing
 * when no frame was added, so a run that fails on its first frame replaces nothing.
 */
class DYNVO_EXPORTS RunOutputs {
public:
  /** \param[in] paths what to write; folders are created if needed
   * \param[in] initial_groundtruth when set, poses start at its pose nearest the first frame
   * \throws std::invalid_argument when paths.clouds_every is 0
   * \throws pcl::IOException when a folder or file cannot be created
   */
  explicit RunOutputs(const RunOutputPaths& paths,
                      const Trajectory* initial_groundtruth = nullptr);

  /// Records one frame; a frame the pipeline could not process (FrameResult::error) gets a
  /// trajectory line but no label image, cloud or object pose. \throws pcl::IOException
  /// when a file cannot be written
  void add(const Frame& frame, const FrameResult& result);

  /// Writes the trajectory and the objects folder and moves the objects file into
  /// place, when a frame was added.
  /// \throws pcl::IOException when a file cannot be written
  void finish();

  /// Camera poses so far (camera-to-world).
  const Trajectory& trajectory() const { return trajectory_; }

private:
  RunOutputPaths paths_;
  const Trajectory* initial_groundtruth_;
  Eigen::Isometry3d T_world_start_ = Eigen::Isometry3d::Identity();
  std::unique_ptr<LineFile> objects_;       ///< paths_.objects, or none
  std::unique_ptr<LineFile> frames_report_; ///< paths_.frames_report, or none
  Trajectory trajectory_;
  ObjectTrajectories object_trajectories_;
};

/// The median of the values (the upper middle one of an even count); 0 when empty.
DYNVO_EXPORTS double median(std::vector<double> values);

/// Progress bar on a terminal, per-frame timings, and the closing lines of a run.
class DYNVO_EXPORTS RunReport {
public:
  /// \param[in] expected_frames frames the run will process (0 = unknown)
  explicit RunReport(std::size_t expected_frames);

  /// Records one frame (frame 0 only prepares the pipeline and is not timed).
  void add(const FrameResult& result);

  /// Frames recorded.
  std::size_t frames() const { return frames_; }

  /// Median time per frame after frame 0 (ms, decoding excluded); 0 before the second frame.
  double medianMs() const;

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
