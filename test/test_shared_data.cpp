// SPDX-License-Identifier: BSD-3-Clause
// The shared-data rule: a missing real recording skips locally and fails under CI=true.
#include "support/shared_data.h"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include "support/temp_dir.h"

#include <cstdlib>
#include <optional>
#include <string>

namespace {

using dynvo::test::MissingData;
using dynvo::test::missingDataAction;

/// Sets an environment variable for one scope and restores it afterwards.
class ScopedEnv {
public:
  ScopedEnv(const char* name, const char* value)
      : name_(name)
  {
    if (const char* old = std::getenv(name))
      old_ = old;
    if (value)
      setenv(name, value, 1);
    else
      unsetenv(name);
  }
  ~ScopedEnv()
  {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
  const char* name_;
  std::optional<std::string> old_;
};

/// A test body needing a folder that does not exist.
void
requireMissingFolder()
{
  DYNVO_REQUIRE_SHARED_DATA("/nonexistent/dynvo_shared_data/rgb.txt");
}

TEST(SharedData, MissingFolderFailsOnlyWhenCiIsTrue)
{
  EXPECT_EQ(missingDataAction(nullptr), MissingData::SKIP);
  EXPECT_EQ(missingDataAction(""), MissingData::SKIP);
  EXPECT_EQ(missingDataAction("false"), MissingData::SKIP);
  EXPECT_EQ(missingDataAction("0"), MissingData::SKIP);
  EXPECT_EQ(missingDataAction("true"), MissingData::FAIL);
  EXPECT_EQ(missingDataAction("TRUE"), MissingData::FAIL);
  EXPECT_EQ(missingDataAction("1"), MissingData::FAIL);
}

TEST(SharedData, MessageNamesTheMissingPathAndIsEmptyWhenPresent)
{
  const dynvo::test::TempDir dir;
  EXPECT_EQ(dynvo::test::missingDataMessage(dir.path().string()), "");
  const std::string missing = dir.file("tum_fr1_xyz_200/rgb.txt");
  const std::string message = dynvo::test::missingDataMessage(missing);
  EXPECT_NE(message.find(missing), std::string::npos) << message;
  EXPECT_NE(message.find("DYNVO_SHARED_DATA_DIR"), std::string::npos) << message;
  EXPECT_EQ(dynvo::test::sharedDataPath("x"),
            std::string(DYNVO_SHARED_DATA_DIR) + "/x");
}

TEST(SharedData, UnderCiTheRequirementIsAFatalFailure)
{
  const ScopedEnv ci("CI", "true");
  EXPECT_FATAL_FAILURE(requireMissingFolder(), "CI=true: the shared data is required");
}

TEST(SharedData, PresentDataNeitherSkipsNorFails)
{
  const ScopedEnv ci("CI", "true");
  const dynvo::test::TempDir dir;
  DYNVO_REQUIRE_SHARED_DATA(dir.path().string());
  SUCCEED(); // reached: the macro returned nothing
}

} // namespace
