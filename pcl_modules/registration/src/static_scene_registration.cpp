// SPDX-License-Identifier: BSD-3-Clause
// Explicit instantiations of StaticSceneRegistration (docs/style.md §2.4).
#include <dynvo/registration/impl/static_scene_registration.hpp>

#include <pcl/point_types.h>

template class DYNVO_EXPORTS dynvo::StaticSceneRegistration<pcl::PointXYZRGB>;
template class DYNVO_EXPORTS dynvo::StaticSceneRegistration<pcl::PointXYZRGBA>;
