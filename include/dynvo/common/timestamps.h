// SPDX-License-Identifier: BSD-3-Clause
// Timestamp association as done by the TUM RGB-D benchmark's associate.py.
#pragma once

#include <dynvo/common/export.h>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace dynvo {

/** \brief Parses a plain decimal number, the only form text files may hold:
 * `[+-]digits[.digits][(e|E)[+-]digits]` (or `.digits`), with a finite value. Hexadecimal
 * (`0x1p3`), `inf`, `nan` and trailing characters are refused (std::stod takes them).
 * \param[in] token the whole text
 * \param[out] value the number; untouched when false is returned
 * \return true when the token is such a number
 */
DYNVO_EXPORTS bool parseDecimal(const std::string& token, double& value);

/** \brief One-to-one association of two timestamp lists, as associate.py does.
 *
 * Every pair (a, b) with |a - (b + offset)| < max_difference is a candidate; candidates
 * are taken greedily by increasing difference, each stamp being used at most once.
 * \param[in] first timestamps (seconds), any order
 * \param[in] second timestamps (seconds), any order
 * \param[in] max_difference largest accepted difference (seconds), default 0.02
 * \param[in] offset added to the second list's stamps (seconds), default 0
 * \return index pairs (into first, into second), sorted by the first stamp
 */
DYNVO_EXPORTS std::vector<std::pair<std::size_t, std::size_t>>
associateTimestamps(const std::vector<double>& first,
                    const std::vector<double>& second,
                    double max_difference = 0.02,
                    double offset = 0.0);

/** \brief Index of the element of the sorted list closest to t, found exactly as
 * the TUM benchmark's find_closest_index (binary search keeping the best probe).
 * \param[in] sorted non-empty list sorted in increasing order
 * \param[in] t query value
 */
DYNVO_EXPORTS std::size_t findClosestIndex(const std::vector<double>& sorted, double t);

} // namespace dynvo
