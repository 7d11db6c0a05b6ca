// SPDX-License-Identifier: BSD-3-Clause
// Segmentation scores of a folder of predicted label PNGs against a sequence folder:
// the file reading around the plain-data scores of dynvo/eval/label_metrics.h.
#pragma once

#include <dynvo/common/export.h>
#include <dynvo/eval/label_metrics.h>

#include <string>

namespace dynvo::app {

/** \brief Scores the label PNGs of a dynvo_odometry -labels_dir folder against a sequence.
 *
 * The sequence is a TUM folder (rgb.txt, depth.txt, as read by TumFolderSource): its frames
 * are the colour frames associated with a depth image; a pixel is valid where that depth is
 * non-zero. The truth labels of a frame are labels/<colour stamp %.6f>.png; without a
 * labels/ folder every pixel is truly static (a static real recording). The predictions are
 * the .png files of predicted_dir, named <stamp>.png (digits and one '.', as formatStamp()
 * writes; other files are ignored). Each sequence frame is paired with the prediction of
 * nearest stamp within max_difference, one to one (as associateTimestamps()); unpaired
 * sequence frames and unpaired predictions are not scored (scores.frames counts the pairs;
 * compare it with sequence_frames).
 * \throws pcl::IOException naming the file: a missing folder, a .png not named by a stamp,
 *         no prediction within max_difference of any frame, a missing truth label file, an
 *         unreadable or not 8-bit single-channel PNG, a prediction whose size differs from
 *         its truth labels (or, without labels/, its depth image)
 */
DYNVO_EXPORTS SegmentationEvaluation
evaluateSegmentation(const std::string& predicted_dir,
                     const std::string& sequence_dir,
                     const SegmentationEvaluationOptions& options = {});

} // namespace dynvo::app
