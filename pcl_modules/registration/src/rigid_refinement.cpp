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
              const StaticSceneRegistrationParameters& parameters,
              const Eigen::Matrix4f& guess,
              Eigen::Matrix4f& T_target_source)
{
  registration.setInputSource(source);
  registration.setInputTarget(target);
  registration.setMaxCorrespondenceDistance(
      parameters.refinement_max_correspondence_distance);
  registration.setMaximumIterations(parameters.refinement_max_iterations);
  registration.setTransformationEpsilon(parameters.refinement_transformation_epsilon);
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
                          RegistrationRefinement method,
                          const StaticSceneRegistrationParameters& parameters,
                          const Eigen::Matrix4f& guess,
                          Eigen::Matrix4f& T_target_source)
{
  switch (method) {
  case RegistrationRefinement::icp: {
    pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
    return runRefinement(icp, source, target, parameters, guess, T_target_source);
  }
  case RegistrationRefinement::gicp: {
    pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
    return runRefinement(gicp, source, target, parameters, guess, T_target_source);
  }
  case RegistrationRefinement::none:
    break;
  }
  return false;
}

} // namespace dynvo::detail
