// SPDX-License-Identifier: BSD-3-Clause
// The whole odometry on synthetic sequences with known camera motion.
#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/app/synthesize.h>
#include <dynvo/common/conventions.h>
#include <dynvo/common/trajectory.h>
#include <dynvo/eval/trajectory_metrics.h>
#include <dynvo/io/frame.h>
#include <dynvo/io/trajectory_io.h>
#include <dynvo/io/tum_folder_source.h>
#include <dynvo/synth/scene_synthesizer.h>

#include "support/pose_compare.h"
#include "support/shared_data.h"
#include "support/temp_dir.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGB>;

/// The synthesizer of the first `frames` frames of a scenario (default options otherwise).
dynvo::SceneSynthesizer
synthesizer(const std::string& scenario, int frames)
{
  dynvo::SynthOptions synth_options;
  synth_options.scenario = scenario;
  synth_options.frames = frames;
  return dynvo::SceneSynthesizer(synth_options);
}

/// Default pipeline options with the synthesizer's camera.
dynvo::app::PipelineOptions
optionsFor(const dynvo::SceneSynthesizer& synth)
{
  dynvo::app::PipelineOptions options;
  options.intrinsics = synth.intrinsics();
  return options;
}

struct SequenceRun {
  dynvo::Trajectory estimate;
  dynvo::Trajectory groundtruth;
  std::vector<bool> lost;
  std::vector<bool> recovered;          ///< FrameResult::recovered
  std::vector<double> inlier_threshold; ///< segmentation threshold per frame (m^2)
  std::vector<bool> keyframe;           ///< the frame became the keyframe
  std::vector<double> keyframe_overlap; ///< FrameResult::keyframe_overlap
};

using Configure = std::function<void(dynvo::app::PipelineOptions&)>;

/// Renders the frames of a synthetic sequence and runs the pipeline on them (options as
/// `configure` leaves them); `edit` may change a frame's images before the cloud is made
/// (frame index, colour, depth).
template <typename Edit>
SequenceRun
runSequence(const dynvo::SynthOptions& synth_options,
            unsigned threads,
            Edit edit,
            const Configure& configure = {})
{
  const dynvo::SceneSynthesizer synth(synth_options);
  dynvo::app::PipelineOptions options = optionsFor(synth);
  options.threads = threads;
  if (configure)
    configure(options);
  dynvo::app::OdometryPipeline pipeline(options);
  SequenceRun run;
  Eigen::Isometry3d T_camera0_world = Eigen::Isometry3d::Identity();
  for (int k = 0; k < synth_options.frames; ++k) {
    dynvo::SynthFrame frame = synth.render(k);
    if (k == 0)
      T_camera0_world = frame.T_world_camera.inverse();
    edit(k, frame.color, frame.depth);
    const auto cloud =
        dynvo::makeOrganizedCloud(frame.color, frame.depth, synth.intrinsics());
    const auto& result = pipeline.process(cloud, frame.timestamp);
    run.estimate.push_back({frame.timestamp, Eigen::Isometry3d(result.T_world_curr)});
    // The pipeline's world frame is camera 0: express the ground truth there too.
    run.groundtruth.push_back(
        {frame.timestamp, T_camera0_world * frame.T_world_camera});
    run.lost.push_back(result.lost);
    run.recovered.push_back(result.recovered);
    run.inlier_threshold.push_back(result.inlier_threshold);
    run.keyframe.push_back(result.keyframe);
    run.keyframe_overlap.push_back(result.keyframe_overlap);
  }
  return run;
}

template <typename Edit>
SequenceRun
runScenario(const std::string& scenario,
            int frames,
            unsigned threads,
            Edit edit,
            const Configure& configure = {})
{
  dynvo::SynthOptions synth_options;
  synth_options.scenario = scenario;
  synth_options.frames = frames;
  return runSequence(synth_options, threads, edit, configure);
}

SequenceRun
runScenario(const std::string& scenario, int frames, unsigned threads = 1)
{
  return runScenario(scenario, frames, threads,
                     [](int, dynvo::ColorImage&, dynvo::DepthImage&) {});
}

TEST(OdometryPipeline, FollowsAMovingCameraPastAMovingObject)
{
  // The default step is the direct one (docs/algorithm.md §7.7): photometric on the static
  // cells of both frames only, so the box entering the view must not push it, and the
  // keyframe fit stays in the loop with the direct refit of the chain. The rendered colour
  // carries no noise, so the step is far more precise than the flow fit (0.0002 m/s
  // measured): 1 mm/s still fails a box that pulls the step by a few hundredths of a
  // millimetre per frame.
  const SequenceRun run = runScenario("moving_crossing", 45);
  for (std::size_t k = 0; k < run.lost.size(); ++k)
    EXPECT_FALSE(run.lost[k]) << "frame " << k;
  EXPECT_GT(std::count(run.keyframe.begin(), run.keyframe.end(), true), 0);
  const auto rpe = dynvo::computeRpe(run.groundtruth, run.estimate);
  RecordProperty("rpe", std::to_string(rpe.trans_rmse));
  EXPECT_LT(rpe.trans_rmse, 0.001);
  EXPECT_LT(rpe.rot_rmse, 0.2);
}

TEST(OdometryPipeline, FlowStepFollowsAMovingCameraPastAMovingObject)
{
  // The same scene with the flow fit as the step (the paper's method, `-backend flow`).
  // 1.5 s of Kinect v1 depth in a room 1.5-4.3 m deep (sigma_z 3-27 mm per pixel, about a
  // tenth of that after the depth window, plus shadows and dropouts): the bound on
  // the synthetic scenes is 0.02 m/s, and the box entering the view must not push the
  // estimate beyond a third of it (measured values: src/app/NOTES.md).
  const SequenceRun run = runScenario(
      "moving_crossing", 45, 1, [](int, dynvo::ColorImage&, dynvo::DepthImage&) {},
      [](dynvo::app::PipelineOptions& o) {
        o.backend.backend = dynvo::RegistrationBackend::flow;
      });
  for (std::size_t k = 0; k < run.lost.size(); ++k)
    EXPECT_FALSE(run.lost[k]) << "frame " << k;
  const auto rpe = dynvo::computeRpe(run.groundtruth, run.estimate);
  EXPECT_LT(rpe.trans_rmse, 0.007);
  EXPECT_LT(rpe.rot_rmse, 0.2);
}

