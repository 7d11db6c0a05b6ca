// SPDX-License-Identifier: BSD-3-Clause
// YAML configuration of the odometry pipeline (ALGORITHM.md §9: every parameter configurable).
#pragma once

#include <dynvo/app/odometry_pipeline.h>

#include <string>

namespace dynvo::app {

/** \brief Overrides options with the values of a YAML file.
 *
 * The file has up to four maps, `scene_flow`, `segmentation`, `registration` and `pipeline`,
 * whose keys are the field names of the Parameters structs (nested `depth` map inside
 * `scene_flow`); see writePipelineConfig() for the complete list with the defaults. Keys left
 * out keep their value. The result is validated.
 * \throws pcl::IOException naming the file and the key when the file cannot be read, a key is
 *         unknown, a value has the wrong type, or the options are invalid
 */
DYNVO_EXPORTS void loadPipelineConfig(const std::string& path,
                                      PipelineOptions& options);

/// Writes options as a YAML file that loadPipelineConfig() reads back unchanged.
/// \throws pcl::IOException when the file cannot be written
DYNVO_EXPORTS void writePipelineConfig(const std::string& path,
                                       const PipelineOptions& options);

} // namespace dynvo::app
