// SPDX-License-Identifier: BSD-3-Clause
// Explicit instantiations of StaticSetSelection (docs/style.md §2.4).
#include <dynvo/registration/impl/static_set_selection.hpp>

#include <pcl/point_types.h>

template class DYNVO_EXPORTS dynvo::StaticSetSelection<pcl::PointXYZRGB>;
template class DYNVO_EXPORTS dynvo::StaticSetSelection<pcl::PointXYZRGBA>;
