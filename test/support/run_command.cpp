// SPDX-License-Identifier: BSD-3-Clause
#include "support/run_command.h"
#include "support/temp_dir.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

namespace dynvo::test {

namespace {

std::string
slurp(const std::string& path)
{
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

} // namespace

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
  result.out = slurp(out);
  result.err = slurp(err);
  return result;
}

} // namespace dynvo::test
