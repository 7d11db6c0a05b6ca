// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/error_text.h>

#include <pcl/exceptions.h>

#include <cctype>
#include <new>

namespace dynvo {

std::string
errorText(const std::exception& e)
{
  const std::string what = e.what();
  if (dynamic_cast<const std::bad_alloc*>(&e))
    return "out of memory (" + what + ")";
  const auto* pcl_error = dynamic_cast<const pcl::PCLException*>(&e);
  if (!pcl_error)
    return what;
  // PCLException::createDetailedMessage: "[function ][in file [@ line ]]: description";
  // PCL's OpenNI2 code nests such messages, so the last " : " ends the last location.
  std::string text = what;
  if (pcl_error->getFunctionName() || pcl_error->getFileName()) {
    const std::size_t colon = what.rfind(" : ");
    if (colon != std::string::npos)
      text = what.substr(colon + 3);
  }
  else if (what.rfind(": ", 0) == 0) {
    text = what.substr(2);
  }
  // One line: PCL's multi-line descriptions ("...\n\tDeviceOpen: ...") joined by "; ".
  std::string line;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\n') {
      line += text[i] == '\t' ? ' ' : text[i];
      continue;
    }
    while (i + 1 < text.size() && std::isspace(static_cast<unsigned char>(text[i + 1])))
      ++i;
    if (i + 1 < text.size())
      line += "; ";
  }
  return line;
}

} // namespace dynvo
