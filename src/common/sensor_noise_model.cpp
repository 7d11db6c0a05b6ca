// SPDX-License-Identifier: BSD-3-Clause
#include <dynvo/common/sensor_noise_model.h>

namespace dynvo {

const ParameterTable<SensorNoiseModel>&
SensorNoiseModel::table()
{
  using P = SensorNoiseModel;
  using R = FieldRange;
  static_assert(AGGREGATE_FIELD_COUNT<P> == 5, "every field of P needs a row below");
  static const ParameterTable<P> table(std::vector<ParameterTable<P>::Field>{
      makeField("axial_base", &P::axial_base, R::above(0), "sigma_0, metres"),
      makeField("axial_quadratic", &P::axial_quadratic, R::atLeast(0), "k, m^-1"),
      makeField("axial_offset", &P::axial_offset, R::atLeast(0), "z_0, metres"),
      makeField("axial_scale", &P::axial_scale, R::above(0), "factor on sigma_z"),
      makeField("lateral_pixels", &P::lateral_pixels, R::above(0), "sigma_px, px"),
  });
  return table;
}

void
SensorNoiseModel::validate() const
{
  table().checkAll(*this, "[dynvo::SensorNoiseModel::validate]");
}

Eigen::Matrix3f
SensorNoiseModel::transferInformation(const Eigen::Vector3f& a,
                                      const Eigen::Vector3f& b,
                                      float focal,
                                      float axial_gain,
                                      float lateral_gain) const
{
  const TransferVariance variance = transferVariance(a, b, focal);
  const float axial = axial_gain * axial_gain * variance.axial;
  const float lateral = lateral_gain * lateral_gain * variance.lateral;
  const Eigen::Vector3f ray = b.normalized();
  const Eigen::Matrix3f along = ray * ray.transpose();
  return along / axial + (Eigen::Matrix3f::Identity() - along) / lateral;
}

} // namespace dynvo
