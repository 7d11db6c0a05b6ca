// SPDX-License-Identifier: BSD-3-Clause
// The real RGB-D recordings under DYNVO_SHARED_DATA_DIR (CMake cache variable): the only
// test inputs with real sensor noise. Locally a missing folder skips the test; under CI
// (environment variable CI=true at test time) it fails, so CI never passes without them.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace dynvo::test {

/// What a test does when its shared data folder is missing.
enum class MissingData {
  SKIP, ///< GTEST_SKIP (a developer machine without the recordings)
  FAIL  ///< GTEST_FAIL (CI: the recordings must be there)
};

/// FAIL when the CI variable's value is "true" or "1" (any case), else SKIP.
/// \param[in] ci_env the value of the CI environment variable, nullptr when unset
MissingData missingDataAction(const char* ci_env);

/// DYNVO_SHARED_DATA_DIR + "/" + name (e.g. "tum_fr1_xyz_200").
std::string sharedDataPath(const std::string& name);

/// Empty when `marker` (a file inside the folder) exists; otherwise the message to skip
/// or fail with, naming the path and the CMake variable.
std::string missingDataMessage(const std::string& marker);

} // namespace dynvo::test

/// In a test body or SetUp(): skips (locally) or fails (CI=true) unless `marker` exists.
#define DYNVO_REQUIRE_SHARED_DATA(marker)                                              \
  do {                                                                                 \
    const std::string dynvo_missing_ = ::dynvo::test::missingDataMessage(marker);      \
    if (!dynvo_missing_.empty()) {                                                     \
      if (::dynvo::test::missingDataAction(std::getenv("CI")) ==                       \
          ::dynvo::test::MissingData::FAIL)                                            \
        GTEST_FAIL() << dynvo_missing_ << " (CI=true: the shared data is required)";   \
      else                                                                             \
        GTEST_SKIP() << dynvo_missing_;                                                \
    }                                                                                  \
  } while (false)
