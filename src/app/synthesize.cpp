// SPDX-License-Identifier: BSD-3-Clause
// dynvo_synthesize's file side: frames from dynvo_synth, files through dynvo_io.
#include <dynvo/app/synthesize.h>

#include <dynvo/common/timestamps.h>
#include <dynvo/io/image_io.h>
#include <dynvo/io/label_io.h>
#include <dynvo/io/sequence_writer.h>
#include <dynvo/io/trajectory_io.h>
#include <dynvo/io/tum_folder_source.h>
#include <dynvo/synth/scene_compositor.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace dynvo::app {

namespace fs = std::filesystem;

namespace {

/// Ground truth is interpolated across gaps up to this long (s); the TUM motion capture
/// runs at 100 Hz but drops samples (fr1/xyz has a 0.11 s gap).
constexpr double MAX_GROUNDTRUTH_GAP = 0.25;

std::vector<ObjectPose>
objectPoses(const std::vector<ObjectState>& objects)
{
  std::vector<ObjectPose> poses;
  for (const ObjectState& object : objects)
    poses.push_back({object.id, object.T_world_object, object.moving});
  return poses;
}

/// \throws pcl::IOException naming `file` when the images' sizes differ from w x h
void
checkSize(const ColorImage& color,
          const RawDepthImage& depth,
          std::uint32_t width,
          std::uint32_t height,
          const fs::path& file)
{
  if (color.width != width || color.height != height || depth.width != width ||
      depth.height != height)
    throw pcl::IOException(file.string() +
                           ": image size differs from the first frame's");
}

} // namespace

void
writeSyntheticSequence(const SynthOptions& options,
                       const std::string& folder,
                       int threads)
{
  if (threads < 1)
    throw std::invalid_argument("[dynvo::app::writeSyntheticSequence] threads must "
                                "be >= 1, got " +
                                std::to_string(threads));
  const SceneSynthesizer synth(options);
  const SequenceWriter writer(folder, SceneSynthesizer::DEPTH_PNG_SCALE);
  const int frames = options.frames;

  std::vector<SequenceIndexEntry> entries(frames);
  Trajectory groundtruth(frames);
  std::atomic<int> next_frame{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  const auto worker = [&]() {
    try {
      for (int k = next_frame++; k < frames && !failed; k = next_frame++) {
        const SynthFrame frame = synth.render(k);
        writer.writeFrame(frame.timestamp, frame.timestamp, frame.color,
                          quantizeDepth(frame.depth, SceneSynthesizer::DEPTH_PNG_SCALE),
                          {frame.color.width, frame.color.height, frame.labels});
        entries[k] = {frame.timestamp, frame.timestamp, objectPoses(frame.objects)};
        groundtruth[k] = {frame.timestamp, frame.T_world_camera};
      }
    }
    catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!first_error)
        first_error = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(threads, frames); ++t)
    pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool)
    thread.join();
  if (first_error)
    std::rethrow_exception(first_error);
  writer.writeIndex("# dynvo synthetic scenario '" + options.scenario + "', seed " +
                        std::to_string(options.seed) + "\n",
                    entries, groundtruth);
}

std::size_t
writeCompositeSequence(const SynthOptions& options,
                       const CompositeOptions& composite,
                       const std::string& folder)
{
  SceneCompositor compositor(options); // throws first for a scenario without objects
  if (composite.frames < 0)
    throw std::invalid_argument("[dynvo::app::writeCompositeSequence] frames must be "
                                ">= 0, got " +
                                std::to_string(composite.frames));
  const fs::path recording(composite.recording);
  TumFolderSource::Options source_options;
  source_options.intrinsics = composite.intrinsics;
  source_options.depth_scale = composite.depth_scale;
  const TumFolderSource source(composite.recording, source_options);
  const fs::path groundtruth_path = recording / "groundtruth.txt";
  const Trajectory groundtruth = readTrajectory(groundtruth_path.string());
  // The associated pairs with a camera: the recording's ground truth interpolated at the
  // colour stamp. Pairs without one (TUM fr3 starts before its motion capture) are skipped.
  const std::size_t wanted =
      composite.frames > 0 ? static_cast<std::size_t>(composite.frames) : source.size();
  std::vector<TumFolderSource::Entry> entries;
  std::vector<double> rgb_stamps;
  std::vector<Eigen::Isometry3d> T_world_camera;
  std::size_t skipped = 0;
  for (const TumFolderSource::Entry& entry : source.entries()) {
    if (entries.size() == wanted)
      break;
    const auto pose =
        interpolatePose(groundtruth, entry.rgb_stamp, MAX_GROUNDTRUTH_GAP);
    if (!pose) {
      ++skipped;
      continue;
    }
    entries.push_back(entry);
    rgb_stamps.push_back(entry.rgb_stamp);
    T_world_camera.push_back(*pose);
  }
  if (entries.empty())
    throw pcl::IOException(
        recording.string() +
        (source.size() == 0 ? ": no associated colour/depth pairs"
                            : ": no associated colour/depth pair has ground truth in " +
                                  groundtruth_path.string()));
  const std::size_t frames = entries.size();

  // Everything that can fail on the inputs is checked before the folder is made.
  const ColorImage first_color =
      readColorImage((recording / entries[0].rgb_file).string());
  const RawDepthImage first_depth =
      readRawDepthImage((recording / entries[0].depth_file).string());
  checkSize(first_color, first_depth, first_color.width, first_color.height,
            recording / entries[0].depth_file);
  if (std::all_of(first_depth.data.begin(), first_depth.data.end(),
                  [](std::uint16_t raw) {
                    return raw == 0;
                  }))
    throw pcl::IOException((recording / entries[0].depth_file).string() +
                           ": first depth image has no measurement");
  compositor.setRecording(composite.intrinsics, source.depthScale(), rgb_stamps,
                          T_world_camera, first_color, first_depth);

  const SequenceWriter writer(folder, SceneSynthesizer::DEPTH_PNG_SCALE);
  std::vector<SequenceIndexEntry> index;
  for (std::size_t k = 0; k < frames; ++k) {
    const TumFolderSource::Entry& entry = entries[k];
    const ColorImage color =
        k == 0 ? first_color : readColorImage((recording / entry.rgb_file).string());
    const RawDepthImage depth =
        k == 0 ? first_depth
               : readRawDepthImage((recording / entry.depth_file).string());
    checkSize(color, depth, first_color.width, first_color.height,
              recording / entry.rgb_file);
    const CompositeFrame frame = compositor.composite(k, color, depth);
    writer.writeFrame(entry.rgb_stamp, entry.depth_stamp, frame.color, frame.depth,
                      frame.labels);
    index.push_back({entry.rgb_stamp, entry.depth_stamp, objectPoses(frame.objects)});
  }
  writer.writeIndex("# dynvo composite of scenario '" + options.scenario + "' (seed " +
                        std::to_string(options.seed) + ", objects scaled by " +
                        std::to_string(compositor.objectScale()) + ") into " +
                        recording.string() + "\n",
                    index, groundtruth);
  return skipped;
}

} // namespace dynvo::app
