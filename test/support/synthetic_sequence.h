// SPDX-License-Identifier: BSD-3-Clause
// A synthetic recording in the TUM layout, written once for the app tests of a suite.
// Header-only: it needs dynvo_app (writeSyntheticSequence), which dynvo_test_support does
// not link.
#pragma once

#include <dynvo/app/synthesize.h>
#include <dynvo/synth/scene_synthesizer.h>

#include "support/temp_dir.h"

#include <string>

namespace dynvo::test {

/// A scenario written as a TUM folder (with groundtruth.txt) in its own temporary folder,
/// removed with the object.
class SyntheticSequence {
public:
  /// \param[in] scenario one of SceneSynthesizer::scenarios()
  /// \param[in] frames frames to write
  /// \param[in] width image columns (px)
  /// \param[in] height image rows (px)
  SyntheticSequence(const std::string& scenario, int frames, int width, int height)
  {
    SynthOptions options;
    options.scenario = scenario;
    options.frames = frames;
    options.width = width;
    options.height = height;
    app::writeSyntheticSequence(options, path(), 2);
  }

  /// The TUM folder.
  std::string path() const { return dir_.file("seq"); }

private:
  TempDir dir_;
};

} // namespace dynvo::test
