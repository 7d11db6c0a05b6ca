// SPDX-License-Identifier: BSD-3-Clause
// Segmentation and tracking on synthetic dynamic sequences (SceneSynthesizer + scene flow).
//
// Frames are rendered at VGA with 16 px cells (40 x 30 grid), as in the paper. At 320 x 240
// with 8 px cells the LK window (15 px) spans two cells, so object boundaries blur over
// more cells and the cell IoU drops by about 0.1. Cell ground truth is the majority of the
// per-pixel labels (0 static, k object k while it moves) of the cell; IoU is taken over
// the cells with valid_3d flow, the only ones the segmentation can label.
// Depth noise is off: with the Kinect model (sigma = 1.2e-3 z^2, 11 mm at 3 m) the fixed
// th_inlier of 5.5 mm rejects most points beyond 2 m (docs/algorithm.md §12), and the IoU on
// static_two falls to about 0.02.
#include <dynvo/io/frame.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>
#include <dynvo/synth/scene_synthesizer.h>

#include <pcl/point_types.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <map>
#include <string>
#include <vector>

namespace {

constexpr int WIDTH = 640;
constexpr int HEIGHT = 480;
constexpr int CELL = 16;
constexpr int COLS = WIDTH / CELL;
constexpr int ROWS = HEIGHT / CELL;
/// Objects moving less than this per frame are not scored (issue: "more than 1 cm per frame").
constexpr double MIN_OBJECT_SPEED = 0.01;

using Point = pcl::PointXYZRGB;

/// One processed frame: ground truth and output per cell.
struct FrameRecord {
  std::vector<std::uint8_t> truth;  ///< majority synthesizer label per cell
  std::vector<std::uint8_t> valid;  ///< valid_3d flow per cell
  std::vector<std::uint8_t> labels; ///< output label per cell
  std::map<int, double> speed;      ///< object id -> centre displacement since k-1 (m)
  std::map<int, bool> moving;       ///< object id -> synthesizer "moving" flag
  std::map<int, std::vector<char>> visible; ///< object id -> cells whose centre sees it
};

/// Cells whose centre ray hits the object's box first (moving or not): ray/box slab test,
/// accepted when the hit depth matches the rendered depth within 1 cm (noise-free depth).
std::vector<char>
visibleCells(const dynvo::SynthFrame& frame,
             const dynvo::ObjectState& object,
             const dynvo::CameraIntrinsics& K)
{
  std::vector<char> cells(COLS * ROWS, 0);
  const Eigen::Isometry3d T_object_camera =
      object.T_world_object.inverse() * frame.T_world_camera;
  const Eigen::Vector3d origin = T_object_camera.translation();
  for (int i = 0; i < COLS * ROWS; ++i) {
    const int u = (i % COLS) * CELL + CELL / 2, v = (i / COLS) * CELL + CELL / 2;
    // Ray with unit z in the camera frame: the ray parameter is the camera depth.
    const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
    const Eigen::Vector3d d = T_object_camera.linear() * ray;
    double near = 0.0, far = 1e9;
    for (int axis = 0; axis < 3; ++axis) {
      const double t1 = (-object.half_extents[axis] - origin[axis]) / d[axis];
      const double t2 = (object.half_extents[axis] - origin[axis]) / d[axis];
      near = std::max(near, std::min(t1, t2));
      far = std::min(far, std::max(t1, t2));
    }
    const float z = frame.depth.data[static_cast<std::size_t>(v) * WIDTH + u];
    cells[i] = near <= far && std::abs(z - near) < 0.01;
  }
  return cells;
}

/// Renders frames first..first+frames-1 of a scenario and runs flow + segmentation on all
/// but the first.
std::vector<FrameRecord>
runSequence(const std::string& scenario,
            int first,
            int frames,
            bool tracking,
            float separation_ratio =
                dynvo::RigidMotionSegmentationParameters().object_separation_ratio)
{
  dynvo::SynthOptions options;
  options.scenario = scenario;
  options.frames = first + frames;
  options.width = WIDTH;
  options.height = HEIGHT;
  options.noise = false; // see the file comment
  const dynvo::SceneSynthesizer synth(options);

  dynvo::GridSceneFlowEstimation<Point> flow_estimation;
  flow_estimation.setCameraIntrinsics(synth.intrinsics());
  flow_estimation.setCellSize(CELL);
  dynvo::RigidMotionSegmentation<Point> segmentation;
  segmentation.setCameraIntrinsics(synth.intrinsics());
  segmentation.setTracking(tracking);
  segmentation.setObjectSeparationRatio(separation_ratio);

  std::vector<FrameRecord> records;
  dynvo::SynthFrame previous;
  pcl::PointCloud<dynvo::PointFlow>::Ptr flow(new pcl::PointCloud<dynvo::PointFlow>);
  std::vector<pcl::PointIndices> segments;
  for (int k = first; k < first + frames; ++k) {
    dynvo::SynthFrame frame = synth.render(k);
    const auto cloud =
        dynvo::makeOrganizedCloud(frame.color, frame.depth, synth.intrinsics());
    flow_estimation.shiftCurrentToPrevious();
    flow_estimation.setInputCloud(cloud);
    if (k > first) {
      flow_estimation.compute(*flow);
      segmentation.setInputCloud(cloud);
      segmentation.setInputFlow(flow);
      segmentation.segment(segments);
      // The pipeline's constant-velocity prediction: last frame's background motion.
      segmentation.setPredictedMotion(segmentation.getMotions().front());

      FrameRecord record;
      record.truth.assign(COLS * ROWS, 0);
      record.valid.assign(COLS * ROWS, 0);
      for (int i = 0; i < COLS * ROWS; ++i) {
        std::array<int, 256> votes{};
        const int col = i % COLS, row = i / COLS;
        for (int v = row * CELL; v < (row + 1) * CELL; ++v)
          for (int u = col * CELL; u < (col + 1) * CELL; ++u)
            ++votes[frame.labels[static_cast<std::size_t>(v) * WIDTH + u]];
        record.truth[i] = static_cast<std::uint8_t>(
            std::max_element(votes.begin(), votes.end()) - votes.begin());
        record.valid[i] = (*flow)[i].valid_3d;
      }
      record.labels = segmentation.getCellLabels();
      for (std::size_t o = 0; o < frame.objects.size(); ++o) {
        const int id = frame.objects[o].id;
        record.speed[id] = (frame.objects[o].T_world_object.translation() -
                            previous.objects[o].T_world_object.translation())
                               .norm();
        record.moving[id] = frame.objects[o].moving;
        record.visible[id] = visibleCells(frame, frame.objects[o], synth.intrinsics());
      }
      records.push_back(std::move(record));
    }
    previous = std::move(frame);
  }
  return records;
}

/// Cell IoU of truth == object and labels == label, over cells with valid flow.
double
validCellIoU(const FrameRecord& record, int object, int label)
{
  int both = 0, either = 0;
  for (std::size_t i = 0; i < record.truth.size(); ++i) {
    if (!record.valid[i])
      continue;
    const bool in_truth = record.truth[i] == object,
               in_label = record.labels[i] == label;
    both += in_truth && in_label;
    either += in_truth || in_label;
  }
  return either == 0 ? 0.0 : static_cast<double>(both) / either;
}

TEST(SegmentationSequences, TwoFrameSegmentationFindsMovingObjects)
{
  // static_two: static camera, two boxes moving independently.
  const std::vector<FrameRecord> records = runSequence("static_two", 0, 40, false);
  double iou_sum = 0.0;
  int scored = 0;
  for (const FrameRecord& record : records)
    for (const auto& [object, speed] : record.speed) {
      if (speed <= MIN_OBJECT_SPEED)
        continue;
      double best = 0.0;
      for (int label = 2; label < 256; ++label)
        best = std::max(best, validCellIoU(record, object, label));
      iou_sum += best;
      ++scored;
    }
  ASSERT_GT(scored, 20);
  const double mean_iou = iou_sum / scored;
  RecordProperty("mean_cell_iou", std::to_string(mean_iou));
  EXPECT_GE(mean_iou, 0.8);
}

/// Output label held by most valid cells of `cells` (0 when none is valid).
int
majorityLabel(const FrameRecord& record,
              const std::vector<char>& cells,
              int* count = nullptr)
{
  std::array<int, 256> votes{};
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (cells[i] && record.valid[i])
      ++votes[record.labels[i]];
  const auto best = std::max_element(votes.begin(), votes.end());
  if (count)
    *count = *best;
  return *best == 0 ? 0 : static_cast<int>(best - votes.begin());
}

std::vector<char>
truthCells(const FrameRecord& record, int object)
{
  std::vector<char> cells(record.truth.size());
  for (std::size_t i = 0; i < cells.size(); ++i)
    cells[i] = record.truth[i] == object;
  return cells;
}

TEST(SegmentationSequences, CrossingObjectsKeepTheirIds)
{
  // static_two: static camera, two boxes moving independently (paths cross in the image).
  const std::vector<FrameRecord> records = runSequence("static_two", 0, 90, true);
  for (const int object : {1, 2}) {
    int scored = 0, switches = 0, previous = -1;
    for (const FrameRecord& record : records) {
      if (record.speed.at(object) <= MIN_OBJECT_SPEED)
        continue;
      const int id = majorityLabel(record, truthCells(record, object));
      if (previous >= 0 && id != previous)
        ++switches;
      previous = id;
      ++scored;
    }
    SCOPED_TRACE("object " + std::to_string(object));
    RecordProperty("object_" + std::to_string(object) + "_switches",
                   std::to_string(switches) + "/" + std::to_string(scored));
    ASSERT_GT(scored, 40);
    EXPECT_LE(switches, 0.05 * scored);
    EXPECT_GE(previous, 2); // a moving id, not the background
  }
}

TEST(SegmentationSequences, StopAndGo)
{
  // stop_and_go, object 1: moving camera; the object rests, moves from about 2 s to about
  // 4 s (frames 60 to 120), then rests.
  dynvo::RigidMotionSegmentationParameters params;
  const int max_age = static_cast<int>(params.max_age);
  const std::vector<FrameRecord> records = runSequence("stop_and_go", 50, 85, true);
  // The restart is counted from the first frame where the object moves by the inlier radius
  // sqrt(th_inlier) = 5.5 mm: slower motion cannot be told from the background (docs/algorithm.md
  // §12), and the 0.25 s speed ramp takes 4 frames to get there (0.1, 1, 2.5, 4.5 mm).
  const double detectable = std::sqrt(params.inlier_threshold);
  int restart = -1, stop = -1;
  for (std::size_t k = 1; k < records.size(); ++k) {
    if (records[k].speed.at(1) >= detectable && restart < 0)
      restart = static_cast<int>(k);
    if (!records[k].moving.at(1) && records[k - 1].moving.at(1) && restart >= 0 &&
        stop < 0)
      stop = static_cast<int>(k);
  }
  ASSERT_FALSE(records.front().moving.at(1)); // the window starts at rest
  ASSERT_GE(restart, 0);
  ASSERT_GE(stop, 0);
  ASSERT_LT(stop + max_age + 2, static_cast<int>(records.size()));
  // Restart: a moving id on most of its cells within 3 frames.
  int moving_at = -1;
  for (int k = restart; k <= restart + 3 && moving_at < 0; ++k)
    if (majorityLabel(records[k], records[k].visible.at(1)) >= 2)
      moving_at = k;
  EXPECT_GE(moving_at, 0) << "no moving id within 3 frames of the restart at "
                          << restart;
  RecordProperty("frames_to_moving_id", std::to_string(moving_at - restart));
  // Stop: static (label 1) within alpha_max + 2 frames, and it stays static.
  int static_at = -1;
  for (int k = stop; k <= stop + max_age + 2 && static_at < 0; ++k)
    if (majorityLabel(records[k], records[k].visible.at(1)) == 1)
      static_at = k;
  EXPECT_GE(static_at, 0) << "not static within alpha_max + 2 frames of the stop at "
                          << stop;
  RecordProperty("frames_to_static", std::to_string(static_at - stop));
}

TEST(SegmentationSequences, LargeOccluderDoesNotTakeTheBackgroundLabel)
{
  // moving_occluder: moving camera; the box approaches, covers more valid cells than the
  // background from about frame 80 on (89 % at its nearest, frame 157), slows to a halt
  // there and recedes. While slow it moves less than the 5.5 mm inlier radius relative to
  // the background, so the segmentation merges the two (docs/algorithm.md §12); without
  // object_separation_ratio the box became background after alpha_max frames and kept
  // label 1 once it sped up again (held on 48 of 125 frames, the background lost label 1
  // entirely from frame 193).
  const std::vector<FrameRecord> records =
      runSequence("moving_occluder", 55, 150, true);
  int large = 0, held = 0;
  for (const FrameRecord& record : records) {
    int box = 0, background = 0, background_1 = 0, labelled_1 = 0;
    for (std::size_t i = 0; i < record.truth.size(); ++i) {
      if (!record.valid[i])
        continue;
      box += record.truth[i] == 1;
      background += record.truth[i] == 0;
      background_1 += record.truth[i] == 0 && record.labels[i] == 1;
      labelled_1 += record.labels[i] == 1;
    }
    if (box <= background)
      continue; // score only the frames where the box covers most of the measured image
    ++large;
    // Label 1 is on the background: it covers most of the measured background (the rest is
    // held by the model's inertia), and at most 5 % of the box's cells carry it (cells on
    // the box's silhouette mix both motions).
    held += background_1 >= 0.5 * background && labelled_1 - background_1 <= 0.05 * box;
  }
  RecordProperty("background_held", std::to_string(held) + "/" + std::to_string(large));
  ASSERT_GT(large, 100);
  EXPECT_GE(held, 0.95 * large);
}

} // namespace
