// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer harness: dynvo::readTrajectory on arbitrary bytes. Only pcl::IOException may
// come out; anything else (a crash, a sanitizer report, another exception) is a finding.
#include <dynvo/io/trajectory_io.h>

#include <pcl/exceptions.h>

#include "fuzz_input.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  try {
    dynvo::readTrajectory(dynvo::fuzz::writeInput("trajectory.txt", data, size));
  }
  catch (const pcl::IOException&) {
  }
  return 0;
}
