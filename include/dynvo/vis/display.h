// SPDX-License-Identifier: BSD-3-Clause
// Whether off-screen rendering can run here (Debian's VTK 9.1 needs an X server with GLX).
#pragma once

#include <dynvo/common/export.h>

#include <string>

namespace dynvo {

/** \brief True when an X display with the GLX extension can be opened, so VTK can render.
 *
 * Checked with Xlib, before any VTK call: Debian's VTK 9.1 is built for GLX only and
 * aborts the process when it renders without an X server (docs/platform.md). On a headless
 * machine run the program under `xvfb-run -a`.
 * \param[out] reason when not null and the answer is false: why, in one line
 */
DYNVO_EXPORTS bool displayAvailable(std::string* reason = nullptr);

} // namespace dynvo
