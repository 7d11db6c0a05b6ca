// SPDX-License-Identifier: BSD-3-Clause
// Grey patches of two consecutive frames compared in place (docs/algorithm.md §4.1).
#pragma once

#include <dynvo/common/export.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>

namespace dynvo {

/// The colours of frames k-1 and k, read in place from two organized clouds of one size
/// (PCL's packed rgba words: b, g, r, a bytes); pixel i's colour is at rgba[i * stride].
struct FramePairColours {
  const std::uint32_t* previous = nullptr; ///< frame k-1, pixel 0; null: no colours
  const std::uint32_t* current = nullptr;  ///< frame k, pixel 0; null: no colours
  std::size_t stride = 0;                  ///< 4-byte words from one pixel to the next
  int width = 0;                           ///< columns of both frames (px)
  int height = 0;                          ///< rows of both frames (px)

  bool empty() const { return !previous || !current || width <= 0 || height <= 0; }
};

/** \brief [D] Whether the image leaves a cell's track ambiguous (docs/algorithm.md §4.1).
 *
 * The 9 x 9 grey patch at `centre` in frame k is compared (zero-mean sum of squared
 * differences) with the patches of frame k-1 at integer positions: within 1 px of `track`
 * (where the cell's own flow puts it) and within `radius` px of `other` (where another
 * motion puts it). The track is ambiguous when the other position matches at most
 * AMBIGUITY_FACTOR times as badly as the cell's own. A flat patch matches anywhere, so it is
 * ambiguous too: the image cannot confirm its track over the other motion.
 * \return false as well when a patch leaves the image
 */
DYNVO_EXPORTS bool trackIsAmbiguous(const FramePairColours& colours,
                                    const Eigen::Vector2f& centre,
                                    const Eigen::Vector2f& track,
                                    const Eigen::Vector2f& other,
                                    int radius);

/// The other position matches within this factor of the track's own (ZSSD).
constexpr float AMBIGUITY_FACTOR = 1.5f;

} // namespace dynvo
