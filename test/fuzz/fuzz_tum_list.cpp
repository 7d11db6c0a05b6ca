// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer harness: the TUM list parser and association (dynvo::TumFolderSource's
// constructor) with the input as both rgb.txt and depth.txt. Only pcl::IOException may
// come out.
#include <dynvo/io/tum_folder_source.h>

#include <pcl/exceptions.h>

#include "fuzz_input.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  dynvo::fuzz::writeInput("rgb.txt", data, size);
  dynvo::fuzz::writeInput("depth.txt", data, size);
  try {
    dynvo::TumFolderSource source(dynvo::fuzz::workDir().string(), {});
  }
  catch (const pcl::IOException&) {
  }
  return 0;
}