TEST(OdometryPipeline, StaticCameraIsNotFooledByMovingBoxes)
{
  const auto no_edit = [](int, dynvo::ColorImage&, dynvo::DepthImage&) {};
  const SequenceRun run = runScenario("static_two", 60, 1, no_edit);
  // Frame to frame, the segmentation alone keeps the boxes out: the paper's setting.
  const auto frame_to_frame = [](bool use_segmentation) {
    return [=](dynvo::app::PipelineOptions& o) {
      o.keyframes = false;
      o.use_segmentation = use_segmentation;
    };
  };
  const SequenceRun segmented =
      runScenario("static_two", 60, 1, no_edit, frame_to_frame(true));
  const SequenceRun ablation =
      runScenario("static_two", 60, 1, no_edit, frame_to_frame(false));
  const auto rpe = dynvo::computeRpe(run.groundtruth, run.estimate);
  const auto segmented_rpe =
      dynvo::computeRpe(segmented.groundtruth, segmented.estimate);
  const auto ablation_rpe = dynvo::computeRpe(ablation.groundtruth, ablation.estimate);
  // The camera stands still while two boxes (about 15 % of the cells) move 1-3 cm per
  // frame. With the boxes kept out, only depth noise remains (the 0.02 m/s bound);
  // counting every cell as static drags the estimate along with the boxes, many times
  // further (measured values: src/app/NOTES.md).
  EXPECT_LT(rpe.trans_rmse, 0.02);
  EXPECT_LT(segmented_rpe.trans_rmse, 0.02);
  EXPECT_GT(ablation_rpe.trans_rmse, 3.0 * segmented_rpe.trans_rmse);
}

TEST(OdometryPipeline, FrameWithoutDepthOrTextureIsLostWithoutDerailing)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const SequenceRun run =
      runScenario("moving_static", 30, 1,
                  [&](int k, dynvo::ColorImage& color, dynvo::DepthImage& depth) {
                    if (k == 10)
                      std::fill(depth.data.begin(), depth.data.end(), nan);
                    if (k == 20)
                      std::fill(color.data.begin(), color.data.end(), 0);
                  });
  // No valid depth: no 3D flow into frame 10 or out of it. A black image: nothing to track.
  EXPECT_TRUE(run.lost[10]);
  EXPECT_TRUE(run.lost[20]);
  for (int k : {5, 15, 25, 29})
    EXPECT_FALSE(run.lost[k]) << "frame " << k;
  // The lost frames take the constant-velocity prediction; the camera moves smoothly, so the
  // trajectory stays within a few centimetres of the truth after 1 s.
  const Eigen::Vector3d error = run.estimate.back().T_world_camera.translation() -
                                run.groundtruth.back().T_world_camera.translation();
  EXPECT_LT(error.norm(), 0.05);
}

/// Distance of camera k from camera j (metres) in a trajectory.
double
distanceBetween(const dynvo::Trajectory& trajectory, std::size_t j, std::size_t k)
{
  return (trajectory[k].T_world_camera.translation() -
          trajectory[j].T_world_camera.translation())
      .norm();
}

TEST(OdometryPipeline, AVelocityNoFrameMeasuresComesToRest)
{
  // Frames 10-39 (1 s) measure nothing: in one run they are black and without depth, so the
  // fits fail; in the other they are bad (a cloud of another size), so they are skipped.
  // Either way they are lost, and the last measured velocity carries the camera on: it holds
  // for one frame's interval, then fades with tau (docs/algorithm.md §7.5). Over the
  // stretch's n frames that is 1 + tau / dt * (1 - exp(-(n - 1) dt / tau)) last steps: 9.6
  // at 30 Hz and tau = 0.3 s, not the 30 of a constant velocity. 2 % for the steps' blend
  // from the identity (a screw motion's translation does not scale exactly linearly).
  constexpr int first = 10;
  constexpr int last = 39;
  const auto blind = [](int k, dynvo::ColorImage& color, dynvo::DepthImage& depth) {
    if (k < first || k > last)
      return;
    std::fill(color.data.begin(), color.data.end(), 0);
    std::fill(depth.data.begin(), depth.data.end(),
              std::numeric_limits<float>::quiet_NaN());
  };
  const auto bad = [](int k, dynvo::ColorImage& color, dynvo::DepthImage& depth) {
    if (k < first || k > last)
      return;
    color.height /= 2;
    color.data.resize(color.data.size() / 2);
    depth.height /= 2;
    depth.data.resize(depth.data.size() / 2);
  };
  const dynvo::app::PipelineOptions defaults;
  const SequenceRun run = runScenario("moving_static", 45, 1, blind);
  const SequenceRun skipped = runScenario("moving_static", 45, 1, bad);
  const SequenceRun constant =
      runScenario("moving_static", 45, 1, blind, [](dynvo::app::PipelineOptions& o) {
        o.velocity_memory = 1e9;
      });
  const double dt = run.estimate[first].timestamp - run.estimate[first - 1].timestamp;
  const double step = distanceBetween(run.estimate, first - 2, first - 1);
  const double tau = defaults.velocity_memory;
  const double reach =
      step * (1.0 + tau / dt * (1.0 - std::exp(-(last - first) * dt / tau)));
  for (const SequenceRun* r : {&run, &skipped}) {
    for (int k = first; k <= last; ++k)
      EXPECT_TRUE(r->lost[k]) << "frame " << k;
    const double blind_path = distanceBetween(r->estimate, first - 1, last);
    EXPECT_LT(blind_path, 1.02 * reach);
    // The velocity fades, it is not dropped: the predicted steps repeat the last one's
    // nearly straight screw, so the stretch's chord reaches 98 % of the faded steps' sum
    // (100 % measured).
    EXPECT_GT(blind_path, 0.98 * reach);
  }
  RecordProperty("blind_path_in_steps",
                 std::to_string(distanceBetween(run.estimate, first - 1, last) / step));
  // Without fading the last step goes on for all 30 frames.
  EXPECT_GT(distanceBetween(constant.estimate, first - 1, last), 25.0 * step);
  // Measuring resumes once the images come back: after the skipped frames at once, against
  // the last good frame; after the black ones from the second frame, the first having no
  // flow into a black frame.
  for (int k = last + 1; k < 45; ++k) {
    EXPECT_FALSE(skipped.lost[k]) << "frame " << k;
    EXPECT_TRUE(k == last + 1 || !run.lost[k]) << "frame " << k;
  }
}

