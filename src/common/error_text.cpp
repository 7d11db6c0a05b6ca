// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/error_text.h>

#include <pcl/exceptions.h>

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
  // PCLException::createDetailedMessage: "[function ][in file [@ line ]]: description".
  const bool located = pcl_error->getFunctionName() || pcl_error->getFileName();
  const std::size_t colon = what.find(located ? " : " : ": ");
  if (colon == std::string::npos || (!located && colon != 0))
    return what;
  return what.substr(colon + (located ? 3 : 2));
}

} // namespace dynvo
