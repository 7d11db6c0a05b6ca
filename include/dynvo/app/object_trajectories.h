// SPDX-License-Identifier: BSD-3-Clause
// Object-to-world trajectories of the tracked objects of a run (-objects_dir).
#pragma once

#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/common/export.h>
#include <dynvo/common/trajectory.h>
#include <dynvo/eval/trajectory_metrics.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace dynvo::app {

/// A frame counts as moving for an object when its frame origin moves faster than this
/// in the world (m/s): the accuracy asked of object trajectories (issue 15), below
/// which a speed cannot be told from rest.
constexpr double OBJECT_MOVING_SPEED = 0.05;

/// The trajectory of one tracked object and its summary figures.
struct DYNVO_EXPORTS ObjectTrack {
  int id = 0;  ///< segment label (2..)
  int run = 1; ///< 1 for the id's first run of consecutive frames, 2 for its next, ...
  /// T_world_object at each frame of the run (TUM poses, metres). The object frame has
  /// its origin at the segment's centroid, the camera's axes, at the run's first frame.
  Trajectory poses;
  std::size_t frames_moving =
      0;                    ///< frames after the first faster than OBJECT_MOVING_SPEED
  double path_length = 0.0; ///< world distance of the origin over the run (m)

  /// path_length / (last stamp - first stamp) (m/s); 0 with one frame.
  double meanSpeed() const;
};

/** \brief Composes each tracked object's pose from the camera poses and the objects'
 * frame-to-frame motions.
 *
 * An object is a run of consecutive frames with a segment of one id: the tracker hands
 * the id of a segment that disappeared to a later, unrelated segment, so an id that
 * comes back after a frame without it starts a new run (ObjectTrack::run). At a run's
 * first frame, T_world_object = T_world_curr * [I | c], c the centroid of the segment's
 * finite points (camera frame); at each later frame, T_world_object = T_world_curr *
 * T_curr_prev(s) * inv(T_world_prev) * T_world_object(prev), where T_curr_prev(s) is
 * the segment's motion (FrameResult::motions) and T_world_prev the previous camera
 * pose.
 */
class DYNVO_EXPORTS ObjectTrajectories {
public:
  /** \brief Records one frame of the run.
   * \param[in] result the pipeline's result (segments, segment_labels, motions)
   * \param[in] cloud the frame the result is of (its grid)
   * \param[in] T_world_curr the camera pose of the frame in the run's world
   */
  void add(const FrameResult& result,
           const pcl::PointCloud<pcl::PointXYZRGB>& cloud,
           const Eigen::Isometry3d& T_world_curr);

  /// Every run so far, by first frame (then id).
  const std::vector<ObjectTrack>& tracks() const { return tracks_; }

private:
  std::vector<ObjectTrack> tracks_;
  std::map<int, std::size_t>
      active_;              ///< id -> its run in tracks_, ids of the last frame
  std::map<int, int> runs_; ///< runs of each id so far
  Eigen::Isometry3d T_world_prev_ = Eigen::Isometry3d::Identity();
};

/// File name of a run's trajectory in an objects folder: "object_<id>_<run>.txt".
DYNVO_EXPORTS std::string objectTrajectoryName(int id, int run);

/** \brief Writes an objects folder: object_<id>_<run>.txt per track (TUM,
 * object-to-world), camera.txt (the run's camera trajectory: the world the objects
 * are in) and objects_summary.txt, whose '#' header documents the columns "id run
 * first_stamp last_stamp frames_seen frames_moving mean_speed path_length". Each file
 * is replaced whole (PartialFile); the summary lists the tracks of this run, so it is
 * the folder's index.
 * \throws pcl::IOException naming the file that cannot be written
 */
DYNVO_EXPORTS void writeObjectsFolder(const std::string& folder,
                                      const std::vector<ObjectTrack>& tracks,
                                      const Trajectory& camera);

/// What readObjectsFolder() gives.
struct ObjectsFolder {
  Trajectory camera;                ///< camera.txt
  std::vector<ObjectTrack> objects; ///< the summary's tracks, with their trajectories
};

/** \brief Reads a folder written by writeObjectsFolder(): the tracks listed in
 * objects_summary.txt (other files are ignored), their trajectories and camera.txt.
 * \throws pcl::IOException naming the file that is missing or malformed
 */
DYNVO_EXPORTS ObjectsFolder readObjectsFolder(const std::string& folder);

/// An estimated object farther than this from every true object, on average over its
/// frames (m), has no true counterpart: more than the half diagonal of the scenarios'
/// largest object (0.5 m), so a centroid on any of its faces still matches.
constexpr double OBJECT_MATCH_DISTANCE = 0.5;

/// The score of one estimated object (dynvo_evaluate -objects_dir).
struct ObjectScore {
  int id = 0;       ///< estimated object id
  int run = 1;      ///< run of the id (ObjectTrack::run)
  int truth_id = 0; ///< matched true object (0 = none within OBJECT_MATCH_DISTANCE)
  std::size_t frames = 0; ///< frames of its trajectory
  double seconds = 0.0;   ///< last stamp - first stamp (s)
  double distance = 0.0;  ///< mean distance to the nearest true origin (m; 0: none)
  RpeResult rpe;          ///< computeObjectRpe() (pairs 0: not scored, 1 s or shorter)
};

/** \brief Scores the trajectories of an objects folder against a synthetic sequence's
 * objects.txt and groundtruth.txt.
 *
 * Each object's estimate is moved into the truth's world by the camera at its first
 * stamp t_0: T_truth_estimate = groundtruth(t_0) * inv(camera.txt(t_0)), so camera
 * drift before the object appeared does not count. It is matched to the true object
 * whose origin is nearest to the estimated origin on average over the estimate's frames
 * (within OBJECT_MATCH_DISTANCE), and scored with computeObjectRpe() (1 s pairs).
 * \throws pcl::IOException naming a file that is missing or malformed, or a stamp
 *         without ground truth
 */
DYNVO_EXPORTS std::vector<ObjectScore> evaluateObjects(const std::string& objects_dir,
                                                       const std::string& sequence_dir);

/** \brief The result lines of dynvo_evaluate -objects_dir, one per object: "object=<id>
 * truth=<id|none> frames=<n> seconds=<s> distance=<m> rpe_trans_rmse=<m/s|nan>
 * pairs=<n>", then "objects=<n> scored=<n> max_rpe_trans_rmse=<m/s|nan>" (scored:
 * pairs > 0); with json one JSON object {"objects": [...], "scored": n,
 * "max_rpe_trans_rmse": x}. No trailing newline.
 */
DYNVO_EXPORTS std::string formatObjectScores(const std::vector<ObjectScore>& scores,
                                             bool json = false);

} // namespace dynvo::app
