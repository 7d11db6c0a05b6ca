// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer harness: a PCD file through dynvo::PcdSequenceSource (the header check against
// the file size and the frame-size limit, then PCL's reader). Only pcl::IOException may
// come out; a large allocation (libFuzzer -rss_limit_mb, default 2048) is a finding too.
#include <dynvo/io/pcd_sequence_source.h>

#include <pcl/exceptions.h>

#include "fuzz_input.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  dynvo::fuzz::writeInput("0.pcd", data, size);
  try {
    dynvo::PcdSequenceSource source(dynvo::fuzz::workDir().string());
    dynvo::Frame frame;
    source.next(frame);
  }
  catch (const pcl::IOException&) {
  }
  return 0;
}
