// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace dynvo {

bool
parseDecimal(const std::string& token, double& value)
{
  const auto digits = [&token](std::size_t& i) {
    const std::size_t start = i;
    while (i < token.size() && std::isdigit(static_cast<unsigned char>(token[i])))
      ++i;
    return i - start;
  };
  std::size_t i = 0;
  if (i < token.size() && (token[i] == '+' || token[i] == '-'))
    ++i;
  std::size_t mantissa = digits(i);
  if (i < token.size() && token[i] == '.')
    mantissa += digits(++i);
  if (mantissa == 0)
    return false;
  if (i < token.size() && (token[i] == 'e' || token[i] == 'E')) {
    if (++i < token.size() && (token[i] == '+' || token[i] == '-'))
      ++i;
    if (digits(i) == 0)
      return false;
  }
  if (i != token.size())
    return false;
  std::size_t used = 0;
  double parsed = 0.0;
  try {
    parsed = std::stod(token, &used);
  }
  catch (const std::exception&) {
    return false; // out of range
  }
  if (used != token.size() || !std::isfinite(parsed))
    return false;
  value = parsed;
  return true;
}

std::vector<std::pair<std::size_t, std::size_t>>
associateTimestamps(const std::vector<double>& first,
                    const std::vector<double>& second,
                    double max_difference,
                    double offset)
{
  // Candidates come from a window search in the sorted second list, so the cost is
  // O(n log n) instead of associate.py's O(n m); the greedy choice is the same.
  std::vector<std::size_t> order(second.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return second[a] < second[b];
  });
  std::vector<double> sorted_second(second.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    sorted_second[k] = second[order[k]] + offset;

  std::vector<std::tuple<double, std::size_t, std::size_t>> candidates;
  for (std::size_t i = 0; i < first.size(); ++i) {
    auto it = std::lower_bound(sorted_second.begin(), sorted_second.end(),
                               first[i] - max_difference);
    for (; it != sorted_second.end() && *it <= first[i] + max_difference; ++it) {
      const double diff = std::abs(first[i] - *it);
      if (diff < max_difference)
        candidates.emplace_back(diff, i, order[it - sorted_second.begin()]);
    }
  }
  std::sort(candidates.begin(), candidates.end());

  std::vector<bool> used_first(first.size(), false);
  std::vector<bool> used_second(second.size(), false);
  std::vector<std::pair<std::size_t, std::size_t>> matches;
  for (const auto& [diff, i, j] : candidates) {
    if (used_first[i] || used_second[j])
      continue;
    used_first[i] = used_second[j] = true;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end(), [&](const auto& a, const auto& b) {
    return first[a.first] < first[b.first];
  });
  return matches;
}

std::size_t
findClosestIndex(const std::vector<double>& sorted, double t)
{
  std::size_t beginning = 0;
  std::size_t end = sorted.size();
  std::size_t best = 0;
  double difference = std::abs(sorted.front() - t);
  while (beginning < end) {
    const std::size_t middle = (beginning + end) / 2;
    if (std::abs(sorted[middle] - t) < difference) {
      difference = std::abs(sorted[middle] - t);
      best = middle;
    }
    if (t == sorted[middle])
      return middle;
    if (sorted[middle] > t)
      end = middle;
    else
      beginning = middle + 1;
  }
  return best;
}

} // namespace dynvo