TEST(OdometryPipeline, FrameAfterALostOneIsRecoveredAgainstTheKeyframe)
{
  // Frame 10 is black: nothing to track, so it is lost and takes the constant-velocity
  // prediction. Frame 11 has no flow into the black frame either: frame to frame it is lost
  // too, while with keyframes it is registered against the keyframe taken before the black
  // frame, searched from the prediction over the whole pyramid.
  const auto black_frame = [](int k, dynvo::ColorImage& color, dynvo::DepthImage&) {
    if (k == 10)
      std::fill(color.data.begin(), color.data.end(), 0);
  };
  const SequenceRun run = runScenario("moving_static", 20, 1, black_frame);
  const SequenceRun frame_to_frame = runScenario("moving_static", 20, 1, black_frame,
                                                 [](dynvo::app::PipelineOptions& o) {
                                                   o.keyframes = false;
                                                 });
  EXPECT_TRUE(run.lost[10]);
  EXPECT_FALSE(run.keyframe[10]) << "a lost frame must not become the keyframe";
  EXPECT_TRUE(frame_to_frame.lost[11]);
  for (std::size_t k = 11; k < run.lost.size(); ++k)
    EXPECT_FALSE(run.lost[k]) << "frame " << k;
  // Registered frames of this noisy room are within a millisecond-scale error of the truth
  // (ATE about 0.3 mm over 4 s, measured): 2 mm at frame 11 means it was registered, not
  // predicted. The frame-to-frame run carries the two predicted steps of a camera that
  // accelerates at up to about 0.5 m/s^2 into every later pose.
  const auto error = [](const SequenceRun& r, std::size_t k) {
    return (r.estimate[k].T_world_camera.translation() -
            r.groundtruth[k].T_world_camera.translation())
        .norm();
  };
  EXPECT_LT(error(run, 11), 0.002);
  EXPECT_LT(error(run, 19), 0.002);
  EXPECT_LT(error(run, 19), error(frame_to_frame, 19));
}

/// Expects the camera step between two poses (camera-to-world) taken dt seconds apart to lie
/// within the pipeline's motion bound, with 1 % for the pose's rounding to the colour stamp,
/// which blends two bounded steps.
void
expectStepWithinBound(const Eigen::Isometry3d& previous,
                      const Eigen::Isometry3d& current,
                      double dt,
                      int frame)
{
  const dynvo::app::PipelineOptions defaults;
  const Eigen::Isometry3d step = previous.inverse() * current;
  EXPECT_LE(step.translation().norm(), 1.01 * defaults.max_speed * dt)
      << "frame " << frame;
  EXPECT_LE(Eigen::AngleAxisd(step.linear()).angle(),
            1.01 * defaults.max_rotation_rate * dt)
      << "frame " << frame;
}

TEST(OdometryPipeline, OccluderOverNearlyTheWholeImageNeverDerailsThePose)
{
  // Frames 20-49 (1 s): a textured board 0.8 m from the camera covers all but the right
  // 5 % of the image and slides 6 px per frame, so the flow is dominated by a coherent
  // motion that is not the camera's (a person passing close to a hand-held camera).
  constexpr int first = 20;
  constexpr int last = 49;
  constexpr int frames = 80;
  const auto occluder = [&](int k, dynvo::ColorImage& color, dynvo::DepthImage& depth) {
    if (k < first || k > last)
      return;
    const std::uint32_t covered = depth.width - depth.width / 20;
    for (std::uint32_t v = 0; v < depth.height; ++v)
      for (std::uint32_t u = 0; u < covered; ++u) {
        const std::uint32_t block =
            ((u + 6u * static_cast<std::uint32_t>(k)) / 8u) * 7919u +
            (v / 8u) * 104729u;
        const auto grey =
            static_cast<std::uint8_t>(40u + (block * 2654435761u >> 24) % 180u);
        const std::size_t i = static_cast<std::size_t>(v) * depth.width + u;
        std::fill_n(color.data.begin() + 3 * i, 3, grey);
        depth.data[i] = 0.8f;
      }
  };
  const SequenceRun run = runScenario("moving_static", frames, 1, occluder);
  for (std::size_t k = 1; k < run.estimate.size(); ++k) {
    ASSERT_TRUE(run.estimate[k].T_world_camera.matrix().allFinite()) << "frame " << k;
    expectStepWithinBound(
        run.estimate[k - 1].T_world_camera, run.estimate[k].T_world_camera,
        run.estimate[k].timestamp - run.estimate[k - 1].timestamp, static_cast<int>(k));
  }
  // Over the occluded second the camera follows the board (18 cm at the end, measured
  // 2026-12-04: 95 % of the cells move coherently and within the motion guard of the
  // prediction), but tracking resumes once the board has gone: the frames after it are registered, and each step matches the true one within
  // 3 mm (registered steps of this room are within about 1 mm; src/app/NOTES.md).
  for (int k = last + 3; k < frames; ++k) {
    EXPECT_FALSE(run.lost[k]) << "frame " << k;
    const Eigen::Isometry3d estimated =
        run.estimate[k - 1].T_world_camera.inverse() * run.estimate[k].T_world_camera;
    const Eigen::Isometry3d truth = run.groundtruth[k - 1].T_world_camera.inverse() *
                                    run.groundtruth[k].T_world_camera;
    EXPECT_LT((estimated.translation() - truth.translation()).norm(), 0.003)
        << "frame " << k;
  }
}

