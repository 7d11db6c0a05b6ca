// SPDX-License-Identifier: BSD-3-Clause
// The field table and the checks of StaticSetSelectionParameters.
#include <dynvo/registration/static_set_selection_parameters.h>

namespace dynvo {

const ParameterTable<StaticSetSelectionParameters>&
StaticSetSelectionParameters::table()
{
  using P = StaticSetSelectionParameters;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 1, "every field of P needs a row below");
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeField("static_consensus", &P::static_consensus, FieldRange::atLeast(0),
                "x inlier threshold, 0 = off"),
  });
  return table;
}

void
StaticSetSelectionParameters::validate() const
{
  table().checkAll(*this, "[dynvo::StaticSetSelection::Parameters::validate]");
}

} // namespace dynvo
