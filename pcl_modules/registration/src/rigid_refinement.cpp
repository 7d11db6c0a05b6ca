// SPDX-License-Identifier: BSD-3-Clause
// The only translation unit that parses PCL's ICP and GICP templates (docs/style.md
// §2.4).
#include <dynvo/registration/rigid_refinement.h>

#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>

namespace dynvo::detail {

namespace {

/// Applies the shared settings, runs the registration and reads its result.
template <typename RegistrationT>
bool
runRefinement(RegistrationT& registration,
              const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& source,
              const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& target,
              const StaticMaskRegistrationParameters& parameters,
              const Eigen::Matrix4f& guess,
              Eigen::Matrix4f& T_target_source)
{
  registration.setInputSource(source);
  registration.setInputTarget(target);
  registration.setMaxCorrespondenceDistance(parameters.icp_max_correspondence_distance);
  registration.setMaximumIterations(parameters.icp_max_iterations);
  registration.setTransformationEpsilon(parameters.icp_transformation_epsilon);
  pcl::PointCloud<pcl::PointXYZ> aligned;
  registration.align(aligned, guess);
  if (!registration.hasConverged())
    return false;
  T_target_source = registration.getFinalTransformation();
  return true;
}

} // namespace

bool
refineRigidTransformation(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& source,
                          const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& target,
                          const StaticMaskRegistrationParameters& parameters,
                          const Eigen::Matrix4f& guess,
                          Eigen::Matrix4f& T_target_source)
{
  switch (parameters.backend) {
  case RegistrationBackend::icp: {
    pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
    return runRefinement(icp, source, target, parameters, guess, T_target_source);
  }
  case RegistrationBackend::gicp: {
    pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
    return runRefinement(gicp, source, target, parameters, guess, T_target_source);
  }
  case RegistrationBackend::flow:
  case RegistrationBackend::cv_rgbd:
  case RegistrationBackend::direct:
    break;
  }
  return false;
}

} // namespace dynvo::detail
