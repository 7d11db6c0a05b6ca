// SPDX-License-Identifier: BSD-3-Clause
// Replacing a file whole or not at all: write "<path>.partial", then rename it into place.
#pragma once

#include <dynvo/common/export.h>

#include <string>

namespace dynvo {

/** \brief An output file written beside its destination and moved into place by commit().
 *
 * Whatever writes the data writes partialPath(); commit() renames it onto path(), so an
 * existing file at path() is replaced atomically, and only once the new one is complete.
 * Destroying an uncommitted PartialFile removes the partial file and leaves path() as
 * it was.
 * \code
 * dynvo::PartialFile file("trajectory.txt");
 * std::ofstream(file.partialPath()) << text;
 * file.commit();
 * \endcode
 */
class DYNVO_EXPORTS PartialFile {
public:
  /// \param[in] path the destination; nothing is created yet
  explicit PartialFile(std::string path);
  ~PartialFile();
  PartialFile(const PartialFile&) = delete;
  PartialFile& operator=(const PartialFile&) = delete;

  /// The destination.
  const std::string& path() const { return path_; }

  /// Where the data goes until commit(): path() + ".partial".
  std::string partialPath() const { return path_ + ".partial"; }

  /// Renames partialPath() onto path(). \throws pcl::IOException naming path() on failure
  void commit();

private:
  std::string path_;
  bool committed_ = false;
};

/// Writes bytes to path through a PartialFile. \throws pcl::IOException naming path
DYNVO_EXPORTS void replaceFile(const std::string& path, const std::string& bytes);

} // namespace dynvo
