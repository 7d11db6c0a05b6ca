// SPDX-License-Identifier: BSD-3-Clause
// Frame, unit and label conventions shared by every dynvo module.
#pragma once

#include <cstdint>

/**
 * \file conventions.h
 * Conventions used throughout dynvo (see docs/algorithm.md §0 and docs/style.md §2.2):
 * - Units: metres, radians, seconds, pixels. Timestamps are seconds (double).
 * - Camera axes: OpenCV optical frame (x right, y down, z forward).
 * - A transform named T_a_b maps points given in frame b into frame a.
 *   The camera pose T_world_curr is camera-to-world; the paper's H_k is T_curr_prev.
 * - The PCLBase input cloud is always the current frame k; the grid is anchored in it.
 * - Indices are linear pixel indices (row * width + col) into the organized current cloud.
 * - Missing depth is a NaN point (x = y = z = NaN) at its pixel.
 */
namespace dynvo {

/// Label value meaning "no measurement" in label maps written by the pipeline.
constexpr std::uint8_t LABEL_NONE = 0;
/// Label value of the static background in label maps written by the pipeline.
constexpr std::uint8_t LABEL_STATIC = 1;

} // namespace dynvo
