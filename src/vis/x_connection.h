// SPDX-License-Identifier: BSD-3-Clause
// Internal: an X connection owned by dynvo and lent to VTK render windows.
#pragma once

#include <string>

namespace dynvo::detail {

/** \brief One open X display connection with GLX, closed on destruction.
 *
 * Render windows get it through vtkRenderWindow::SetDisplayId(), so VTK never opens a
 * connection of its own (a failed one aborts the process in VTK 9.1). Holding it open also
 * keeps Xvfb from resetting, which it does whenever its last client leaves and during which
 * it refuses connections. Destroy the windows that use it first.
 */
class XConnection {
public:
  /// Opens $DISPLAY; when that fails, get() is null and reason() says why.
  XConnection();
  ~XConnection();
  XConnection(const XConnection&) = delete;
  XConnection& operator=(const XConnection&) = delete;

  /// The Display*, or null when none could be opened.
  void* get() const { return display_; }

  const std::string& reason() const { return reason_; }

private:
  void* display_ = nullptr; ///< Display*, kept opaque so Xlib's macros stay in one file
  std::string reason_;      ///< why opening failed
};

} // namespace dynvo::detail
