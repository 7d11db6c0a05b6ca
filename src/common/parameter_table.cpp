// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/parameter_table.h>

#include <cstdio>
#include <cstdlib>

namespace dynvo {

bool
FieldRange::contains(double value) const
{
  if (!std::isfinite(value))
    return false;
  const bool above_lo = lo_open ? value > lo : value >= lo;
  const bool below_hi = hi_open ? value < hi : value <= hi;
  return above_lo && below_hi;
}

std::string
FieldRange::describe() const
{
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return std::string("in ") + (lo_open ? "(" : "[") + formatFieldValue(lo) + ", " +
           formatFieldValue(hi) + (hi_open ? ")" : "]");
  if (has_lo)
    return (lo_open ? "> " : ">= ") + formatFieldValue(lo);
  if (has_hi)
    return (hi_open ? "< " : "<= ") + formatFieldValue(hi);
  return "finite";
}

std::string
formatFieldValue(double value, bool single_precision)
{
  // The shortest %g spelling that parses back to the same double (or float).
  char text[32];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(text, sizeof(text), "%.*g", precision, value);
    const double parsed = std::strtod(text, nullptr);
    if (single_precision ? static_cast<float>(parsed) == static_cast<float>(value)
                         : parsed == value)
      break;
  }
  return text;
}

} // namespace dynvo
