// SPDX-License-Identifier: BSD-3-Clause
// YAML configuration of the odometry pipeline (docs/algorithm.md §9: every parameter
// configurable).
#pragma once

#include <dynvo/app/odometry_pipeline.h>

#include <string>

namespace dynvo::app {

/** \brief Every key of the configuration file, in file order: the fields of
 * GridSceneFlowParameters::table() as "scene_flow.<field>" (its depth fields as
 * "scene_flow.depth.<field>"), RigidMotionSegmentationParameters::table() as
 * "segmentation.<field>", StaticSceneRegistrationParameters::table() as
 * "registration.<field>" and PipelineOptions::table() as "pipeline.<field>".
 * The camera intrinsics are not part of the file (apps take -camera).
 */
DYNVO_EXPORTS const ParameterTable<PipelineOptions>& pipelineConfigTable();

/// One line per key of pipelineConfigTable(): "  key value   (symbol, unit; range)", with
/// the values of options (pass default-constructed options for the defaults).
DYNVO_EXPORTS std::string pipelineConfigHelp(const PipelineOptions& options);

/** \brief Overrides options with the values of a YAML file.
 *
 * The file has up to four maps, `scene_flow`, `segmentation`, `registration` and `pipeline`,
 * whose keys are the field names of the Parameters structs (nested `depth` map inside
 * `scene_flow`); see pipelineConfigTable() for the list and writePipelineConfig() for a file
 * with the defaults. Keys left out keep their value. The result is validated.
 * \throws pcl::IOException naming the file and the key when the file cannot be read, a key is
 *         unknown, a value has the wrong type or is out of its range, or the options are
 *         invalid (a rule tying several fields)
 */
DYNVO_EXPORTS void loadPipelineConfig(const std::string& path,
                                      PipelineOptions& options);

/// Writes options as a YAML file that loadPipelineConfig() reads back unchanged.
/// \throws pcl::IOException when the file cannot be written
DYNVO_EXPORTS void writePipelineConfig(const std::string& path,
                                       const PipelineOptions& options);

} // namespace dynvo::app
