// SPDX-License-Identifier: BSD-3-Clause
// A temporary folder per test, removed when the test ends.
#pragma once

#include <filesystem>
#include <string>

namespace dynvo::test {

/// Creates a fresh, empty folder under the system temp dir; removes it on destruction.
class TempDir {
public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

  /// path() / name as a string.
  std::string file(const std::string& name) const { return (path_ / name).string(); }

private:
  std::filesystem::path path_;
};

/// Writes text to a file, replacing it.
void writeText(const std::string& path, const std::string& text);

/// The whole content of a file ("" when it cannot be read).
std::string readText(const std::string& path);

} // namespace dynvo::test
