// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>
#include <dynvo/io/partial_file.h>
#include <dynvo/io/trajectory_io.h>

#include <pcl/exceptions.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

namespace dynvo {

namespace {

/// Largest accepted magnitude of a stamp (s) or coordinate (m): far beyond any recording,
/// small enough that squared errors summed over millions of poses stay finite.
constexpr double MAX_MAGNITUDE = 1e15;

/// The pose of values[first .. first + 6] (tx ty tz qx qy qz qw).
/// \throws pcl::IOException "<where>quaternion norm ..." when the norm is not 1
Eigen::Isometry3d
poseOf(const std::vector<double>& values, std::size_t first, const std::string& where)
{
  Eigen::Quaterniond q(values[first + 6], values[first + 3], values[first + 4],
                       values[first + 5]);
  if (std::abs(q.norm() - 1.0) > 1e-3)
    throw pcl::IOException(where + "quaternion norm " + std::to_string(q.norm()) +
                           " is not 1 (tolerance 1e-3)");
  q.normalize();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() =
      Eigen::Vector3d(values[first], values[first + 1], values[first + 2]);
  return pose;
}

/** \brief Calls on_line(values, where) for every line that is not blank or a '#'
 * comment, after checking that it holds exactly `columns` finite numbers (commas count
 * as blanks).
 * \throws pcl::IOException "<file>:<line>: <problem>", or when the file cannot be
 * opened
 */
void
readNumberLines(
    const std::string& path,
    const char* columns_text,
    std::size_t columns,
    const std::function<void(const std::vector<double>&, const std::string&)>& on_line)
{
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw pcl::IOException(path + ": is a folder, not a trajectory file");
  std::ifstream in(path);
  if (!in)
    throw pcl::IOException(path + ": cannot open trajectory file");
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#')
      continue;
    const std::string where = path + ":" + std::to_string(number) + ": ";
    // TUM files may separate values by commas as well as blanks.
    for (char& c : line)
      if (c == ',')
        c = ' ';
    std::istringstream tokens(line);
    std::vector<double> values;
    std::string token;
    while (tokens >> token) {
      double value = 0.0;
      if (!parseDecimal(token, value))
        throw pcl::IOException(where + "'" + token +
                               "' is not a finite decimal number");
      if (std::abs(value) > MAX_MAGNITUDE)
        throw pcl::IOException(where + "value '" + token +
                               "' is out of range (magnitude above 1e15)");
      values.push_back(value);
    }
    if (values.size() != columns)
      throw pcl::IOException(where + "expected " + std::to_string(columns) +
                             " numbers (" + columns_text + "), got " +
                             std::to_string(values.size()));
    on_line(values, where);
  }
}

/// Appends a pose whose stamp must be later than the last one's.
void
appendPose(Trajectory& trajectory,
           double stamp,
           const Eigen::Isometry3d& pose,
           const std::string& where)
{
  if (!trajectory.empty() && !(stamp > trajectory.back().timestamp))
    throw pcl::IOException(where + "timestamp " + std::to_string(stamp) +
                           " does not increase");
  trajectory.push_back({stamp, pose});
}

} // namespace

Trajectory
readTrajectory(const std::string& path)
{
  Trajectory trajectory;
  readNumberLines(path, "timestamp tx ty tz qx qy qz qw", 8,
                  [&](const std::vector<double>& values, const std::string& where) {
                    appendPose(trajectory, values[0], poseOf(values, 1, where), where);
                  });
  return trajectory;
}

std::map<int, Trajectory>
readObjectPoses(const std::string& path)
{
  std::map<int, Trajectory> objects;
  readNumberLines(path, "timestamp id tx ty tz qx qy qz qw moving", 10,
                  [&](const std::vector<double>& values, const std::string& where) {
                    const double id = values[1];
                    if (!(id >= 1.0 && id <= 255.0 && id == std::floor(id)))
                      throw pcl::IOException(where + "object id " + std::to_string(id) +
                                             " is not a whole number in [1, 255]");
                    appendPose(objects[static_cast<int>(id)], values[0],
                               poseOf(values, 2, where), where);
                  });
  return objects;
}

std::string
formatTumLine(const StampedPose& pose)
{
  Eigen::Quaterniond q(pose.T_world_camera.rotation());
  q.normalize();
  if (q.w() < 0.0)
    q.coeffs() = -q.coeffs();
  const Eigen::Vector3d& t = pose.T_world_camera.translation();
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f",
                pose.timestamp, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return buffer;
}

void
writeTrajectory(const std::string& path,
                const Trajectory& trajectory,
                const std::string& pose_name)
{
  std::string text = "# timestamp tx ty tz qx qy qz qw (" + pose_name + ", metres)\n";
  for (const StampedPose& pose : trajectory)
    text += formatTumLine(pose) + '\n';
  replaceFile(path, text);
}

} // namespace dynvo
