// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer harness: dynvo::readLabelImage (the PNG size and truncation checks, then
// OpenCV) on arbitrary bytes. Only pcl::IOException may come out.
#include <dynvo/io/label_io.h>

#include <pcl/exceptions.h>

#include "fuzz_input.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  try {
    dynvo::readLabelImage(dynvo::fuzz::writeInput("label.png", data, size));
  }
  catch (const pcl::IOException&) {
  }
  return 0;
}