TEST(OdometryPipeline, DroppedFramesInAFastSweepKeepEveryPoseRigidAndBounded)
{
  // The fast sweep (up to 1 m/s and 90 deg/s) with every third frame dropped, as a
  // hand-held Kinect drops frames on TUM fr1/desk: the steps alternate between one and two
  // frame intervals, and the sweep's start is missed, so frames are lost and take the
  // prediction. Whatever the estimate, each pose must stay a rigid motion and each step
  // within the physical bound: before every pose was orthonormalised, the last step, taken
  // from two slightly non-rigid poses, fed its error back through the prediction on lost
  // frames (2.6e-3 off SO(3) after 18 frames, tripling every two frames, steps of 3.2 m in
  // 66 ms, RPE 358 m/s; a held-out run reached 1e43 m).
  const dynvo::SceneSynthesizer synth = synthesizer("fast_sweep", 90);
  const dynvo::app::PipelineOptions options = optionsFor(synth);
  dynvo::app::OdometryPipeline pipeline(options);
  Eigen::Matrix4d previous = Eigen::Matrix4d::Identity();
  double previous_stamp = 0.0;
  for (int k = 0; k < 90; ++k) {
    if (k % 3 == 2)
      continue;
    const dynvo::SynthFrame frame = synth.render(k);
    const auto& result = pipeline.process(
        dynvo::makeOrganizedCloud(frame.color, frame.depth, synth.intrinsics()),
        frame.timestamp);
    const Eigen::Matrix4d& pose = result.T_world_curr;
    ASSERT_TRUE(pose.allFinite()) << "frame " << k;
    const Eigen::Matrix3d R = pose.topLeftCorner<3, 3>();
    EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-9)
        << "frame " << k;
    if (k > 0)
      expectStepWithinBound(Eigen::Isometry3d(previous), Eigen::Isometry3d(pose),
                            frame.timestamp - previous_stamp, k);
    previous = pose;
    previous_stamp = frame.timestamp;
  }
}

TEST(OdometryPipeline, PoseIsReportedAtTheColourStamp)
{
  // A sensor whose colour image is taken 15 ms after its depth image (TUM fr1's offsets reach
  // 17 ms): the scenario is rendered at 600 Hz, frame k takes its depth from t_k and its
  // colour from t_k + 15 ms, 33.3 ms apart. The flow ends are read at the depth instants
  // (docs/algorithm.md §1.2), the chain of poses stays there, and the pose is reported at the
  // colour stamp, carried 1.45 steps along the step from frame k-1 (§7.4). The camera moves
  // 4-7 mm per frame, so a pose left at the depth instant misses the colour stamp's truth by
  // 2-3 mm; the carried one misses it by the registration error of this noisy room (up to
  // 0.6 mm at a depth instant, carried 1.45 and 0.45 times) plus what a straight step misses
  // of a camera accelerating at up to 0.5 m/s^2 (0.2 mm): 1.2 mm.
  constexpr int frames = 20;
  constexpr int step = 20; // renders per frame interval: 33.3 ms at 600 Hz
  constexpr int delay = 9; // renders from depth to colour: 15 ms
  dynvo::SynthOptions synth_options;
  synth_options.scenario = "moving_static";
  synth_options.fps = 600.0;
  synth_options.frames = frames * step;
  const dynvo::SceneSynthesizer synth(synth_options);
  dynvo::app::OdometryPipeline pipeline(optionsFor(synth));
  Eigen::Isometry3d T_camera0_world = Eigen::Isometry3d::Identity();
  for (int k = 0; k < frames; ++k) {
    const dynvo::SynthFrame depth = synth.render(k * step);
    const dynvo::SynthFrame colour = synth.render(k * step + delay);
    if (k == 0)
      T_camera0_world = depth.T_world_camera.inverse();
    const auto cloud =
        dynvo::makeOrganizedCloud(colour.color, depth.depth, synth.intrinsics());
    const auto& result = pipeline.process(cloud, colour.timestamp, depth.timestamp);
    ASSERT_FALSE(result.lost) << "frame " << k;
    if (k == 0)
      continue; // nothing to carry the first pose along
    const Eigen::Matrix4d truth_at_colour =
        (T_camera0_world * colour.T_world_camera).matrix();
    const Eigen::Matrix4d truth_at_depth =
        (T_camera0_world * depth.T_world_camera).matrix();
    EXPECT_GT(dynvo::test::translationError(truth_at_depth, truth_at_colour), 0.002)
        << "frame " << k;
    EXPECT_LT(dynvo::test::translationError(result.T_world_curr, truth_at_colour),
              0.0012)
        << "frame " << k;
  }
}

TEST(OdometryPipeline, StaticCameraDoesNotDriftAgainstItsKeyframe)
{
  // A fixed camera and a box crossing a third of the view, exact depth: every frame is
  // registered against the same keyframe, so nothing accumulates over 10 s. Frame-to-frame
  // registration adds each frame's error to the next (sub-millimetre per frame here).
  dynvo::SynthOptions synth_options;
  synth_options.scenario = "static_one";
  synth_options.frames = 300;
  synth_options.noise = false;
  synth_options.width = 320;
  synth_options.height = 240;
  const SequenceRun run =
      runSequence(synth_options, 1, [](int, dynvo::ColorImage&, dynvo::DepthImage&) {});
  for (std::size_t k = 1; k < run.lost.size(); ++k)
    ASSERT_FALSE(run.lost[k]) << "frame " << k;
  const auto ate = dynvo::computeAte(run.groundtruth, run.estimate);
  // The bound: sub-millimetre ATE over 300 frames without depth noise.
  EXPECT_LT(ate.rmse, 0.001);
  // No drift after the first keyframe (frame 1): the estimates of frames 1 and 299 agree
  // within the error of a single registration of exact depth (a tenth of a millimetre).
  EXPECT_TRUE(run.keyframe[1]);
  EXPECT_EQ(std::count(run.keyframe.begin(), run.keyframe.end(), true), 1);
  EXPECT_LT(distanceBetween(run.estimate, 1, run.estimate.size() - 1), 0.0005);
}

