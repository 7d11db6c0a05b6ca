// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/timestamps.h>
#include <dynvo/vis/label_renderer.h>
#include <dynvo/vis/trajectory_plot.h>

#include "window_png_writer.h"
#include "x_connection.h"

#include <pcl/console/print.h>

#include <vtkAxis.h>
#include <vtkChartMatrix.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPlot.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkVector.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace dynvo {

namespace {

const char* const PREFIX = "[dynvo::writeTrajectoryPlot]";

/// Adds one line plot of (xs, ys) to a chart; the table lives as long as the chart.
void
addCurve(vtkChartXY* chart,
         const std::vector<double>& xs,
         const std::vector<double>& ys,
         const char* x_name,
         const char* y_name,
         const char* label,
         const std::array<std::uint8_t, 3>& color)
{
  vtkNew<vtkTable> table;
  vtkNew<vtkDoubleArray> x_column;
  vtkNew<vtkDoubleArray> y_column;
  x_column->SetName(x_name);
  y_column->SetName(y_name);
  table->AddColumn(x_column);
  table->AddColumn(y_column);
  table->SetNumberOfRows(static_cast<vtkIdType>(xs.size()));
  for (std::size_t i = 0; i < xs.size(); ++i) {
    table->SetValue(static_cast<vtkIdType>(i), 0, xs[i]);
    table->SetValue(static_cast<vtkIdType>(i), 1, ys[i]);
  }
  vtkPlot* plot = chart->AddPlot(vtkChart::LINE);
  plot->SetInputData(table, 0, 1);
  plot->SetColor(color[0], color[1], color[2], 255);
  plot->SetWidth(2.0);
  plot->SetLabel(label);
}

/// Horizontal and vertical plot coordinates of every pose in the chosen plane.
void
planeCoordinates(const Trajectory& trajectory,
                 PlotPlane plane,
                 std::vector<double>& xs,
                 std::vector<double>& ys)
{
  const int vertical = plane == PlotPlane::xy ? 1 : 2;
  xs.clear();
  ys.clear();
  for (const StampedPose& pose : trajectory) {
    xs.push_back(pose.T_world_camera.translation().x());
    ys.push_back(pose.T_world_camera.translation()(vertical));
  }
}

/// Smallest axis span drawn (metres or seconds): a flat curve still gets a readable axis.
constexpr double MIN_SPAN = 0.01;

/// Fixes an axis to the data range [low, high] widened by 5 % of its span on each side, so
/// that a curve on the data bounds lies inside the plot area rather than on its frame.
void
setPaddedRange(vtkAxis* axis, const char* title, double low, double high)
{
  const double centre = 0.5 * (low + high);
  const double half = 0.5 * std::max(high - low, MIN_SPAN) * 1.1;
  axis->SetTitle(title);
  axis->SetBehavior(vtkAxis::FIXED);
  axis->SetRange(centre - half, centre + half);
}

/// Padded axes covering every curve of a chart.
void
fitAxes(vtkChartXY* chart,
        const std::vector<const std::vector<double>*>& xs,
        const std::vector<const std::vector<double>*>& ys,
        const char* x_title,
        const char* y_title)
{
  const auto range = [](const std::vector<const std::vector<double>*>& columns) {
    double low = std::numeric_limits<double>::infinity();
    double high = -low;
    for (const auto* column : columns)
      for (const double value : *column) {
        low = std::min(low, value);
        high = std::max(high, value);
      }
    return std::make_pair(low, high);
  };
  const auto [x_low, x_high] = range(xs);
  const auto [y_low, y_high] = range(ys);
  setPaddedRange(chart->GetAxis(vtkAxis::BOTTOM), x_title, x_low, x_high);
  setPaddedRange(chart->GetAxis(vtkAxis::LEFT), y_title, y_low, y_high);
}

} // namespace

void
TrajectoryPlotOptions::validate() const
{
  if (width < 200 || height < 150)
    throw std::invalid_argument(
        "[dynvo::TrajectoryPlotOptions::validate] the plot must be at least 200x150 px "
        "(room for axes and labels), got " +
        std::to_string(width) + "x" + std::to_string(height));
  if (!(max_time_difference > 0.0 && std::isfinite(max_time_difference)))
    throw std::invalid_argument("[dynvo::TrajectoryPlotOptions::validate] "
                                "max_time_difference must be > 0 s, got " +
                                std::to_string(max_time_difference));
}

