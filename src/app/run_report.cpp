// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/run_report.h>
#include <dynvo/common/conventions.h>
#include <dynvo/common/timestamps.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/label_io.h>
#include <dynvo/common/lens_undistortion.h>
#include <dynvo/io/partial_file.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <stdexcept>
#include <unistd.h>

namespace dynvo::app {

namespace fs = std::filesystem;

RunOutputs::RunOutputs(const RunOutputPaths& paths,
                       const Trajectory* initial_groundtruth)
    : paths_(paths)
    , initial_groundtruth_(initial_groundtruth)
{
  if (paths_.clouds_every < 1)
    throw std::invalid_argument("[dynvo::app::RunOutputs] clouds_every must be >= 1");
  for (const std::string& folder :
       {paths_.labels_dir, paths_.clouds_dir, paths_.objects_dir}) {
    if (folder.empty())
      continue;
    std::error_code error;
    fs::create_directories(folder, error);
    if (error || !fs::is_directory(folder))
      throw pcl::IOException(folder + ": cannot create the output folder");
  }
  if (!paths_.objects.empty())
    objects_ = std::make_unique<LineFile>(
        paths_.objects,
        "# timestamp id n_pixels tx ty tz qx qy qz qw (T_curr_prev, metres)");
  if (!paths_.frames_report.empty())
    frames_report_ =
        std::make_unique<LineFile>(paths_.frames_report, frameReportHeader());
}

void
RunOutputs::add(const Frame& frame, const FrameResult& result)
{
  if (trajectory_.empty() && initial_groundtruth_ && !initial_groundtruth_->empty()) {
    std::vector<double> stamps;
    for (const auto& pose : *initial_groundtruth_)
      stamps.push_back(pose.timestamp);
    T_world_start_ = (*initial_groundtruth_)[findClosestIndex(stamps, result.timestamp)]
                         .T_world_camera;
  }
  StampedPose pose;
  pose.timestamp = result.timestamp;
  pose.T_world_camera = T_world_start_ * Eigen::Isometry3d(result.T_world_curr);
  trajectory_.push_back(pose);

  // A frame the pipeline could not process (result.error) has no image to label.
  if (result.error.empty()) {
    if (!paths_.labels_dir.empty()) {
      // On the recording's pixels, where the frame was undistorted.
      const LabelImage labels{result.width, result.height, result.labels};
      writeLabelImage(
          (fs::path(paths_.labels_dir) / stampedPngName(result.timestamp)).string(),
          frame.undistortion ? frame.undistortion->distort(labels) : labels);
    }
    if (!paths_.clouds_dir.empty() &&
        (trajectory_.size() - 1) % paths_.clouds_every == 0)
      writeLabelledCloud(
          (fs::path(paths_.clouds_dir) / (formatStamp(result.timestamp) + ".pcd"))
              .string(),
          *frame.cloud, result.labels);
    if (!paths_.objects_dir.empty())
      object_trajectories_.add(result, *frame.cloud, pose.T_world_camera);
  }
  if (objects_)
    for (std::size_t s = 1; s < result.segments.size(); ++s)
      objects_->write(formatObjectMotionLine(result.timestamp, result.segment_labels[s],
                                             result.segments[s].indices.size(),
                                             result.motions[s]));
  if (frames_report_)
    frames_report_->write(formatFrameReportLine(result));
}

void
RunOutputs::finish()
{
  // Nothing computed: every existing file stays as it was (the partial file goes).
  if (trajectory_.empty())
    return;
  if (!paths_.trajectory.empty())
    writeTrajectory(paths_.trajectory, trajectory_);
  if (!paths_.objects_dir.empty())
    writeObjectsFolder(paths_.objects_dir, object_trajectories_.tracks(), trajectory_);
  for (const auto& file : {objects_.get(), frames_report_.get()})
    if (file)
      file->commit();
}

std::string
frameReportHeader()
{
  return "# stamp\tlost\treason\tstatic_cells\tresidual_m2\tkeyframe\tmoving_share\t"
         "scene_flow_ms\tsegmentation_ms\tregistration_ms\ttotal_ms";
}

std::string
formatFrameReportLine(const FrameResult& result)
{
  std::size_t labelled = 0;
  std::size_t moving = 0;
  for (const std::uint8_t label : result.labels) {
    labelled += label != LABEL_NONE;
    moving += label > LABEL_STATIC;
  }
  const double share =
      labelled > 0 ? static_cast<double>(moving) / static_cast<double>(labelled) : 0.0;
  char line[256];
  std::snprintf(
      line, sizeof(line), "%s\t%d\t%s\t%zu\t%.3e\t%ld\t%.4f\t%.2f\t%.2f\t%.2f\t%.2f",
      formatStamp(result.timestamp).c_str(), result.lost ? 1 : 0,
      result.recovered ? "recovered_dense" : lostReasonName(result.lost_reason),
      result.static_cells, result.residual, result.keyframe_index, share,
      result.times.scene_flow_ms, result.times.segmentation_ms,
      result.times.registration_ms, result.times.total_ms);
  return line;
}

LineFile::LineFile(const std::string& path, const std::string& header)
    : file_(path)
{
  out_.open(file_.partialPath(), std::ios::trunc);
  if (!out_)
    throw pcl::IOException(path + ": cannot write the file");
  write(header);
}

void
LineFile::write(const std::string& line)
{
  out_ << line << '\n';
  if (!out_)
    throw pcl::IOException(file_.path() + ": write failed");
}

void
LineFile::commit()
{
  out_.close();
  if (!out_)
    throw pcl::IOException(file_.path() + ": write failed");
  file_.commit();
}

RunReport::RunReport(std::size_t expected_frames)
    : expected_frames_(expected_frames)
    , terminal_(::isatty(STDERR_FILENO) == 1)
{
}

void
RunReport::add(const FrameResult& result)
{
  if (frames_ > 0) {
    total_ms_.push_back(result.times.total_ms);
    flow_ms_.push_back(result.times.scene_flow_ms);
    segmentation_ms_.push_back(result.times.segmentation_ms);
    registration_ms_.push_back(result.times.registration_ms);
  }
  lost_ += result.lost ? 1 : 0;
  ++frames_;
  if (terminal_) {
    const int width = 40;
    const int done =
        expected_frames_ > 0
            ? static_cast<int>(width * std::min(frames_, expected_frames_) /
                               expected_frames_)
            : 0;
    std::fprintf(stderr, "\r[%s%s] %zu/%zu frames, %.1f ms",
                 std::string(done, '#').c_str(), std::string(width - done, ' ').c_str(),
                 frames_, expected_frames_, result.times.total_ms);
    std::fflush(stderr);
  }
}

double
median(std::vector<double> values)
{
  if (values.empty())
    return 0.0;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double
RunReport::medianMs() const
{
  return median(total_ms_);
}

void
RunReport::printSummary(const std::string& accuracy) const
{
  if (terminal_)
    std::fprintf(stderr, "\n");
  const double mean =
      total_ms_.empty()
          ? 0.0
          : std::accumulate(total_ms_.begin(), total_ms_.end(), 0.0) / total_ms_.size();
  std::printf("stages median_ms: scene_flow=%.2f segmentation=%.2f registration=%.2f\n",
              median(flow_ms_), median(segmentation_ms_), median(registration_ms_));
  if (!accuracy.empty())
    std::printf("%s\n", accuracy.c_str());
  std::printf("frames=%zu lost=%zu median_ms=%.2f mean_ms=%.2f fps=%.1f\n", frames_,
              lost_, medianMs(), mean, mean > 0.0 ? 1000.0 / mean : 0.0);
}

std::string
RunReport::accuracy(const Trajectory& groundtruth, const Trajectory& estimate)
{
  try {
    return formatMetrics(computeRpe(groundtruth, estimate),
                         computeAte(groundtruth, estimate));
  }
  catch (const std::invalid_argument& e) {
    return std::string("accuracy not available: ") + e.what();
  }
}

} // namespace dynvo::app