TEST(OdometryPipeline, KeyframeIsRenewedAtTheConfiguredOverlapOrDistance)
{
  // Only the overlap rule active (distance and angle limits out of reach): a frame becomes
  // the keyframe exactly when its fit to the keyframe keeps fewer than min_overlap of the
  // inliers of the first fit to it. The moving camera sweeps the room, so a stricter
  // threshold renews the keyframe more often.
  std::vector<int> renewals;
  for (const double min_overlap : {0.5, 0.9}) {
    const SequenceRun run = runScenario(
        "moving_static", 60, 1, [](int, dynvo::ColorImage&, dynvo::DepthImage&) {},
        [&](dynvo::app::PipelineOptions& o) {
          o.keyframe_min_overlap = min_overlap;
          o.keyframe_max_distance = 10.0;
          o.keyframe_max_angle = 3.0;
        });
    EXPECT_TRUE(run.keyframe[1]) << "the first tracked frame is the first keyframe";
    int count = 0;
    for (std::size_t k = 2; k < run.keyframe.size(); ++k) {
      ASSERT_FALSE(run.lost[k]) << "frame " << k;
      if (run.keyframe[k - 1]) {
        EXPECT_DOUBLE_EQ(run.keyframe_overlap[k], 1.0) << "frame " << k;
      }
      EXPECT_EQ(run.keyframe[k], run.keyframe_overlap[k] < min_overlap)
          << "frame " << k << ", overlap " << run.keyframe_overlap[k];
      count += run.keyframe[k];
    }
    renewals.push_back(count);
  }
  EXPECT_GE(renewals[1], 2);
  EXPECT_GT(renewals[1], renewals[0]);

  // Only the distance rule: the keyframe is renewed once the camera is 5 cm from it.
  const double max_distance = 0.05;
  const SequenceRun run = runScenario(
      "moving_static", 60, 1, [](int, dynvo::ColorImage&, dynvo::DepthImage&) {},
      [&](dynvo::app::PipelineOptions& o) {
        o.keyframe_min_overlap = 1e-6;
        o.keyframe_max_distance = max_distance;
        o.keyframe_max_angle = 3.0;
      });
  std::size_t keyframe = 1;
  int count = 0;
  for (std::size_t k = 2; k < run.keyframe.size(); ++k) {
    EXPECT_EQ(run.keyframe[k],
              distanceBetween(run.estimate, keyframe, k) > max_distance)
        << "frame " << k;
    if (run.keyframe[k]) {
      keyframe = k;
      ++count;
    }
  }
  // The camera travels about 0.3 m in these 2 s.
  EXPECT_GE(count, 2);
}

TEST(OdometryPipeline, ThreadCountDoesNotChangeTheResult)
{
  // A moving camera and a moving box; every frame tracked (a run that lost every frame
  // would give the same identity poses with any thread count).
  const SequenceRun one = runScenario("moving_crossing", 12, 1);
  const SequenceRun two = runScenario("moving_crossing", 12, 2);
  ASSERT_EQ(one.estimate.size(), 12u);
  ASSERT_EQ(two.estimate.size(), one.estimate.size());
  for (std::size_t k = 1; k < one.lost.size(); ++k) {
    EXPECT_FALSE(one.lost[k]) << "frame " << k;
    EXPECT_FALSE(two.lost[k]) << "frame " << k;
  }
  EXPECT_GT((one.groundtruth.back().T_world_camera.translation() -
             one.groundtruth.front().T_world_camera.translation())
                .norm(),
            0.005);
  EXPECT_GT(one.estimate.back().T_world_camera.translation().norm(), 0.005);
  for (std::size_t k = 0; k < one.estimate.size(); ++k)
    EXPECT_EQ(one.estimate[k].T_world_camera.matrix(),
              two.estimate[k].T_world_camera.matrix())
        << "frame " << k;
}

TEST(OdometryPipeline, EveryPixelWithDepthIsLabelledFromTheFirstFrame)
{
  // docs/algorithm.md §6.1: label 0 only where the depth is missing; frame 0, without flow,
  // is static background (the start-up assumption).
  constexpr int FRAMES = 3;
  const dynvo::SceneSynthesizer synth = synthesizer("static_two", FRAMES);
  dynvo::app::PipelineOptions options = optionsFor(synth);
  dynvo::app::OdometryPipeline pipeline(options);
  for (int k = 0; k < FRAMES; ++k) {
    const dynvo::SynthFrame frame = synth.render(k);
    const auto cloud =
        dynvo::makeOrganizedCloud(frame.color, frame.depth, synth.intrinsics());
    const dynvo::app::FrameResult& result = pipeline.process(cloud, frame.timestamp);
    ASSERT_EQ(result.labels.size(), cloud->size());
    std::size_t with_depth = 0, moving = 0;
    for (std::size_t p = 0; p < cloud->size(); ++p) {
      const bool has_depth = std::isfinite((*cloud)[p].z);
      with_depth += has_depth;
      moving += result.labels[p] >= 2;
      ASSERT_EQ(result.labels[p] == dynvo::LABEL_NONE, !has_depth) << "frame " << k;
    }
    ASSERT_GT(with_depth, cloud->size() / 2) << "frame " << k;
    if (k == 0)
      EXPECT_EQ(moving, 0u);
  }
}

