// SPDX-License-Identifier: BSD-3-Clause
// Explicit instantiations of RigidMotionSegmentation (docs/style.md §2.4).
#include <dynvo/motion_segmentation/impl/rigid_motion_segmentation.hpp>

#include <pcl/point_types.h>

template class DYNVO_EXPORTS dynvo::RigidMotionSegmentation<pcl::PointXYZRGB>;
template class DYNVO_EXPORTS dynvo::RigidMotionSegmentation<pcl::PointXYZRGBA>;
