// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/object_trajectories.h>
#include <dynvo/io/partial_file.h>
#include <dynvo/io/trajectory_io.h>

#include <pcl/exceptions.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace dynvo::app {

namespace fs = std::filesystem;

namespace {

const char* const SUMMARY_NAME = "objects_summary.txt";
const char* const CAMERA_NAME = "camera.txt";

/// Centroid of the finite points of a segment (camera frame, metres); false when none.
bool
segmentCentroid(const pcl::PointCloud<pcl::PointXYZRGB>& cloud,
                const pcl::PointIndices& segment,
                Eigen::Vector3d& centroid)
{
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t count = 0;
  for (const auto index : segment.indices) {
    const auto& point = cloud[index];
    if (!std::isfinite(point.x) || !std::isfinite(point.y) || !std::isfinite(point.z))
      continue;
    sum += point.getVector3fMap().cast<double>();
    ++count;
  }
  if (count == 0)
    return false;
  centroid = sum / static_cast<double>(count);
  return true;
}

} // namespace

double
ObjectTrack::meanSpeed() const
{
  const double span =
      poses.size() < 2 ? 0.0 : poses.back().timestamp - poses.front().timestamp;
  return span > 0.0 ? path_length / span : 0.0;
}

void
ObjectTrajectories::add(const FrameResult& result,
                        const pcl::PointCloud<pcl::PointXYZRGB>& cloud,
                        const Eigen::Isometry3d& T_world_curr)
{
  std::map<int, std::size_t> active;
  for (std::size_t s = 1; s < result.segments.size(); ++s) {
    const int id = result.segment_labels[s];
    const auto known = active_.find(id);
    if (known == active_.end()) {
      Eigen::Vector3d centroid;
      if (!segmentCentroid(cloud, result.segments[s], centroid))
        continue;
      ObjectTrack track;
      track.id = id;
      track.run = ++runs_[id];
      track.poses.push_back(
          {result.timestamp, T_world_curr * Eigen::Translation3d(centroid)});
      active[id] = tracks_.size();
      tracks_.push_back(track);
      continue;
    }
    ObjectTrack& track = tracks_[known->second];
    const StampedPose& before = track.poses.back();
    const Eigen::Isometry3d T_curr_prev(result.motions[s].cast<double>());
    const Eigen::Isometry3d T_world_object =
        T_world_curr * T_curr_prev * T_world_prev_.inverse() * before.T_world_camera;
    const double step =
        (T_world_object.translation() - before.T_world_camera.translation()).norm();
    const double dt = result.timestamp - before.timestamp;
    track.path_length += step;
    if (dt > 0.0 && step / dt > OBJECT_MOVING_SPEED)
      ++track.frames_moving;
    track.poses.push_back({result.timestamp, T_world_object});
    active[id] = known->second;
  }
  active_ = std::move(active);
  T_world_prev_ = T_world_curr;
}

std::string
objectTrajectoryName(int id, int run)
{
  return "object_" + std::to_string(id) + "_" + std::to_string(run) + ".txt";
}

void
writeObjectsFolder(const std::string& folder,
                   const std::vector<ObjectTrack>& tracks,
                   const Trajectory& camera)
{
  const fs::path root(folder);
  std::string summary =
      "# objects of a dynvo_odometry run; object_<id>_<run>.txt holds each one's\n"
      "# trajectory (TUM, object-to-world: origin at its first centroid, camera axes "
      "at its\n"
      "# first frame), camera.txt the camera's (the world of the objects).\n"
      "# id: segment label (2..); run: 1 for the id's first run of consecutive frames, "
      "2\n"
      "# for the next (the tracker reuses ids); first_stamp, last_stamp: the run's "
      "first\n"
      "# and last frame (s); frames_seen: frames of the run; frames_moving: of those "
      "after\n"
      "# the first, frames in which the origin moved faster than 0.05 m/s in the "
      "world;\n"
      "# mean_speed: path_length / (last_stamp - first_stamp) (m/s, 0 for one frame);\n"
      "# path_length: world distance of the origin over the run (m).\n"
      "# id run first_stamp last_stamp frames_seen frames_moving mean_speed "
      "path_length\n";
  for (const ObjectTrack& track : tracks) {
    writeTrajectory((root / objectTrajectoryName(track.id, track.run)).string(),
                    track.poses, "object-to-world");
    char line[256];
    std::snprintf(line, sizeof(line), "%d %d %.6f %.6f %zu %zu %.6f %.6f\n", track.id,
                  track.run, track.poses.front().timestamp,
                  track.poses.back().timestamp, track.poses.size(), track.frames_moving,
                  track.meanSpeed(), track.path_length);
    summary += line;
  }
  writeTrajectory((root / CAMERA_NAME).string(), camera);
  replaceFile((root / SUMMARY_NAME).string(), summary);
}

