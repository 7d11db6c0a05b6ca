// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/segmentation_evaluation.h>

#include <dynvo/common/timestamps.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/tum_folder_source.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace dynvo::app {

namespace fs = std::filesystem;

namespace {

/// True for a stem as formatStamp() writes it: digits with at most one '.'.
bool
isDecimalStamp(const std::string& stem)
{
  const auto digits = std::count_if(stem.begin(), stem.end(), [](unsigned char c) {
    return std::isdigit(c) != 0;
  });
  const auto dots = std::count(stem.begin(), stem.end(), '.');
  return digits > 0 && dots <= 1 &&
         static_cast<std::size_t>(digits + dots) == stem.size();
}

struct StampedPath {
  double stamp;
  fs::path path;
};

/// The <stamp>.png files of a prediction folder, by increasing stamp.
std::vector<StampedPath>
listPredictions(const std::string& folder)
{
  if (!fs::is_directory(folder))
    throw pcl::IOException(folder +
                           ": not a directory (expected predicted label PNGs)");
  std::vector<StampedPath> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".png")
      continue;
    const std::string stem = entry.path().stem().string();
    if (!isDecimalStamp(stem))
      throw pcl::IOException(entry.path().string() +
                             ": label file name is not a timestamp (<stamp>.png)");
    files.push_back({std::stod(stem), entry.path()});
  }
  if (files.empty())
    throw pcl::IOException(folder + ": no label PNGs (<stamp>.png)");
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return a.stamp < b.stamp;
  });
  return files;
}

/// \throws pcl::IOException naming both files when the label image is not width x height
void
checkSize(const LabelImage& labels,
          const std::string& labels_path,
          std::uint32_t width,
          std::uint32_t height,
          const std::string& reference_path)
{
  if (labels.width != width || labels.height != height)
    throw pcl::IOException(
        labels_path + ": label image is " + std::to_string(labels.width) + "x" +
        std::to_string(labels.height) + " but " + reference_path + " is " +
        std::to_string(width) + "x" + std::to_string(height));
}

/// The tolerance as the error message prints it ("%.6f").
std::string
formatTolerance(double seconds)
{
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", seconds);
  return text;
}

} // namespace

SegmentationEvaluation
evaluateSegmentation(const std::string& predicted_dir,
                     const std::string& sequence_dir,
                     const SegmentationEvaluationOptions& options)
{
  if (!(options.max_difference >= 0.0))
    throw std::invalid_argument("[dynvo::evaluateSegmentation] max_difference must "
                                "not be negative");
  const auto predictions = listPredictions(predicted_dir);
  const TumFolderSource sequence(sequence_dir, TumFolderSource::Options{});
  const fs::path labels_dir = fs::path(sequence_dir) / "labels";

  SegmentationEvaluation result;
  result.has_truth_labels = fs::is_directory(labels_dir);
  result.sequence_frames = sequence.size();
  result.predictions = predictions.size();

  std::vector<double> frame_stamps, prediction_stamps;
  for (const auto& entry : sequence.entries())
    frame_stamps.push_back(entry.rgb_stamp);
  for (const auto& prediction : predictions)
    prediction_stamps.push_back(prediction.stamp);
  const auto pairs =
      associateTimestamps(frame_stamps, prediction_stamps, options.max_difference);
  if (pairs.empty())
    throw pcl::IOException(predicted_dir + ": no label PNG is within " +
                           formatTolerance(options.max_difference) +
                           " s of a frame of " + sequence_dir);

  std::vector<LabelFrameCounts> counts;
  counts.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    const Frame frame = sequence.read(i);
    const std::string depth_path =
        (fs::path(sequence_dir) / sequence.entries()[i].depth_file).string();
    LabelImage truth{frame.depth.width, frame.depth.height,
                     std::vector<std::uint8_t>(frame.depth.data.size(), 0)};
    std::string truth_path = depth_path; // without labels/ the depth sets the size
    if (result.has_truth_labels) {
      truth_path = (labels_dir / stampedPngName(frame_stamps[i])).string();
      truth = readLabelImage(truth_path);
      checkSize(truth, truth_path, frame.depth.width, frame.depth.height, depth_path);
    }
    const std::string predicted_path = predictions[j].path.string();
    const LabelImage predicted = readLabelImage(predicted_path);
    checkSize(predicted, predicted_path, truth.width, truth.height, truth_path);
    counts.push_back(countLabelFrame(predicted, truth, validDepthMask(frame.depth)));
  }
  result.scores = summarizeSegmentation(counts, options.background_precision);
  return result;
}

} // namespace dynvo::app
