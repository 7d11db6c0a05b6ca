// SPDX-License-Identifier: BSD-3-Clause
// Explicit instantiations of StaticMaskRegistration (docs/style.md §2.4).
#include <dynvo/registration/impl/static_mask_registration.hpp>

#include <pcl/point_types.h>

template class DYNVO_EXPORTS dynvo::StaticMaskRegistration<pcl::PointXYZRGB>;
template class DYNVO_EXPORTS dynvo::StaticMaskRegistration<pcl::PointXYZRGBA>;
