// SPDX-License-Identifier: BSD-3-Clause
#include "support/run_command.h"
#include "support/temp_dir.h"

#include <cstdio>
#include <cstdlib>
#include <sys/wait.h>

namespace dynvo::test {

CommandResult
runCommand(const std::string& command)
{
  TempDir capture;
  const std::string out = capture.file("stdout"), err = capture.file("stderr");
  const int status = std::system((command + " >" + out + " 2>" + err).c_str());
  CommandResult result;
  if (WIFEXITED(status))
    result.exit_code = WEXITSTATUS(status);
  else if (WIFSIGNALED(status))
    result.exit_code = 128 + WTERMSIG(status);
  result.out = readText(out);
  result.err = readText(err);
  return result;
}

} // namespace dynvo::test