TEST(OdometryPipeline, ReportsBadFramesAsLostWithoutThrowing)
{
  dynvo::app::PipelineOptions options;
  dynvo::app::OdometryPipeline pipeline(options);
  auto organized = pcl::make_shared<Cloud>(64, 48, pcl::PointXYZRGB(0.f, 0.f, 1.f));
  EXPECT_TRUE(pipeline.process(organized, 0.0).error.empty());
  auto flat = pcl::make_shared<Cloud>();
  flat->resize(100);
  const std::vector<std::pair<Cloud::ConstPtr, std::string>> bad = {
      {pcl::make_shared<Cloud>(32, 48), "frame size changed from 64x48 to 32x48"},
      {flat, "organized"},
      {nullptr, "got none"}};
  for (const auto& [cloud, reason] : bad) {
    const dynvo::app::FrameResult* result = nullptr;
    ASSERT_NO_THROW(result = &pipeline.process(cloud, 0.1));
    EXPECT_TRUE(result->lost) << reason;
    EXPECT_NE(result->error.find(reason), std::string::npos) << result->error;
    EXPECT_TRUE(result->T_world_curr.allFinite());
    EXPECT_EQ(result->labels.size(),
              static_cast<std::size_t>(result->width) * result->height);
  }
  EXPECT_EQ(pipeline.frameCount(), 1u);
  EXPECT_TRUE(pipeline.process(organized, 0.2).error.empty());
  EXPECT_EQ(pipeline.frameCount(), 2u);

  options.threads = 0;
  EXPECT_THROW(dynvo::app::OdometryPipeline{options}, std::invalid_argument);
}

TEST(OdometryPipeline, ABadFrameLeavesTheRestOfTheRunUntouched)
{
  // The bad frame keeps the sequence state, so every good frame is registered against the
  // same previous frame as in the run without it: the poses are the same bits.
  constexpr int FRAMES = 8;
  const dynvo::SceneSynthesizer synth = synthesizer("moving_crossing", FRAMES);
  dynvo::app::PipelineOptions options = optionsFor(synth);
  dynvo::app::OdometryPipeline clean(options);
  dynvo::app::OdometryPipeline interrupted(options);
  Eigen::Matrix4d last = Eigen::Matrix4d::Identity();
  for (int k = 0; k < FRAMES; ++k) {
    const dynvo::SynthFrame frame = synth.render(k);
    const auto cloud =
        dynvo::makeOrganizedCloud(frame.color, frame.depth, synth.intrinsics());
    if (k == 3) {
      const auto& skipped = interrupted.process(
          pcl::make_shared<Cloud>(cloud->width / 2, cloud->height), frame.timestamp);
      ASSERT_TRUE(skipped.lost);
      ASSERT_FALSE(skipped.error.empty());
    }
    const Eigen::Matrix4d expected = clean.process(cloud, frame.timestamp).T_world_curr;
    const auto& result = interrupted.process(cloud, frame.timestamp);
    EXPECT_TRUE(result.error.empty()) << k;
    EXPECT_FALSE(result.lost) << k;
    EXPECT_EQ(result.T_world_curr, expected) << k;
    last = expected;
  }
  // Not vacuous: the camera moved.
  EXPECT_GT((last.topRightCorner<3, 1>().norm()), 1e-3);
}

TEST(OdometryPipeline, InlierThresholdFollowsTheMeasuredNoise)
{
  // The threshold starts at the upper bound (no residual measured yet), then follows 3 x the
  // running mean of the static fit's residual. Synthetic Kinect noise after the depth window,
  // with the far background in the static set (the sensor model keeps it), leaves a residual
  // of about 1.2e-5 m^2: the threshold settles near 3.6e-5, well below the 6e-5 upper bound
  // and above the 3e-5 lower one.
  const dynvo::app::PipelineOptions defaults;
  const SequenceRun run = runScenario("moving_static", 20);
  EXPECT_DOUBLE_EQ(run.inlier_threshold[1], defaults.segmentation.inlier_threshold);
  for (std::size_t k = 2; k < run.inlier_threshold.size(); ++k) {
    EXPECT_GE(run.inlier_threshold[k], defaults.inlier_noise.min_inlier_threshold) << k;
    EXPECT_LT(run.inlier_threshold[k], 0.75 * defaults.segmentation.inlier_threshold)
        << k;
  }
}

/// Reading options of a TUM fr1 recording: the fr1 camera.
dynvo::TumFolderSource::Options
fr1SourceOptions()
{
  dynvo::TumFolderSource::Options options;
  options.intrinsics = dynvo::CameraIntrinsics::fromPreset("fr1");
  return options;
}

TEST(OdometryPipeline, InlierThresholdStaysLooseOnRealKinectFrames)
{
  // TUM fr1/xyz: colour and depth are not taken at the same instant, and the hand-held camera
  // moves up to 0.5 m/s, so the static fit's residual is about 1.9e-5 m^2 and 3 x its mean
  // keeps the threshold well above the lower bound (measured values: src/app/NOTES.md).
  const std::string folder = dynvo::test::sharedDataPath("tum_fr1_xyz_200");
  DYNVO_REQUIRE_SHARED_DATA(folder + "/rgb.txt");
  dynvo::TumFolderSource source(folder, fr1SourceOptions());
  dynvo::app::PipelineOptions options;
  options.intrinsics = fr1SourceOptions().intrinsics;
  dynvo::app::OdometryPipeline pipeline(options);
  dynvo::Frame frame;
  double sum = 0.0;
  int frames = 0;
  for (int k = 0; k < 40 && source.next(frame); ++k) {
    const auto& result = pipeline.process(frame.cloud, frame.timestamp);
    EXPECT_FALSE(result.lost) << "frame " << k;
    if (k >= 10) { // after the running mean (weight 0.1) has forgotten its start
      sum += result.inlier_threshold;
      ++frames;
    }
  }
  ASSERT_EQ(frames, 30);
  RecordProperty("mean_inlier_threshold", std::to_string(sum / frames));
  EXPECT_GT(sum / frames, 1.5 * options.inlier_noise.min_inlier_threshold);
}

/// The pipeline's trajectory over a TUM fr1 recording (default options as `configure`
/// leaves them) and which frames were lost.
struct RecordingRun {
  dynvo::Trajectory estimate;
  std::vector<bool> lost;
};

