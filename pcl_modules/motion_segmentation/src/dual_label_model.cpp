// SPDX-License-Identifier: BSD-3-Clause
// Dual-mode per-cell label model: compensation, update, swap, read-out (docs/algorithm.md §5, §6).
#include <dynvo/motion_segmentation/dual_label_model.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace dynvo {

namespace {

/// Running-average update of one model with a one-hot measurement of `label`.
void
updateModel(float* p, float& age, int labels, int label, float max_age)
{
  const float scale = age / (age + 1.0f);
  for (int l = 0; l < labels; ++l)
    p[l] *= scale;
  p[label - 1] += 1.0f / (age + 1.0f);
  age = std::min(age + 1.0f, max_age);
}

/// argmax over labels (1-based); ties go to `preferred`, then to the lower id.
std::uint8_t
argmaxLabel(const float* p, int labels, std::uint8_t preferred)
{
  int best = 0;
  float best_value = 0.0f;
  for (int l = 1; l <= labels; ++l)
    if (p[l - 1] > best_value) {
      best = l;
      best_value = p[l - 1];
    }
  if (best != 0 && preferred >= 1 && preferred <= labels &&
      p[preferred - 1] == best_value)
    best = preferred;
  return static_cast<std::uint8_t>(best);
}

} // namespace

void
DualLabelModel::reset(int cols, int rows, int labels)
{
  cols_ = cols;
  rows_ = rows;
  labels_ = labels;
  const std::size_t n = static_cast<std::size_t>(cols) * rows;
  p_a_.assign(n * labels, 0.0f);
  p_c_.assign(n * labels, 0.0f);
  age_a_.assign(n, 0.0f);
  age_c_.assign(n, 0.0f);
  label_.assign(n, 0);
  warped_label_.assign(n, 0);
}

std::uint8_t
DualLabelModel::argmax(Model model, std::size_t cell, std::uint8_t preferred) const
{
  return argmaxLabel(&probabilities(model)[cell * labels_], labels_, preferred);
}

void
DualLabelModel::setModel(Model model,
                         std::size_t cell,
                         const std::vector<float>& probabilities,
                         float age)
{
  if (static_cast<int>(probabilities.size()) != labels_)
    throw std::invalid_argument(
        "[dynvo::DualLabelModel::setModel] need one probability per label");
  std::vector<float>& p = model == Model::apparent ? p_a_ : p_c_;
  std::copy(probabilities.begin(), probabilities.end(), p.begin() + cell * labels_);
  (model == Model::apparent ? age_a_ : age_c_)[cell] = age;
}

