// SPDX-License-Identifier: BSD-3-Clause
// Runs an app as a child process for app-level tests.
#pragma once

#include <string>

namespace dynvo::test {

struct CommandResult {
  int exit_code = -1; ///< the process's exit status (128 + signal when killed)
  std::string out;    ///< everything it wrote to stdout
  std::string err;    ///< everything it wrote to stderr
};

/// Runs `command` through /bin/sh, capturing stdout and stderr separately.
CommandResult runCommand(const std::string& command);

} // namespace dynvo::test
