// SPDX-License-Identifier: BSD-3-Clause
// ICP/GICP refinement on plain XYZ clouds, compiled once in src/rigid_refinement.cpp so that
// PCL 1.13's icp.h/gicp.h (which include their impl) stay out of every other translation unit.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/registration/static_mask_registration_parameters.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>

namespace dynvo::detail {

/** \brief Refines T_target_source with ICP or GICP.
 * \param[in] source finite points to move (metres, source frame)
 * \param[in] target finite points to align to (metres, target frame)
 * \param[in] parameters backend (icp or gicp; any other returns false),
 *            icp_max_correspondence_distance, icp_max_iterations and
 *            icp_transformation_epsilon are used
 * \param[in] guess initial T_target_source
 * \param[out] T_target_source refined transformation; written only when the method converged
 * \return true when PCL reports convergence
 */
DYNVO_EXPORTS bool
refineRigidTransformation(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& source,
                          const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& target,
                          const StaticMaskRegistrationParameters& parameters,
                          const Eigen::Matrix4f& guess,
                          Eigen::Matrix4f& T_target_source);

} // namespace dynvo::detail
