// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/run_report.h>
#include <dynvo/common/timestamps.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/partial_file.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <unistd.h>

namespace dynvo::app {

namespace fs = std::filesystem;

namespace {

double
median(std::vector<double> values)
{
  if (values.empty())
    return 0.0;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

} // namespace

RunOutputs::RunOutputs(const std::string& trajectory_path,
                       const std::string& labels_dir,
                       const std::string& objects_path,
                       const Trajectory* initial_groundtruth)
    : trajectory_path_(trajectory_path)
    , labels_dir_(labels_dir)
    , objects_path_(objects_path)
    , initial_groundtruth_(initial_groundtruth)
{
  if (!labels_dir_.empty()) {
    std::error_code error;
    fs::create_directories(labels_dir_, error);
    if (error || !fs::is_directory(labels_dir_))
      throw pcl::IOException(labels_dir_ + ": cannot create the labels folder");
  }
  if (!objects_path_.empty()) {
    objects_file_ = std::make_unique<PartialFile>(objects_path_);
    objects_.open(objects_file_->partialPath(), std::ios::trunc);
    if (!objects_)
      throw pcl::IOException(objects_path_ + ": cannot write objects file");
    objects_ << "# timestamp id n_pixels tx ty tz qx qy qz qw (T_curr_prev, metres)\n";
  }
}

void
RunOutputs::add(const FrameResult& result)
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
  if (!labels_dir_.empty() && result.error.empty())
    writeLabelImage((fs::path(labels_dir_) / stampedPngName(result.timestamp)).string(),
                    {result.width, result.height, result.labels});
  if (objects_.is_open()) {
    for (std::size_t s = 1; s < result.segments.size(); ++s)
      objects_ << formatObjectMotionLine(result.timestamp, result.segment_labels[s],
                                         result.segments[s].indices.size(),
                                         result.motions[s])
               << '\n';
    if (!objects_)
      throw pcl::IOException(objects_path_ + ": write failed");
  }
}

void
RunOutputs::finish()
{
  // Nothing computed: every existing file stays as it was (the partial file goes).
  if (trajectory_.empty())
    return;
  if (!trajectory_path_.empty())
    writeTrajectory(trajectory_path_, trajectory_);
  if (objects_file_) {
    objects_.close();
    if (!objects_)
      throw pcl::IOException(objects_path_ + ": write failed");
    objects_file_->commit();
  }
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
              lost_, median(total_ms_), mean, mean > 0.0 ? 1000.0 / mean : 0.0);
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
