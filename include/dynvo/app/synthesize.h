// SPDX-License-Identifier: BSD-3-Clause
// dynvo_synthesize's outputs: synthetic sequences and composites written as TUM folders.
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/export.h>
#include <dynvo/synth/scene_synthesizer.h>

#include <string>

namespace dynvo::app {

/** \brief Writes a scenario in the TUM layout: rgb/, depth/ (16-bit,
 * SceneSynthesizer::DEPTH_PNG_SCALE per metre), labels/ (uint8), rgb.txt, depth.txt,
 * groundtruth.txt, objects.txt (dynvo::SequenceWriter).
 *
 * Files are named by their stamp ("%.6f.png"); labels use the colour stamp.
 * groundtruth.txt holds T_world_camera at the colour stamps; objects.txt one line per
 * frame and object: "timestamp id tx ty tz qx qy qz qw moving" (object-to-world).
 * \param[in] options the scenario (SceneSynthesizer)
 * \param[in] folder must not exist or be empty; nothing existing is overwritten
 * \param[in] threads worker threads (>= 1); the bytes written do not depend on it
 * \throws pcl::IOException when the folder is not empty or cannot be written
 * \throws std::invalid_argument when threads < 1 or the options are invalid
 */
DYNVO_EXPORTS void writeSyntheticSequence(const SynthOptions& options,
                                          const std::string& folder,
                                          int threads);

/// Where to composite a scenario's objects (dynvo_synthesize -composite).
struct CompositeOptions {
  std::string recording;       ///< TUM folder: rgb.txt, depth.txt, groundtruth.txt
  CameraIntrinsics intrinsics; ///< the recording's camera
  double depth_scale = 0.0;    ///< raw depth units per metre; 0 = the folder's default
  int frames = 0; ///< the first N associated frames with ground truth; 0 = all
};

/** \brief Composites the scenario's rigid objects into a real TUM recording
 * (dynvo::SceneCompositor) and writes the result like writeSyntheticSequence().
 *
 * Frame k of the output is the k-th associated pair of the recording that has ground
 * truth, at its stamps; the camera pose is the recording's ground truth interpolated at the
 * colour stamp (linear translation, slerp rotation, across gaps of at most 0.25 s). Pairs
 * without ground truth around their colour stamp are skipped. objects.txt holds the
 * objects in the recording's world; groundtruth.txt is the recording's. Every input is
 * read and checked before the output folder is made.
 * \param[in] folder must not exist or be empty; nothing existing is overwritten
 * \return the associated pairs skipped for want of ground truth
 * \throws std::invalid_argument when the scenario has no objects or frames < 0
 * \throws pcl::IOException when the recording cannot be read (missing or wrong-type
 *         image, no pair with ground truth) or the folder cannot be written
 */
DYNVO_EXPORTS std::size_t writeCompositeSequence(const SynthOptions& options,
                                                 const CompositeOptions& composite,
                                                 const std::string& folder);

} // namespace dynvo::app
