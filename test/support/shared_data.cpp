// SPDX-License-Identifier: BSD-3-Clause
#include "support/shared_data.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace dynvo::test {

MissingData
missingDataAction(const char* ci_env)
{
  if (ci_env == nullptr)
    return MissingData::SKIP;
  std::string value(ci_env);
  std::transform(value.begin(), value.end(), value.begin(), [](unsigned char c) {
    return static_cast<char>(std::tolower(c));
  });
  return value == "true" || value == "1" ? MissingData::FAIL : MissingData::SKIP;
}

std::string
sharedDataPath(const std::string& name)
{
  return std::string(DYNVO_SHARED_DATA_DIR) + "/" + name;
}

std::string
missingDataMessage(const std::string& marker)
{
  if (std::filesystem::exists(marker))
    return {};
  return "shared data not found at " + marker +
         " (set the CMake cache variable DYNVO_SHARED_DATA_DIR)";
}

} // namespace dynvo::test
