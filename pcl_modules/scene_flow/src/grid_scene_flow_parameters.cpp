// SPDX-License-Identifier: BSD-3-Clause
// The field table and the checks of GridSceneFlowParameters.
#include <dynvo/scene_flow/grid_scene_flow_parameters.h>

namespace dynvo {

const ParameterTable<GridSceneFlowParameters>&
GridSceneFlowParameters::table()
{
  using P = GridSceneFlowParameters;
  // The nested depth struct counts as one member.
  static_assert(AGGREGATE_FIELD_COUNT<P> == 13, "every field of P needs a row below");
  using Fields = std::vector<ParameterTable<P>::Field>;
  static const ParameterTable<P> table{
      Fields{
          makeField("cell_size", &P::cell_size, FieldRange::atLeast(2), "w_grid, px")},
      nestFields("depth", &P::depth, DepthPreprocessing::Parameters::table().fields()),
      Fields{
          makeField("window_size", &P::window_size, FieldRange::atLeast(3),
                    "LK win, px"),
          makeField("max_pyramid_level", &P::max_pyramid_level, FieldRange::atLeast(0),
                    "LK levels, 0 = no pyramid"),
          makeField("max_iterations", &P::max_iterations, FieldRange::atLeast(1),
                    "LK iters per level"),
          makeField("epsilon", &P::epsilon, FieldRange::above(0), "LK eps, px"),
          makeField("min_eigen_threshold", &P::min_eigen_threshold,
                    FieldRange::above(0), "OpenCV minEigThreshold"),
          makeChoiceField("forward_backward_check", &P::forward_backward_check,
                          {"full", "local"}, "backward track of the fb check"),
          makeField("forward_backward_threshold", &P::forward_backward_threshold,
                    FieldRange::above(0), "fb_max, px"),
          makeField("depth_edge_tolerance", &P::depth_edge_tolerance,
                    FieldRange::atLeast(0), "tau_edge, relative"),
          // Before depth_window_radius: the order of the files written so far.
          makeField("max_flow", &P::max_flow, FieldRange::above(0),
                    "max_flow3d, metres per frame"),
          makeField("depth_window_radius", &P::depth_window_radius,
                    FieldRange::closed(0, 15), "depth window r, px, 0 = one pixel"),
          makeField("weight_reference_depth", &P::weight_reference_depth,
                    FieldRange::above(0), "z_ref, metres"),
      }};
  return table;
}

void
GridSceneFlowParameters::validate() const
{
  table().checkAll(*this, "[dynvo::GridSceneFlowParameters::validate]");
  depth.validate(); // the cross-field rule of the depth range
}

} // namespace dynvo
