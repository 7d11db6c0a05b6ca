// SPDX-License-Identifier: BSD-3-Clause
// Strict command-line parsing for the dynvo apps (PCL-tool style: single dash, snake_case).
#pragma once

#include <dynvo/common/export.h>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace dynvo::app {

/// A usage error (unknown flag, missing or malformed value): apps exit with code 2.
class UsageError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// One accepted flag. A flag with an empty value_name is a switch (takes no value).
struct Option {
  std::string name;       ///< without the dash, e.g. "tum_dir"
  std::string value_name; ///< e.g. "DIR"; empty for a switch
  std::string help;       ///< one line, stating units and the default
};

/** \brief Parsed and checked arguments.
 *
 * Every token must be a known flag, the value of a flag, or a positional argument.
 * "-h" and "--help" are always accepted (see helpRequested()).
 * \code
 * dynvo::app::Arguments args(argc, argv, {{"frames", "N", "frames to write (300)"}}, 0);
 * const int frames = args.integer("frames", 300);
 * \endcode
 */
class DYNVO_EXPORTS Arguments {
public:
  /// \throws UsageError on an unknown flag, a flag given twice, a missing value, or
  ///         a positional count other than `positional`
  Arguments(int argc,
            const char* const* argv,
            std::vector<Option> options,
            std::size_t positional = 0);

  /// True when "-h" or "--help" was given (positional count is then not checked).
  bool helpRequested() const { return help_; }

  /// True when the flag or switch was given.
  bool has(const std::string& name) const;

  /// The flag's value, or fallback when absent.
  std::string string(const std::string& name, const std::string& fallback = "") const;

  /// The flag's value as a finite number. \throws UsageError when it does not parse
  double number(const std::string& name, double fallback) const;

  /// The flag's value as exactly count comma-separated finite numbers, or fallback when
  /// absent. \throws UsageError when it does not parse or has another count
  std::vector<double> numbers(const std::string& name,
                              std::size_t count,
                              const std::vector<double>& fallback) const;

  /// The flag's value as an integer. \throws UsageError when it does not parse
  long integer(const std::string& name, long fallback) const;

  /// The flag's value as an integer within [low, high] (the fallback is not checked).
  /// \throws UsageError when it does not parse or is out of range
  long integer(const std::string& name, long fallback, long low, long high) const;

  /// Positional arguments in order.
  const std::vector<std::string>& positional() const { return positional_; }

  /// One line per option: "-name VALUE  help".
  std::string optionsHelp() const;

private:
  std::vector<Option> options_;
  std::vector<std::pair<std::string, std::string>> given_;
  std::vector<std::string> positional_;
  bool help_ = false;
};

/// errorText(e) (no PCLException location, "out of memory" for std::bad_alloc) with long
/// words shortened (see shortenLongWords()).
DYNVO_EXPORTS std::string errorMessage(const std::exception& e);

/// The text with every word (run of non-blanks) over 200 characters cut to its first 120
/// and last 40 characters around "...(N characters)...", so that a huge file name does
/// not flood the terminal.
DYNVO_EXPORTS std::string shortenLongWords(const std::string& text);

/** \brief Runs an app's body with the house exit-code policy.
 * UsageError: message and usage on stderr, exit 2. Other std::exception: message via
 * pcl::console::print_error, exit 1. Otherwise the body's return value (0 or 1).
 * With glibc, first makes the process keep freed memory for reuse (mallopt): per-frame
 * buffers are then not mapped afresh every frame.
 * \param[in] usage printed after a usage error, e.g. "dynvo_evaluate GT EST [options]"
 */
DYNVO_EXPORTS int runApp(const std::string& usage, const std::function<int()>& body);

} // namespace dynvo::app
