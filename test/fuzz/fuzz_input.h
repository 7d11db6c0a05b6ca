// SPDX-License-Identifier: BSD-3-Clause
// Shared by the libFuzzer harnesses: the readers take file names, so each input is written
// to a file of this process first.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace dynvo::fuzz {

/// A folder of this process under the temp dir (created once, reused for every input).
inline const std::filesystem::path&
workDir()
{
  static const std::filesystem::path dir = [] {
    const auto path = std::filesystem::temp_directory_path() /
                      ("dynvo_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    return path;
  }();
  return dir;
}

/// Writes the input to workDir() / name and returns that path.
inline std::string
writeInput(const std::string& name, const std::uint8_t* data, std::size_t size)
{
  const std::string path = (workDir() / name).string();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

} // namespace dynvo::fuzz
