// SPDX-License-Identifier: BSD-3-Clause
// dynvo_synthesize as users run it: listing, help, writing a sequence and exit codes.
#include <gtest/gtest.h>

#include "support/run_command.h"
#include "support/temp_dir.h"

#include <filesystem>
#include <fstream>
#include <iterator>

namespace {

using dynvo::test::runCommand;
using dynvo::test::TempDir;

const std::string APP = DYNVO_SYNTHESIZE_BIN;

std::string
readFile(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

} // namespace

TEST(SynthesizeApp, ListsEveryScenario)
{
  const auto result = runCommand(APP + " -list");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* name : {"static_one", "static_two", "moving_crossing",
                           "moving_occluder", "stop_and_go", "moving_static"})
    EXPECT_NE(result.out.find(std::string(name) + " "), std::string::npos) << name;
}

TEST(SynthesizeApp, HelpShowsDefaults)
{
  const auto result = runCommand(APP + " -h");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("default moving_crossing"), std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find("default 300"), std::string::npos) << result.out;
}

TEST(SynthesizeApp, WritesTheSequence)
{
  const TempDir dir;
  const std::string out = dir.file("seq");
  const auto result = runCommand(APP +
                                 " -scenario static_two -frames 3 -seed 4 -width 64 "
                                 "-height 48 -threads 2 -out " +
                                 out);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* file :
       {"rgb.txt", "depth.txt", "groundtruth.txt", "objects.txt", "rgb/1.000000.png",
        "depth/1.000000.png", "labels/1.066667.png"})
    EXPECT_TRUE(std::filesystem::exists(dir.file("seq/") + file)) << file;
  EXPECT_NE((result.out + result.err).find(out), std::string::npos);
}

TEST(SynthesizeApp, BadFlagsExitTwo)
{
  const TempDir dir;
  for (const std::string& args :
       {"-out " + dir.file("a") + " -bogus 1",
        "-out " + dir.file("a") + " -scenario nowhere",
        "-out " + dir.file("a") + " -seed -1", std::string("-frames 3")}) {
    const auto result = runCommand(APP + " " + args);
    EXPECT_EQ(result.exit_code, 2) << args << "\n" << result.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("a")));
}

TEST(SynthesizeApp, NonEmptyOutputFolderExitsOneUntouched)
{
  const TempDir dir;
  dynvo::test::writeText(dir.file("rgb.txt"), "mine\n");
  const auto result =
      runCommand(APP + " -frames 2 -width 32 -height 24 -out " + dir.path().string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find(dir.path().string()), std::string::npos) << result.err;
  EXPECT_EQ(readFile(dir.file("rgb.txt")), "mine\n");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}
