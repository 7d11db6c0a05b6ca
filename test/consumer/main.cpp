// SPDX-License-Identifier: BSD-3-Clause
// Uses the installed dynvo: camera presets, the PointFlow point type and a PCL-style module.
#include <dynvo/common/camera.h>
#include <dynvo/common/point_types.h>
#include <dynvo/scene_flow/grid_scene_flow_estimation.h>

#include <pcl/point_cloud.h>

#include <cstdio>

int
main()
{
  const auto camera = dynvo::CameraIntrinsics::fromPreset("fr1");
  pcl::PointCloud<dynvo::PointFlow> grid(40, 30);
  grid[0].getVector3fMap() = camera.backproject(318.6f, 255.3f, 2.0f);
  dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB> flow_estimation;
  flow_estimation.setCameraIntrinsics(camera);
  std::printf("consumer ok fx=%.1f cells=%zu z=%.1f\n", camera.fx, grid.size(),
              grid[0].z);
  return grid[0].z == 2.0f ? 0 : 1;
}
