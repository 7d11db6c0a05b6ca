// SPDX-License-Identifier: BSD-3-Clause
// The ambiguity test of a cell's track (docs/algorithm.md §4.1) on painted frames: repeated
// texture is ambiguous, unique texture is not, a flat patch cannot confirm its track.
#include <dynvo/motion_segmentation/patch_match.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace {

constexpr int W = 96, H = 64;
constexpr int PERIOD =
    12; ///< px: the repeated texture's period along x (a row of keys)
constexpr int SHIFT =
    2; ///< px: the true image motion from frame k-1 to frame k, along x

/// Grey level g as a packed rgba word (b, g, r all g).
std::uint32_t
packed(int g)
{
  const auto v = static_cast<std::uint32_t>(std::clamp(g, 0, 255));
  return v << 16 | v << 8 | v;
}

/// Frames k-1 and k of a scene that moves SHIFT px to the left: frame k at x is frame k-1 at
/// x + SHIFT. `grey(x, y)` paints frame k-1.
template <typename Grey> struct Frames {
  std::vector<std::uint32_t> previous, current;

  explicit Frames(Grey grey)
      : previous(std::size_t{W} * H)
      , current(std::size_t{W} * H)
  {
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        previous[std::size_t(y) * W + x] = packed(grey(x, y));
        current[std::size_t(y) * W + x] = packed(grey(x + SHIFT, y));
      }
  }

  dynvo::FramePairColours colours() const
  {
    return {previous.data(), current.data(), 1, W, H};
  }
};

/// Repeated along x with PERIOD, unique along y: a row of keys.
int
keys(int x, int y)
{
  return 128 + static_cast<int>(60.0 * std::sin(2.0 * M_PI * x / PERIOD)) +
         (y * 37 % 29);
}

const Eigen::Vector2f CENTRE(40.0f, 32.0f);
const Eigen::Vector2f TRUTH = CENTRE + Eigen::Vector2f(SHIFT, 0.0f); ///< in frame k-1
const Eigen::Vector2f ALIAS = TRUTH + Eigen::Vector2f(PERIOD, 0.0f); ///< one key over

} // namespace

TEST(PatchMatch, RepeatedTextureLeavesTheTrackAmbiguous)
{
  const Frames frames(keys);
  // The track settled one key over: the true position matches as well, found within the
  // radius even when the other motion puts it 2 px off (the search's purpose).
  EXPECT_TRUE(dynvo::trackIsAmbiguous(frames.colours(), CENTRE, ALIAS, TRUTH, 3));
  EXPECT_TRUE(dynvo::trackIsAmbiguous(frames.colours(), CENTRE, ALIAS,
                                      TRUTH + Eigen::Vector2f(2.0f, -2.0f), 3));
  // Beyond the radius the other position lies half a key off: no match.
  EXPECT_FALSE(dynvo::trackIsAmbiguous(frames.colours(), CENTRE, ALIAS,
                                       TRUTH + Eigen::Vector2f(PERIOD / 2, 0.0f), 3));
}

TEST(PatchMatch, UniqueTextureIsNotAmbiguous)
{
  std::mt19937 random(7);
  std::uniform_int_distribution<int> level(0, 255);
  std::vector<int> noise(std::size_t{W + SHIFT} * H);
  for (int& v : noise)
    v = level(random);
  const Frames frames([&](int x, int y) {
    return noise[std::size_t(y) * (W + SHIFT) + std::min(x, W + SHIFT - 1)];
  });
  // The true track against a position one key over: nothing there matches.
  EXPECT_FALSE(dynvo::trackIsAmbiguous(frames.colours(), CENTRE, TRUTH, ALIAS, 3));
  // Another motion that puts the cell where it is: as good as its own track.
  EXPECT_TRUE(dynvo::trackIsAmbiguous(frames.colours(), CENTRE, ALIAS, TRUTH, 3));
}

TEST(PatchMatch, AFlatPatchCannotConfirmItsTrack)
{
  // A flat patch with a little texture (variance 2.25 grey levels^2, the black screens of
  // tum_fr1_xyz_200 read 1-3) matches anywhere: the other motion's position matches it as
  // well as its own track, so the image does not say its own motion is the right one.
  const Frames flat([](int x, int y) {
    return 100 + ((x + y) % 2) * 3;
  });
  EXPECT_TRUE(dynvo::trackIsAmbiguous(flat.colours(), CENTRE, ALIAS, TRUTH, 3));
}

TEST(PatchMatch, MissingPatchesTellNothing)
{
  const Frames frames(keys);
  // A patch or a search square leaving the image, or no colours.
  EXPECT_FALSE(dynvo::trackIsAmbiguous(frames.colours(), Eigen::Vector2f(2.0f, 32.0f),
                                       ALIAS, TRUTH, 3));
  EXPECT_FALSE(dynvo::trackIsAmbiguous(frames.colours(), CENTRE, ALIAS,
                                       Eigen::Vector2f(W - 3.0f, 32.0f), 3));
  EXPECT_FALSE(
      dynvo::trackIsAmbiguous(dynvo::FramePairColours{}, CENTRE, ALIAS, TRUTH, 3));
}
