// SPDX-License-Identifier: BSD-3-Clause
// Display detection with Xlib; kept in its own file because Xlib defines macros (None, Bool).
#include <dynvo/vis/display.h>

#include "x_connection.h"

#include <X11/Xlib.h>

#include <chrono>
#include <cstdlib>
#include <thread>

namespace dynvo {

namespace detail {

XConnection::XConnection()
{
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name) {
    reason_ = "DISPLAY is not set";
    return;
  }
  // Xvfb refuses connections for a moment while it resets after its last client left
  // (e.g. the previous test process); 10 tries 20 ms apart outlast that reset.
  Display* display = nullptr;
  for (int attempt = 0; attempt < 10 && !display; ++attempt) {
    if (attempt > 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    display = XOpenDisplay(name);
  }
  if (!display) {
    reason_ = std::string("cannot open X display '") + name + "'";
    return;
  }
  int opcode = 0;
  int first_event = 0;
  int first_error = 0;
  if (!XQueryExtension(display, "GLX", &opcode, &first_event, &first_error)) {
    XCloseDisplay(display);
    reason_ = std::string("X display '") + name + "' has no GLX extension";
    return;
  }
  display_ = display;
}

XConnection::~XConnection()
{
  if (display_)
    XCloseDisplay(static_cast<Display*>(display_));
}

} // namespace detail

bool
displayAvailable(std::string* reason)
{
  const detail::XConnection connection;
  if (!connection.get() && reason)
    *reason = connection.reason();
  return connection.get() != nullptr;
}

} // namespace dynvo
