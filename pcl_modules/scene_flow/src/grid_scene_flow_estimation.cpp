// SPDX-License-Identifier: BSD-3-Clause
// Explicit instantiations of GridSceneFlowEstimation (docs/style.md §2.4).
#include <dynvo/scene_flow/impl/grid_scene_flow_estimation.hpp>

#include <pcl/point_types.h>

template class DYNVO_EXPORTS dynvo::GridSceneFlowEstimation<pcl::PointXYZRGB>;
template class DYNVO_EXPORTS dynvo::GridSceneFlowEstimation<pcl::PointXYZRGBA>;
