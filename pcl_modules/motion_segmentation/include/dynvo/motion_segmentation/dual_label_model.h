// SPDX-License-Identifier: BSD-3-Clause
// Per-cell dual-mode (apparent / candidate) label model with warping (docs/algorithm.md §5, §6).
#pragma once

#include <dynvo/common/export.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dynvo {

/** \brief The apparent (A) and candidate (C) label models of every grid cell.
 *
 * Each model of a cell is a probability vector P over the labels 1..n_obj (P[l - 1]) and an
 * age alpha in [0, alpha_max]; P = 0 and alpha = 0 mean "uninitialised". L is the label read
 * out for the cell (0 = unknown). The design follows the mean/age model of MCD5.8ms with the
 * measured intensity replaced by a one-hot label. Every frame: compensate() warps both
 * models from the previous grid to the current one, then update() folds in the tracked
 * labels and reads out L. Plain buffers, structure of arrays; not thread-safe.
 */
class DYNVO_EXPORTS DualLabelModel {
public:
  /// Which of the two models of a cell.
  enum class Model { apparent, candidate };

  /// Resets to cols x rows uninitialised cells with `labels` (n_obj) labels each.
  void reset(int cols, int rows, int labels);

  int cols() const { return cols_; }

  int rows() const { return rows_; }

  /// n_obj, the length of each probability vector.
  int labels() const { return labels_; }

  /// Probability of `label` (1..n_obj) in a model of a cell.
  float probability(Model model, std::size_t cell, int label) const
  {
    return probabilities(model)[cell * labels_ + label - 1];
  }

  /// Age alpha of a model of a cell (frames).
  float age(Model model, std::size_t cell) const
  {
    return model == Model::apparent ? age_a_[cell] : age_c_[cell];
  }

  /// Label read out for each cell (0 = unknown).
  const std::vector<std::uint8_t>& readOut() const { return label_; }

  /// Most likely label of a model of a cell (ties: `preferred`, then the lower id); 0 when
  /// the model is uninitialised.
  std::uint8_t argmax(Model model, std::size_t cell, std::uint8_t preferred = 0) const;

  /** \brief Sets one cell's model directly (tests, seeding).
   * \param[in] probabilities n_obj values, P[l - 1] for label l
   * \param[in] age alpha (frames)
   */
  void setModel(Model model,
                std::size_t cell,
                const std::vector<float>& probabilities,
                float age);

  /** \brief Backward area-weighted warp of both models into the current grid (§6).
   *
   * Current cell i is the cell-sized square centred on source[i] in the previous image: its
   * overlaps with the previous cells give bilinear weights; sources outside the grid are
   * dropped and the rest renormalised; a cell without any source is reset.
   * P~ = sum w P / sum over initialised sources of w; alpha~ = sum w alpha.
   * The read-out labels are carried by the nearest-cell mapping, only where tracked[i].
   * \param[in] source p_i per current cell (px, previous image), after the §6 fallbacks
   * \param[in] tracked valid_2d per current cell (nearest-cell warp of the labels)
   * \param[in] cell_size w_grid (px)
   */
  void compensate(const std::vector<Eigen::Vector2f>& source,
                  const std::vector<std::uint8_t>& tracked,
                  int cell_size);

  /** \brief Update with the tracked labels, swap, and label read-out (§5).
   * \param[in] measurement Ghat per cell (0 = no measurement, else 1..n_obj)
   * \param[in] max_age alpha_max (frames)
   */
  void update(const std::vector<std::uint8_t>& measurement, float max_age);

  /** \brief Clears every candidate model's probability of the labels not in use; a
   * candidate left without any is uninitialised (age 0).
   * \param[in] in_use nonzero at index l when label l is in use (labels at or beyond its
   * size are kept)
   */
  void forgetCandidates(const std::vector<char>& in_use);

private:
  const std::vector<float>& probabilities(Model model) const
  {
    return model == Model::apparent ? p_a_ : p_c_;
  }

  int cols_ = 0;                     ///< grid columns
  int rows_ = 0;                     ///< grid rows
  int labels_ = 0;                   ///< n_obj
  std::vector<float> p_a_, p_c_;     ///< P of A and C, cell-major, labels_ per cell
  std::vector<float> age_a_, age_c_; ///< alpha of A and C
  std::vector<std::uint8_t> label_;  ///< L
  std::vector<float> warped_p_a_, warped_p_c_;     ///< compensation output (swapped in)
  std::vector<float> warped_age_a_, warped_age_c_; ///< compensation output (swapped in)
  std::vector<std::uint8_t> warped_label_;         ///< L of the nearest source cell
};

} // namespace dynvo
