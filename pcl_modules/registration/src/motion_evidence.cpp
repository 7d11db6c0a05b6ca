// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/registration/motion_evidence.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>

namespace dynvo {

namespace {

/// Median of chi-square with three degrees of freedom.
constexpr float CHI2_3_MEDIAN = 2.366f;

} // namespace

const ParameterTable<MotionEvidenceParameters>&
MotionEvidenceParameters::table()
{
  using P = MotionEvidenceParameters;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 3, "every field of P needs a row below");
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeField("evidence_drift", &P::evidence_drift, FieldRange::above(0),
                "kappa, chi-square subtracted per frame"),
      makeField("evidence_clip", &P::evidence_clip, FieldRange::above(0),
                "c, largest chi-square of one frame"),
      makeField("evidence_limit", &P::evidence_limit, FieldRange::atLeast(0),
                "h, evidence leaving a cell out of the static set, 0 = off"),
  });
  return table;
}

void
MotionEvidenceParameters::validate() const
{
  table().checkAll(*this, "[dynvo::MotionEvidence::Parameters::validate]");
}

void
MotionEvidence::setParameters(const Parameters& parameters)
{
  parameters.validate();
  params_ = parameters;
}

void
MotionEvidence::setSensorNoise(const SensorNoiseModel& noise, float focal)
{
  noise_ = noise;
  focal_ = focal;
}

void
MotionEvidence::reset()
{
  moving_ = FlowGrid();
  evidence_.clear();
}

void
MotionEvidence::predict(const FlowCloud& flow,
                        std::uint32_t width,
                        std::uint32_t height)
{
  FlowGrid grid;
  if (!FlowGrid::fromFlow(flow, width, height, grid)) {
    reset();
    return;
  }
  std::vector<float> carried(grid.size(), 0.0f);
  if (moving_.sameGeometry(grid) && evidence_.size() == grid.size()) {
    const float cell = static_cast<float>(grid.cell_size);
    const float half = static_cast<float>(grid.cell_size / 2);
    for (std::size_t i = 0; i < grid.size(); ++i) {
      if (!flow[i].valid_2d)
        continue;
      const long col = std::lround((flow[i].prev_u - half) / cell);
      const long row = std::lround((flow[i].prev_v - half) / cell);
      if (col >= 0 && col < static_cast<long>(grid.cols) && row >= 0 &&
          row < static_cast<long>(grid.rows))
        carried[i] = evidence_[static_cast<std::size_t>(row) * grid.cols + col];
    }
  }
  evidence_ = std::move(carried);
  moving_ = grid;
  if (params_.evidence_limit > 0.0f)
    for (std::size_t i = 0; i < grid.size(); ++i)
      moving_.labels[i] =
          evidence_[i] > params_.evidence_limit ? LABEL_STATIC + 1 : LABEL_NONE;
}

void
MotionEvidence::update(const FlowCloud& flow, const Eigen::Matrix4d& T_prev_curr)
{
  if (evidence_.size() != flow.size() || flow.empty())
    return;
  const Eigen::Matrix3f R = T_prev_curr.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f t = T_prev_curr.topRightCorner<3, 1>().cast<float>();
  std::vector<float> chi2(flow.size(), -1.0f); // < 0: no measurement
  std::vector<float> unflagged;
  for (std::size_t i = 0; i < flow.size(); ++i) {
    const PointFlow& f = flow[i];
    if (!f.valid_3d)
      continue;
    const Eigen::Vector3f b = f.getVector3fMap();
    const Eigen::Vector3f a(f.prev_x, f.prev_y, f.prev_z);
    const Eigen::Vector3f e = R * b + t - a;
    const SensorNoiseModel::TransferVariance variance =
        noise_.transferVariance(a, b, focal_);
    const float axial = e.dot(a.normalized());
    chi2[i] = axial * axial / variance.axial +
              (e.squaredNorm() - axial * axial) / variance.lateral;
    if (moving_.labels[i] == LABEL_NONE)
      unflagged.push_back(chi2[i]);
  }
  if (unflagged.empty())
    return;
  // Rescaled down to the chi-square median when this frame's median is above it (the fit or
  // the flow is worse as a whole); never up: the model is the sensor's noise floor, and a
  // quieter frame makes a residual within that floor no more a motion.
  const auto middle =
      unflagged.begin() + static_cast<std::ptrdiff_t>(unflagged.size() / 2);
  std::nth_element(unflagged.begin(), middle, unflagged.end());
  const float scale = *middle > CHI2_3_MEDIAN ? CHI2_3_MEDIAN / *middle : 1.0f;
  const float ceiling = 2.0f * params_.evidence_limit;
  std::size_t flagged = 0;
  for (std::size_t i = 0; i < flow.size(); ++i) {
    if (chi2[i] >= 0.0f)
      evidence_[i] =
          std::clamp(evidence_[i] + std::min(scale * chi2[i], params_.evidence_clip) -
                         params_.evidence_drift,
                     0.0f, ceiling);
    flagged += evidence_[i] > params_.evidence_limit ? 1 : 0;
  }
  PCL_DEBUG(
      "[dynvo::%s::update] median chi-square %.2f over %zu cells; %zu cells above "
      "the limit.\n",
      getClassName().c_str(), *middle, unflagged.size(), flagged);
}

} // namespace dynvo
