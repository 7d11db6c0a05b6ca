// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/io/partial_file.h>

#include <pcl/exceptions.h>

#include <filesystem>
#include <fstream>

namespace dynvo {

PartialFile::PartialFile(std::string path)
    : path_(std::move(path))
{
}

PartialFile::~PartialFile()
{
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove(partialPath(), ignored);
  }
}

void
PartialFile::commit()
{
  std::error_code error;
  std::filesystem::rename(partialPath(), path_, error);
  if (error)
    throw pcl::IOException(path_ + ": cannot move the written file into place (" +
                           error.message() + ")");
  committed_ = true;
}

void
replaceFile(const std::string& path, const std::string& bytes)
{
  PartialFile file(path);
  {
    std::ofstream out(file.partialPath(), std::ios::binary | std::ios::trunc);
    if (!out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())) ||
        !out.flush())
      throw pcl::IOException(path + ": cannot write file");
  }
  file.commit();
}

} // namespace dynvo
