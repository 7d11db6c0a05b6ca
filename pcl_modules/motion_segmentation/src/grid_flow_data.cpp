// SPDX-License-Identifier: BSD-3-Clause
// Copy of an organized PointFlow grid into plain per-cell buffers.
#include <dynvo/motion_segmentation/grid_flow_data.h>

#include <cmath>
#include <limits>

namespace dynvo {

void
GridFlowData::assign(const pcl::PointCloud<PointFlow>& flow, const FlowGrid& grid)
{
  constexpr float NaN = std::numeric_limits<float>::quiet_NaN();
  geometry = FlowGrid(grid.image_width, grid.image_height, grid.cell_size);
  const std::size_t n = flow.size();
  valid_2d.resize(n);
  valid_3d.resize(n);
  previous_pixel.resize(n);
  a.resize(n);
  b.resize(n);
  information.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const PointFlow& f = flow[i];
    valid_2d[i] = f.valid_2d && std::isfinite(f.prev_u) && std::isfinite(f.prev_v);
    valid_3d[i] = valid_2d[i] && f.valid_3d && std::isfinite(f.x) &&
                  std::isfinite(f.y) && std::isfinite(f.z) && std::isfinite(f.prev_x) &&
                  std::isfinite(f.prev_y) && std::isfinite(f.prev_z);
    previous_pixel[i] =
        valid_2d[i] ? Eigen::Vector2f(f.prev_u, f.prev_v) : Eigen::Vector2f(NaN, NaN);
    a[i] = Eigen::Vector3f(f.prev_x, f.prev_y, f.prev_z);
    b[i] = Eigen::Vector3f(f.x, f.y, f.z);
  }
}

void
GridFlowData::setSensorNoise(const SensorNoiseModel& noise,
                             float focal,
                             float axial_gain,
                             float lateral_gain)
{
  information.assign(size(), Eigen::Matrix3f::Zero());
  for (std::size_t i = 0; i < size(); ++i)
    if (valid_3d[i])
      information[i] =
          noise.transferInformation(a[i], b[i], focal, axial_gain, lateral_gain);
}

} // namespace dynvo