ObjectsFolder
readObjectsFolder(const std::string& folder)
{
  const fs::path root(folder);
  const std::string summary_path = (root / SUMMARY_NAME).string();
  std::ifstream summary(summary_path);
  if (!summary)
    throw pcl::IOException(summary_path + ": cannot open the objects summary");
  ObjectsFolder result;
  result.camera = readTrajectory((root / CAMERA_NAME).string());
  std::string line;
  for (int number = 1; std::getline(summary, line); ++number) {
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream tokens(line);
    ObjectTrack track;
    double first = 0.0, last = 0.0, speed = 0.0;
    std::size_t seen = 0;
    if (!(tokens >> track.id >> track.run >> first >> last >> seen >>
          track.frames_moving >> speed >> track.path_length) ||
        track.id < 1 || track.run < 1)
      throw pcl::IOException(summary_path + ":" + std::to_string(number) +
                             ": expected 'id run first_stamp last_stamp frames_seen "
                             "frames_moving mean_speed path_length'");
    track.poses =
        readTrajectory((root / objectTrajectoryName(track.id, track.run)).string());
    result.objects.push_back(track);
  }
  return result;
}

std::vector<ObjectScore>
evaluateObjects(const std::string& objects_dir, const std::string& sequence_dir)
{
  const ObjectsFolder estimate = readObjectsFolder(objects_dir);
  const fs::path sequence(sequence_dir);
  const std::string groundtruth_path = (sequence / "groundtruth.txt").string();
  const Trajectory groundtruth = readTrajectory(groundtruth_path);
  const auto truth = readObjectPoses((sequence / "objects.txt").string());
  // 0.1 s: three frames at 30 Hz; synthetic ground truth has a pose at every frame.
  const double max_gap = 0.1;
  const auto poseAt = [&](const Trajectory& poses, double stamp,
                          const std::string& file) {
    const auto pose = interpolatePose(poses, stamp, max_gap);
    if (!pose)
      throw pcl::IOException(file + ": no pose at stamp " + std::to_string(stamp));
    return *pose;
  };
  std::vector<ObjectScore> scores;
  for (const ObjectTrack& track : estimate.objects) {
    const Trajectory& poses = track.poses;
    ObjectScore score;
    score.id = track.id;
    score.run = track.run;
    score.frames = poses.size();
    if (poses.empty()) {
      scores.push_back(score);
      continue;
    }
    score.seconds = poses.back().timestamp - poses.front().timestamp;
    const double t_0 = poses.front().timestamp;
    const Eigen::Isometry3d T_truth_estimate =
        poseAt(groundtruth, t_0, groundtruth_path) *
        poseAt(estimate.camera, t_0, objects_dir + "/camera.txt").inverse();
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& [truth_id, truth_poses] : truth) {
      double sum = 0.0;
      std::size_t count = 0;
      for (const StampedPose& pose : poses)
        if (const auto true_pose =
                interpolatePose(truth_poses, pose.timestamp, max_gap)) {
          sum += (T_truth_estimate * pose.T_world_camera.translation() -
                  true_pose->translation())
                     .norm();
          ++count;
        }
      if (count > 0 && sum / count < nearest) {
        nearest = sum / count;
        score.truth_id = truth_id;
      }
    }
    score.distance = std::isfinite(nearest) ? nearest : 0.0;
    if (nearest > OBJECT_MATCH_DISTANCE)
      score.truth_id = 0;
    if (score.truth_id != 0) {
      try {
        score.rpe = computeObjectRpe(truth.at(score.truth_id), poses, T_truth_estimate);
      }
      catch (const std::invalid_argument&) {
        score.rpe = RpeResult{}; // no pair 1 s apart: not scored
      }
    }
    scores.push_back(score);
  }
  return scores;
}

std::string
formatObjectScores(const std::vector<ObjectScore>& scores, bool json)
{
  std::size_t scored = 0;
  double worst = std::nan("");
  std::string text = json ? "{\"objects\": [" : "";
  for (const ObjectScore& score : scores) {
    const bool has_rpe = score.rpe.pairs > 0;
    if (has_rpe) {
      ++scored;
      worst = std::isnan(worst) ? score.rpe.trans_rmse
                                : std::max(worst, score.rpe.trans_rmse);
    }
    char line[512];
    const std::string truth_id =
        score.truth_id ? std::to_string(score.truth_id) : (json ? "null" : "none");
    const std::string rpe =
        has_rpe ? std::to_string(score.rpe.trans_rmse) : (json ? "null" : "nan");
    std::snprintf(
        line, sizeof(line),
        json ? "%s{\"object\": %d, \"run\": %d, \"truth\": %s, \"frames\": %zu, "
               "\"seconds\": %.6f, \"distance\": %.6f, "
               "\"rpe_trans_rmse\": %s, \"pairs\": %zu}"
             : "%sobject=%d run=%d truth=%s frames=%zu seconds=%.6f distance=%.6f "
               "rpe_trans_rmse=%s pairs=%zu\n",
        json && &score != &scores.front() ? ", " : "", score.id, score.run,
        truth_id.c_str(), score.frames, score.seconds, score.distance, rpe.c_str(),
        score.rpe.pairs);
    text += line;
  }
  const std::string max =
      std::isnan(worst) ? (json ? "null" : "nan") : std::to_string(worst);
  if (json)
    return text + "], \"scored\": " + std::to_string(scored) +
           ", \"max_rpe_trans_rmse\": " + max + "}";
  return text + "objects=" + std::to_string(scores.size()) +
         " scored=" + std::to_string(scored) + " max_rpe_trans_rmse=" + max;
}

} // namespace dynvo::app