RecordingRun
runFr1Recording(const std::string& folder, const Configure& configure = {})
{
  dynvo::TumFolderSource source(folder, fr1SourceOptions());
  dynvo::app::PipelineOptions options;
  options.intrinsics = fr1SourceOptions().intrinsics;
  if (configure)
    configure(options);
  dynvo::app::OdometryPipeline pipeline(options);
  RecordingRun run;
  dynvo::Frame frame;
  while (source.next(frame)) {
    const auto& result =
        pipeline.process(frame.cloud, frame.timestamp, frame.depth_timestamp);
    run.estimate.push_back({frame.timestamp, Eigen::Isometry3d(result.T_world_curr)});
    run.lost.push_back(result.lost);
  }
  return run;
}

TEST(OdometryPipeline, FramesNoFlowFitMeasuresAreRecoveredByTheDenseFit)
{
  // No flow fit can pass here (each needs more cells than the 1200 of the grid), as on a
  // blurred frame after a gap: every frame goes to OpenCV's dense RGB-D odometry, started
  // from the prediction, on every cell (no frame is measured by a flow fit, so none is called
  // moving; docs/algorithm.md §7.5).
  const auto starved = [](dynvo::app::PipelineOptions& o) {
    o.registration.min_correspondences = 2000;
  };
  const SequenceRun run = runScenario(
      "moving_static", 30, 1, [](int, dynvo::ColorImage&, dynvo::DepthImage&) {},
      starved);
  const auto travelled = [&](std::size_t k) {
    return (run.groundtruth[k].T_world_camera.translation() -
            run.groundtruth[0].T_world_camera.translation())
        .norm();
  };
  const auto error = [&](std::size_t k) {
    return (run.estimate[k].T_world_camera.translation() -
            run.groundtruth[k].T_world_camera.translation())
        .norm();
  };
  // Frame 1 starts from the identity and frame 0's mask is every cell (the start-up
  // assumption); from frame 2 on, every frame is measured by the dense fit.
  for (std::size_t k = 2; k < run.lost.size(); ++k) {
    EXPECT_FALSE(run.lost[k]) << "frame " << k;
    EXPECT_TRUE(run.recovered[k]) << "frame " << k;
  }
  RecordProperty("final_error_m", std::to_string(error(run.lost.size() - 1)));
  RecordProperty("travelled_m", std::to_string(travelled(run.lost.size() - 1)));
  // Predicted frames alone would stand still (no step is ever measured): an error of the
  // whole path, 16 cm. OpenCV's dense odometry drifts 3.7 cm per second on this noisy room
  // ("RPE cv_rgbd" of moving_static in the README's table); the 30 frames are 1 s: within
  // 1.5 times that (4.5 cm measured).
  EXPECT_LT(error(run.lost.size() - 1), 0.056);
  EXPECT_LT(error(run.lost.size() - 1), 0.5 * travelled(run.lost.size() - 1));
}

/// Mean translational RPE (m/s) over six seeds of the fast fr1/desk clip, and the lost frames
/// of the six runs; `configure` edits the options of every run.
struct SixSeeds {
  double rpe = 0.0;
  std::size_t lost = 0;
};

SixSeeds
sixSeedsOfTheFastClip(const std::string& folder,
                      const dynvo::Trajectory& truth,
                      const Configure& configure)
{
  constexpr std::uint32_t SEEDS = 6;
  SixSeeds result;
  for (std::uint32_t seed = 0; seed < SEEDS; ++seed) {
    const RecordingRun run =
        runFr1Recording(folder, [&](dynvo::app::PipelineOptions& o) {
          o.segmentation.seed = seed;
          configure(o);
        });
    result.lost +=
        static_cast<std::size_t>(std::count(run.lost.begin(), run.lost.end(), true));
    const auto rpe = dynvo::computeRpe(truth, run.estimate);
    EXPECT_GT(rpe.pairs, 50u);
    result.rpe += rpe.trans_rmse / SEEDS;
  }
  return result;
}

TEST(OdometryPipeline, FastRealMotionIsTrackedAndKeyframesHelp)
{
  // TUM fr1/desk, fast hand-held (0.5-0.9 m/s, 68 ms gaps, blur). Issue 29's bar: no frame
  // lost and RPE <= 0.04 m/s. The RPE of one seed (the segmentation's hypothesis sampling)
  // spreads by +-15 % on this clip, across the bar, so the bar is held by the mean of six
  // seeds (0.0328 measured with the default direct step), the expected error, not by one
  // draw. Keyframes must help and not hurt (issue 29): with the direct step they take the six
  // seeds from 0.0351 to 0.0328. With the flow step, whose chain carries each step's error,
  // the keyframe fit, whose errors are largely independent of the chain's
  // (docs/algorithm.md §7.3), helps more: 0.054 without keyframes, 0.037 with them (0.69 x).
  const std::string folder = dynvo::test::sharedDataPath("tum_fr1_desk_fast");
  DYNVO_REQUIRE_SHARED_DATA(folder + "/groundtruth.txt");
  const dynvo::Trajectory truth = dynvo::readTrajectory(folder + "/groundtruth.txt");
  // Six seeds with keyframes, then six without, for one step method.
  const auto withAndWithout = [&](dynvo::RegistrationBackend backend,
                                  const std::string& name) {
    std::array<SixSeeds, 2> runs;
    for (const bool on : {true, false}) {
      SixSeeds& run = runs[on ? 0 : 1];
      run = sixSeedsOfTheFastClip(folder, truth, [=](dynvo::app::PipelineOptions& o) {
        o.keyframes = on;
        o.backend.backend = backend;
      });
      RecordProperty(name + (on ? "_with_keyframes" : "_without_keyframes"),
                     std::to_string(run.rpe));
    }
    return runs;
  };
  const auto [with, without] =
      withAndWithout(dynvo::RegistrationBackend::direct, "rpe");
  EXPECT_EQ(with.lost, 0u);
  EXPECT_LE(with.rpe, 0.04);
  EXPECT_LT(with.rpe, without.rpe);
  const auto [flow_with, flow_without] =
      withAndWithout(dynvo::RegistrationBackend::flow, "flow_rpe");
  EXPECT_EQ(flow_with.lost, 0u);
  EXPECT_LT(flow_with.rpe, 0.85 * flow_without.rpe);
}