bool
writeTrajectoryPlot(const Trajectory& estimate,
                    const Trajectory& groundtruth,
                    const std::string& out_png,
                    const TrajectoryPlotOptions& options,
                    const std::vector<std::pair<int, Trajectory>>& objects)
{
  options.validate();
  if (estimate.empty()) {
    PCL_ERROR("%s the estimated trajectory is empty\n", PREFIX);
    return false;
  }
  const detail::XConnection x; // declared before the window, so it is closed after it
  if (!x.get()) {
    PCL_WARN("%s no display (%s): no plot is written; run under `xvfb-run -a` on a "
             "headless machine\n",
             PREFIX, x.reason().c_str());
    return false;
  }

  std::vector<double> error_time;
  std::vector<double> error;
  if (!groundtruth.empty()) {
    std::vector<double> estimate_stamps;
    std::vector<double> groundtruth_stamps;
    for (const StampedPose& p : estimate)
      estimate_stamps.push_back(p.timestamp);
    for (const StampedPose& p : groundtruth)
      groundtruth_stamps.push_back(p.timestamp);
    for (const auto& [e, g] : associateTimestamps(estimate_stamps, groundtruth_stamps,
                                                  options.max_time_difference)) {
      error_time.push_back(estimate[e].timestamp - estimate.front().timestamp);
      error.push_back((estimate[e].T_world_camera.translation() -
                       groundtruth[g].T_world_camera.translation())
                          .norm());
    }
    if (error.empty())
      PCL_WARN("%s no estimated stamp is within %g s of a ground-truth stamp: no error "
               "curve\n",
               PREFIX, options.max_time_difference);
  }

  vtkNew<vtkRenderWindow> window;
  window->SetDisplayId(x.get());
  window->SetOffScreenRendering(1);
  window->SetSize(static_cast<int>(options.width), static_cast<int>(options.height));
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1.0, 1.0, 1.0);
  window->AddRenderer(renderer);
  vtkNew<vtkContextActor> context;
  renderer->AddActor(context);
  vtkNew<vtkChartMatrix> charts;
  context->GetScene()->AddItem(charts);
  charts->SetSize(vtkVector2i(error.empty() ? 1 : 2, 1));
  charts->SetGutterX(60.0f); // room for the right chart's axis labels

  const bool xy = options.plane == PlotPlane::xy;
  const char* vertical_name = xy ? "y (m)" : "z (m)";
  auto* path = vtkChartXY::SafeDownCast(charts->GetChart(vtkVector2i(0, 0)));
  path->SetTitle(xy ? "top-down path (x-y)" : "top-down path (x-z)");
  path->SetShowLegend(true);
  std::vector<double> gt_xs;
  std::vector<double> gt_ys;
  planeCoordinates(groundtruth, options.plane, gt_xs, gt_ys);
  std::vector<double> est_xs;
  std::vector<double> est_ys;
  planeCoordinates(estimate, options.plane, est_xs, est_ys);
  if (!groundtruth.empty())
    addCurve(path, gt_xs, gt_ys, "x (m)", vertical_name, "ground truth",
             options.groundtruth_color);
  addCurve(path, est_xs, est_ys, "x (m)", vertical_name, "estimate",
           options.estimate_color);
  std::vector<const std::vector<double>*> all_xs{&gt_xs, &est_xs};
  std::vector<const std::vector<double>*> all_ys{&gt_ys, &est_ys};
  std::vector<std::vector<double>> object_xs(objects.size()), object_ys(objects.size());
  std::size_t o = 0;
  for (const auto& [id, object] : objects) {
    planeCoordinates(object, options.plane, object_xs[o], object_ys[o]);
    const std::string label = "object " + std::to_string(id);
    addCurve(path, object_xs[o], object_ys[o], "x (m)", vertical_name, label.c_str(),
             LabelRenderer::labelColor(static_cast<std::uint8_t>(id)));
    all_xs.push_back(&object_xs[o]);
    all_ys.push_back(&object_ys[o]);
    ++o;
  }
  fitAxes(path, all_xs, all_ys, "x (m)", vertical_name);

  if (!error.empty()) {
    auto* over_time = vtkChartXY::SafeDownCast(charts->GetChart(vtkVector2i(1, 0)));
    over_time->SetTitle("translational error");
    addCurve(over_time, error_time, error, "time (s)", "error (m)", "|t_est - t_gt|",
             options.estimate_color);
    // Errors are read against zero, so the error axis always includes it.
    const std::vector<double> zero{0.0};
    fitAxes(over_time, {&error_time}, {&error, &zero}, "time (s)", "error (m)");
  }

  window->Render();
  detail::WindowPngWriter png(window);
  return png.write(out_png, PREFIX);
}

} // namespace dynvo
