// SPDX-License-Identifier: BSD-3-Clause
// The checks every app makes on its output paths before it reads the first frame.
#pragma once

#include <dynvo/common/export.h>

#include <string>
#include <vector>

namespace dynvo::app {

/// One output of a run, as given on the command line.
struct OutputPath {
  std::string flag;    ///< e.g. "-out", for messages
  std::string path;    ///< "" = not requested (skipped)
  bool folder = false; ///< a folder the run writes into (created when missing)
};

/** \brief Refuses unsafe outputs before a run starts, then creates the output folders.
 *
 * An output file must not be a folder or another non-regular file, and its folder must
 * exist and be writable; an output folder must be a folder or creatable. No two outputs
 * may name the same path. No output may be, or lie inside, an input (a file the run reads
 * or a folder it reads files from), so a run never writes into or over what it reads.
 * Paths are compared after resolving symbolic links.
 * \param[in] outputs the run's outputs
 * \param[in] inputs files and folders the run reads (missing ones are skipped)
 * \throws UsageError naming the flag, the path and the problem
 */
DYNVO_EXPORTS void prepareOutputs(const std::vector<OutputPath>& outputs,
                                  const std::vector<std::string>& inputs);

} // namespace dynvo::app
