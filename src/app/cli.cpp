// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/app/cli.h>
#include <dynvo/common/error_text.h>
#include <dynvo/common/timestamps.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <malloc.h>
#include <sstream>

namespace dynvo::app {

Arguments::Arguments(int argc,
                     const char* const* argv,
                     std::vector<Option> options,
                     std::size_t positional)
    : options_(std::move(options))
{
  for (int k = 1; k < argc; ++k) {
    const std::string token = argv[k];
    if (token == "-h" || token == "--help") {
      help_ = true;
      continue;
    }
    const bool is_flag =
        token.size() > 1 && token[0] == '-' &&
        !(std::isdigit(static_cast<unsigned char>(token[1])) || token[1] == '.');
    if (!is_flag) {
      positional_.push_back(token);
      continue;
    }
    const std::string name = token.substr(1);
    const auto option =
        std::find_if(options_.begin(), options_.end(), [&](const Option& o) {
          return o.name == name;
        });
    if (option == options_.end())
      throw UsageError("unknown option '" + token + "'");
    if (has(name))
      throw UsageError("option '" + token + "' given twice");
    std::string value;
    if (!option->value_name.empty()) {
      if (k + 1 >= argc)
        throw UsageError("option '" + token + "' needs a value (" + option->value_name +
                         ")");
      value = argv[++k];
    }
    given_.emplace_back(name, value);
  }
  if (!help_ && positional_.size() != positional)
    throw UsageError("expected " + std::to_string(positional) +
                     " positional argument(s), got " +
                     std::to_string(positional_.size()));
}

bool
Arguments::has(const std::string& name) const
{
  return std::any_of(given_.begin(), given_.end(), [&](const auto& g) {
    return g.first == name;
  });
}

std::string
Arguments::string(const std::string& name, const std::string& fallback) const
{
  for (const auto& [given_name, value] : given_)
    if (given_name == name)
      return value;
  return fallback;
}

double
Arguments::number(const std::string& name, double fallback) const
{
  if (!has(name))
    return fallback;
  const std::string text = string(name);
  double value = 0.0;
  if (!parseDecimal(text, value))
    throw UsageError("option '-" + name + "' expects a number, got '" + text + "'");
  return value;
}

std::vector<double>
Arguments::numbers(const std::string& name,
                   std::size_t count,
                   const std::vector<double>& fallback) const
{
  if (!has(name))
    return fallback;
  const std::string text = string(name);
  std::vector<double> values;
  bool parsed = true;
  for (std::size_t begin = 0; parsed;) {
    const std::size_t end = text.find(',', begin);
    double value = 0.0;
    parsed = parseDecimal(text.substr(begin, end - begin), value);
    values.push_back(value);
    if (end == std::string::npos)
      break;
    begin = end + 1;
  }
  if (!parsed || values.size() != count)
    throw UsageError("option '-" + name + "' expects " + std::to_string(count) +
                     " comma-separated numbers, got '" + text + "'");
  return values;
}

long
Arguments::integer(const std::string& name, long fallback) const
{
  if (!has(name))
    return fallback;
  const std::string text = string(name);
  std::size_t used = 0;
  long value = 0;
  try {
    value = std::stol(text, &used);
  }
  catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw UsageError("option '-" + name + "' expects an integer, got '" + text + "'");
  return value;
}

long
Arguments::integer(const std::string& name, long fallback, long low, long high) const
{
  const long value = integer(name, fallback);
  if (has(name) && (value < low || value > high))
    throw UsageError("-" + name + " must be in [" + std::to_string(low) + ", " +
                     std::to_string(high) + "], got " + std::to_string(value));
  return value;
}

std::string
Arguments::optionsHelp() const
{
  std::ostringstream out;
  for (const Option& option : options_) {
    std::string head = "  -" + option.name;
    if (!option.value_name.empty())
      head += " " + option.value_name;
    out << head << std::string(head.size() < 24 ? 24 - head.size() : 1, ' ')
        << option.help << "\n";
  }
  return out.str();
}

std::string
errorMessage(const std::exception& e)
{
  return shortenLongWords(errorText(e));
}

std::string
shortenLongWords(const std::string& text)
{
  constexpr std::size_t LONGEST = 200, HEAD = 120, TAIL = 40;
  std::string out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t blank = text.find_first_of(" \t\n", start);
    const std::size_t end = blank == std::string::npos ? text.size() : blank;
    const std::size_t length = end - start;
    if (length > LONGEST)
      out += text.substr(start, HEAD) + "...(" + std::to_string(length) +
             " characters)..." + text.substr(end - TAIL, TAIL);
    else
      out += text.substr(start, length);
    if (end < text.size())
      out += text[end];
    start = end + 1;
  }
  return out;
}

namespace {

/** Keeps the memory a frame frees for the next frame's buffers. By default glibc maps a
 * large block on its own and unmaps it when freed, and returns the heap's free top to the
 * system beyond a trim threshold (both adjusted as blocks are freed); a VGA frame frees a
 * 9.8 MB cloud, its images and pyramids, and the next frame touched fresh pages again: 260-310
 * page faults per frame on tum_fr1_xyz_200, a tenth of a one-thread run's wall time
 * (src/app/NOTES.md, thirty-third session). Setting either threshold turns off glibc's
 * adjustment of both, so both are set.
 */
void
keepFreedMemory()
{
#ifdef __GLIBC__
  constexpr int MMAP_THRESHOLD = 32 << 20; // glibc's largest on 64-bit
  constexpr int TRIM_THRESHOLD = 64 << 20;
  mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD);
  mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD);
#endif
}

} // namespace

int
runApp(const std::string& usage, const std::function<int()>& body)
{
  keepFreedMemory();
  try {
    return body();
  }
  catch (const UsageError& e) {
    std::fprintf(stderr, "Error: %s\nUsage: %s\n(-h lists the options)\n",
                 errorMessage(e).c_str(), usage.c_str());
    return 2;
  }
  catch (const std::exception& e) {
    pcl::console::print_error("Error: %s\n", errorMessage(e).c_str());
    return 1;
  }
}

} // namespace dynvo::app
