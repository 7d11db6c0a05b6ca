// SPDX-License-Identifier: BSD-3-Clause
// The knob of the static-set selection (docs/algorithm.md §7).
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/common/parameter_table.h>

namespace dynvo {

/// Parameters of StaticSetSelection (the single source of the default).
struct DYNVO_EXPORTS StaticSetSelectionParameters {
  /// Static consensus (multiple of the segmentation's inlier threshold in use, >= 0, 0 = off):
  /// after a first fit on the static segment, every valid cell outside the moving objects
  /// whose flow agrees with it within this many thresholds joins the static set for the final
  /// fit. 0 also turns the motion guard off (one fit on the static segment).
  float static_consensus = 2.0f;

  /// Names, units and ranges of the fields above, in file order (ParameterTable).
  static const ParameterTable<StaticSetSelectionParameters>& table();

  /// \throws std::invalid_argument naming the first field out of the range stated above
  void validate() const;
};

} // namespace dynvo
