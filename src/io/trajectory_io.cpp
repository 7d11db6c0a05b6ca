// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>
#include <dynvo/io/partial_file.h>
#include <dynvo/io/trajectory_io.h>

#include <pcl/exceptions.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace dynvo {

namespace {

/// Largest accepted magnitude of a stamp (s) or coordinate (m): far beyond any recording,
/// small enough that squared errors summed over millions of poses stay finite.
constexpr double MAX_MAGNITUDE = 1e15;

} // namespace

Trajectory
readTrajectory(const std::string& path)
{
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw pcl::IOException(path + ": is a folder, not a trajectory file");
  std::ifstream in(path);
  if (!in)
    throw pcl::IOException(path + ": cannot open trajectory file");
  Trajectory trajectory;
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
    if (values.size() != 8)
      throw pcl::IOException(where +
                             "expected 8 numbers (timestamp tx ty tz qx qy qz "
                             "qw), got " +
                             std::to_string(values.size()));
    if (!trajectory.empty() && !(values[0] > trajectory.back().timestamp))
      throw pcl::IOException(where + "timestamp " + std::to_string(values[0]) +
                             " does not increase");
    Eigen::Quaterniond q(values[7], values[4], values[5], values[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3)
      throw pcl::IOException(where + "quaternion norm " + std::to_string(q.norm()) +
                             " is not 1 (tolerance 1e-3)");
    q.normalize();
    StampedPose pose;
    pose.timestamp = values[0];
    pose.T_world_camera.linear() = q.toRotationMatrix();
    pose.T_world_camera.translation() =
        Eigen::Vector3d(values[1], values[2], values[3]);
    trajectory.push_back(pose);
  }
  return trajectory;
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
writeTrajectory(const std::string& path, const Trajectory& trajectory)
{
  std::string text = "# timestamp tx ty tz qx qy qz qw (camera-to-world, metres)\n";
  for (const StampedPose& pose : trajectory)
    text += formatTumLine(pose) + '\n';
  replaceFile(path, text);
}

} // namespace dynvo
