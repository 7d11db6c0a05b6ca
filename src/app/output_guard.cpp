// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/cli.h>
#include <dynvo/app/output_guard.h>

#include <algorithm>
#include <filesystem>
#include <unistd.h>

namespace dynvo::app {

namespace fs = std::filesystem;

namespace {

/// The absolute path with every existing part's symbolic links resolved.
fs::path
resolved(const std::string& path)
{
  std::error_code error;
  const fs::path absolute = fs::absolute(path, error);
  const fs::path canonical = fs::weakly_canonical(absolute, error);
  return error ? absolute.lexically_normal() : canonical;
}

/// True when path is folder or lies inside it (both resolved).
bool
within(const fs::path& path, const fs::path& folder)
{
  auto p = path.begin();
  for (auto f = folder.begin(); f != folder.end(); ++f, ++p)
    if (p == path.end() || *p != *f)
      return false;
  return true;
}

bool
writable(const fs::path& folder)
{
  return ::access(folder.c_str(), W_OK) == 0;
}

/// Why the output cannot be written ("" when it can); a file may go into one of the
/// output folders that prepareOutputs() creates.
std::string
problem(const OutputPath& output, const std::vector<OutputPath>& outputs)
{
  std::error_code error;
  const fs::path path(output.path);
  const auto status = fs::status(path, error);
  if (output.folder) {
    if (fs::exists(status) && !fs::is_directory(status))
      return "is a file, not a folder";
    if (fs::is_directory(status) && !writable(path))
      return "folder is not writable";
    return "";
  }
  if (fs::is_directory(status))
    return "is a folder; give a file name";
  if (fs::exists(status) && !fs::is_regular_file(status))
    return "is not a regular file";
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const bool made =
      std::any_of(outputs.begin(), outputs.end(), [&](const OutputPath& o) {
        return o.folder && !o.path.empty() &&
               resolved(o.path) == resolved(parent.string());
      });
  if (made)
    return "";
  if (!fs::is_directory(parent, error))
    return "folder '" + parent.string() + "' does not exist";
  if (!writable(parent))
    return "folder '" + parent.string() + "' is not writable";
  return "";
}

} // namespace

void
prepareOutputs(const std::vector<OutputPath>& outputs,
               const std::vector<std::string>& inputs)
{
  std::vector<std::pair<fs::path, bool>> read; // resolved input, is a folder
  for (const std::string& input : inputs) {
    std::error_code error;
    if (!input.empty() && fs::exists(input, error))
      read.emplace_back(resolved(input), fs::is_directory(input, error));
  }
  std::vector<std::pair<fs::path, const OutputPath*>> written;
  for (const OutputPath& output : outputs) {
    if (output.path.empty())
      continue;
    const std::string where = output.flag + " " + output.path + ": ";
    const std::string why = problem(output, outputs);
    if (!why.empty())
      throw UsageError(where + why);
    const fs::path path = resolved(output.path);
    for (const auto& [input, is_folder] : read) {
      if (path == input)
        throw UsageError(where + "is an input of this run; it would be overwritten");
      if (is_folder && within(path, input))
        throw UsageError(where + "is inside the input folder " + input.string() +
                         "; the run never writes into what it reads");
    }
    for (const auto& [other, flag] : written)
      if (path == other)
        throw UsageError(where + "is also given to " + flag->flag);
    written.emplace_back(path, &output);
  }
  for (const OutputPath& output : outputs) {
    std::error_code error;
    if (output.folder && !output.path.empty() &&
        !fs::create_directories(output.path, error) && error)
      throw UsageError(output.flag + " " + output.path +
                       ": cannot create the folder (" + error.message() + ")");
  }
}

} // namespace dynvo::app
