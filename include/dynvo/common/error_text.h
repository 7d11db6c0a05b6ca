// SPDX-License-Identifier: BSD-3-Clause
// The part of an exception's message meant for users.
#pragma once

#include <dynvo/common/export.h>

#include <exception>
#include <string>

namespace dynvo {

/** \brief what() without the "<function> in <file> @ <line> : " that pcl::PCLException puts
 * in front of its description (nested ones included), on one line, and
 * "out of memory (std::bad_alloc)" for std::bad_alloc. dynvo's own messages name the file
 * (of the user's data) they are about.
 */
DYNVO_EXPORTS std::string errorText(const std::exception& e);

} // namespace dynvo
