// SPDX-License-Identifier: BSD-3-Clause
// Internal: grabs a rendered off-screen window into a PNG, reusing the VTK filters.
#pragma once

#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkWindowToImageFilter.h>

#include <string>

class vtkRenderWindow;

namespace dynvo::detail {

/// Copies the back buffer of an already rendered window into a PNG file.
class WindowPngWriter {
public:
  /// Reads from `window` from now on (the window must outlive this object's use).
  explicit WindowPngWriter(vtkRenderWindow* window);

  /** \brief Writes what the last Render() of the window drew.
   * \param[in] path destination PNG
   * \param[in] caller "[dynvo::Class::method]" prefix for the error message
   * \return false (with a PCL_ERROR) when the file cannot be written
   */
  bool write(const std::string& path, const char* caller);

private:
  vtkNew<vtkWindowToImageFilter> grab_; ///< window pixels, RGB, no re-render
  vtkNew<vtkPNGWriter> png_;            ///< encoder
};

} // namespace dynvo::detail
