// SPDX-License-Identifier: BSD-3-Clause
#include "support/temp_dir.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace dynvo::test {

TempDir::TempDir()
{
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = "dynvo_test";
  if (info)
    name += std::string("_") + info->test_suite_name() + "_" + info->name();
  for (char& c : name)
    if (c == '/')
      c = '_';
  static int counter = 0;
  path_ = std::filesystem::temp_directory_path() /
          (name + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir()
{
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

void
writeText(const std::string& path, const std::string& text)
{
  std::ofstream out(path, std::ios::trunc);
  if (!out)
    throw std::runtime_error("cannot write " + path);
  out << text;
}

std::string
readText(const std::string& path)
{
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

} // namespace dynvo::test