void
DualLabelModel::compensate(const std::vector<Eigen::Vector2f>& source,
                           const std::vector<std::uint8_t>& tracked,
                           int cell_size)
{
  const std::size_t n = label_.size();
  warped_p_a_.assign(n * labels_, 0.0f);
  warped_p_c_.assign(n * labels_, 0.0f);
  warped_age_a_.assign(n, 0.0f);
  warped_age_c_.assign(n, 0.0f);
  warped_label_.assign(n, 0);
  const float half = static_cast<float>(cell_size / 2);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2f& p = source[i];
    if (!p.allFinite())
      continue; // no source: the cell starts uninitialised
    // Grid coordinates of the source square's centre: cell (a, b) is centred on (a, b).
    const float u = (p.x() - half) / static_cast<float>(cell_size);
    const float v = (p.y() - half) / static_cast<float>(cell_size);
    if (tracked[i]) {
      const int a = static_cast<int>(std::lround(u));
      const int b = static_cast<int>(std::lround(v));
      if (a >= 0 && a < cols_ && b >= 0 && b < rows_)
        warped_label_[i] = label_[static_cast<std::size_t>(b) * cols_ + a];
    }
    const float a0f = std::floor(u), b0f = std::floor(v);
    const float fu = u - a0f, fv = v - b0f;
    const int a0 = static_cast<int>(a0f), b0 = static_cast<int>(b0f);
    const int da[4] = {0, 1, 0, 1};
    const int db[4] = {0, 0, 1, 1};
    const float w[4] = {(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv};
    float total = 0.0f, init_a = 0.0f, init_c = 0.0f;
    float* pa = &warped_p_a_[i * labels_];
    float* pc = &warped_p_c_[i * labels_];
    for (int s = 0; s < 4; ++s) {
      const int a = a0 + da[s], b = b0 + db[s];
      if (a < 0 || a >= cols_ || b < 0 || b >= rows_ || w[s] <= 0.0f)
        continue;
      const std::size_t j = static_cast<std::size_t>(b) * cols_ + a;
      total += w[s];
      warped_age_a_[i] += w[s] * age_a_[j];
      warped_age_c_[i] += w[s] * age_c_[j];
      if (age_a_[j] > 0.0f) {
        init_a += w[s];
        for (int l = 0; l < labels_; ++l)
          pa[l] += w[s] * p_a_[j * labels_ + l];
      }
      if (age_c_[j] > 0.0f) {
        init_c += w[s];
        for (int l = 0; l < labels_; ++l)
          pc[l] += w[s] * p_c_[j * labels_ + l];
      }
    }
    if (total <= 0.0f) {
      std::fill(pa, pa + labels_, 0.0f);
      std::fill(pc, pc + labels_, 0.0f);
      warped_age_a_[i] = warped_age_c_[i] = 0.0f;
      continue;
    }
    warped_age_a_[i] /= total;
    warped_age_c_[i] /= total;
    for (int l = 0; l < labels_; ++l) {
      pa[l] = init_a > 0.0f ? pa[l] / init_a : 0.0f;
      pc[l] = init_c > 0.0f ? pc[l] / init_c : 0.0f;
    }
  }
  p_a_.swap(warped_p_a_);
  p_c_.swap(warped_p_c_);
  age_a_.swap(warped_age_a_);
  age_c_.swap(warped_age_c_);
}

void
DualLabelModel::update(const std::vector<std::uint8_t>& measurement, float max_age)
{
  const std::size_t n = label_.size();
  for (std::size_t i = 0; i < n; ++i) {
    float* pa = &p_a_[i * labels_];
    float* pc = &p_c_[i * labels_];
    const std::uint8_t g = measurement[i];
    bool apparent_changed = false;
    if (g != 0) {
      if (age_a_[i] <= 0.0f || g == argmaxLabel(pa, labels_, g)) {
        updateModel(pa, age_a_[i], labels_, g, max_age);
        apparent_changed = true;
      }
      else
        updateModel(pc, age_c_[i], labels_, g, max_age);
    }
    if (age_c_[i] > 0.0f && (age_c_[i] >= max_age || age_c_[i] > age_a_[i])) {
      std::swap_ranges(pa, pa + labels_, pc);
      std::swap(age_a_[i], age_c_[i]);
      std::fill(pc, pc + labels_, 0.0f); // [D] candidate reset after a swap, as in MCD
      age_c_[i] = 0.0f;
      apparent_changed = true;
    }
    label_[i] = apparent_changed && age_a_[i] >= 1.0f ? argmaxLabel(pa, labels_, g)
                                                      : warped_label_[i];
  }
}

void
DualLabelModel::forgetCandidates(const std::vector<char>& in_use)
{
  const int known = std::min(labels_, static_cast<int>(in_use.size()) - 1);
  for (std::size_t i = 0; i < age_c_.size(); ++i) {
    float* pc = &p_c_[i * labels_];
    for (int l = 1; l <= known; ++l)
      if (!in_use[l])
        pc[l - 1] = 0.0f;
    if (std::all_of(pc, pc + labels_, [](float p) {
          return p <= 0.0f;
        }))
      age_c_[i] = 0.0f;
  }
}

} // namespace dynvo