/// A composited sequence: its folder and its ground truth.
struct CompositeSequence {
  std::string folder;
  dynvo::Trajectory truth;
};

/// The synthetic `scenario`'s objects composited into the first 120 frames of the TUM fr1
/// recording `folder`, written under `dir`.
CompositeSequence
compositeIntoRecording(const std::string& scenario,
                       const std::string& folder,
                       const dynvo::test::TempDir& dir)
{
  dynvo::SynthOptions options;
  options.scenario = scenario;
  dynvo::app::CompositeOptions composite;
  composite.recording = folder;
  composite.intrinsics = fr1SourceOptions().intrinsics;
  composite.frames = 120;
  dynvo::app::writeCompositeSequence(options, composite, dir.file(scenario));
  return {dir.file(scenario),
          dynvo::readTrajectory(dir.file(scenario) + "/groundtruth.txt")};
}

TEST(OdometryPipeline, CompositedBoxesDoNotPullTheCameraOnARealRecording)
{
  // Two textured boxes (synthetic static_two) composited into TUM fr1/xyz, 120 frames. At
  // 1-1.5 m and 0.2-0.4 m/s they are only 2-4 sigma off the camera's motion in one frame
  // pair, so they fall into the background's segment whenever they are not already apart,
  // and, nearer than the desk, outweigh it in the fit: the camera follows them. Their
  // evidence over frames leaves them out of the fits (docs/algorithm.md §7.6). With the flow
  // step, seeds 0-2: 0.046-0.072 m/s with the evidence, 0.38 and more without; the plain clip
  // reads 0.021. The direct step (the default) reads 0.054 on this sequence with the
  // evidence, and 0.012 without it: here the photometric step on the other pixels holds by
  // itself, but over the 44 composites of src/app/NOTES.md (twelfth session) the evidence
  // still cuts its error by a third (0.067 against 0.097 into tum_fr1_xyz_200), so it is
  // tested with the flow step, where each frame's fit depends on it.
  const std::string folder = dynvo::test::sharedDataPath("tum_fr1_xyz_200");
  DYNVO_REQUIRE_SHARED_DATA(folder + "/groundtruth.txt");
  const dynvo::test::TempDir dir;
  const auto [sequence, truth] = compositeIntoRecording("static_two", folder, dir);
  const auto default_step =
      dynvo::computeRpe(truth, runFr1Recording(sequence).estimate);
  const auto flow_step = [](float evidence_limit) {
    return [=](dynvo::app::PipelineOptions& o) {
      o.backend.backend = dynvo::RegistrationBackend::flow;
      o.motion_evidence.evidence_limit = evidence_limit;
    };
  };
  const float limit = dynvo::app::PipelineOptions().motion_evidence.evidence_limit;
  const auto with =
      dynvo::computeRpe(truth, runFr1Recording(sequence, flow_step(limit)).estimate);
  const auto without =
      dynvo::computeRpe(truth, runFr1Recording(sequence, flow_step(0.0f)).estimate);
  RecordProperty("rpe_default", std::to_string(default_step.trans_rmse));
  RecordProperty("rpe_with_evidence", std::to_string(with.trans_rmse));
  RecordProperty("rpe_without_evidence", std::to_string(without.trans_rmse));
  ASSERT_GT(default_step.pairs, 50u);
  EXPECT_LE(default_step.trans_rmse, 0.15);
  EXPECT_LE(with.trans_rmse, 0.15);
  EXPECT_LT(with.trans_rmse, 0.4 * without.trans_rmse);
}

TEST(OdometryPipeline, SlowBoxCompositedIntoARealRecordingDoesNotTakeTheBackgroundLabel)
{
  // One textured box (synthetic static_one, 25 cm at about 1.3 m, 7-12 mm per frame)
  // composited into TUM fr1/xyz, 120 frames: 2-4 sigma off the camera's motion in one frame
  // pair. When a jerk of the hand-held camera (a constant-velocity prediction off by 2-6
  // cm) fails the background's segment in the guard, label 1 went to the segment whose
  // motion was nearest the prediction on its own cells: a sliver of the background or the
  // box, and the camera followed the box (0.22-0.36 m/s on some seeds). Compared over the
  // whole scene, with the guard's tolerance following half the ego-motion guard's
  // widening (docs/algorithm.md §4), six seeds read 0.022-0.032 (the plain clip 0.021 on
  // seed 0). Bar: 1.5 times issue 29's 0.03, a margin for one seed's spread, far below
  // a camera that follows the box.
  const std::string folder = dynvo::test::sharedDataPath("tum_fr1_xyz_200");
  DYNVO_REQUIRE_SHARED_DATA(folder + "/groundtruth.txt");
  const dynvo::test::TempDir dir;
  const auto [sequence, truth] = compositeIntoRecording("static_one", folder, dir);
  const auto rpe = dynvo::computeRpe(truth, runFr1Recording(sequence).estimate);
  RecordProperty("rpe", std::to_string(rpe.trans_rmse));
  ASSERT_GT(rpe.pairs, 50u);
  EXPECT_LE(rpe.trans_rmse, 0.045);
}

TEST(OdometryPipeline, NoiseFollowingThresholdBoundsAreValidated)
{
  dynvo::app::PipelineOptions options;
  options.inlier_noise.min_inlier_threshold =
      2.0f * options.segmentation.inlier_threshold;
  EXPECT_THROW(dynvo::app::OdometryPipeline{options}, std::invalid_argument);
  options.inlier_noise.min_inlier_threshold = 3e-5f;
  options.inlier_noise.inlier_noise_factor = -1.0f;
  EXPECT_THROW(dynvo::app::OdometryPipeline{options}, std::invalid_argument);
}

} // namespace
