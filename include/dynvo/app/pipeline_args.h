// SPDX-License-Identifier: BSD-3-Clause
// The flags shared by the apps that run the modules: defined once, one default each.
#pragma once

#include <dynvo/app/cli.h>
#include <dynvo/app/frame_source_args.h>
#include <dynvo/app/odometry_pipeline.h>
#include <dynvo/app/output_guard.h>
#include <dynvo/app/run_report.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace dynvo::app {

/// The part of the pipeline an app runs; it decides which of the shared flags the app takes.
enum class PipelineStages {
  scene_flow, ///< the scene flow of one frame pair (dynvo_scene_flow)
  all         ///< OdometryPipeline over a recording (dynvo_odometry, dynvo_segment)
};

/** \brief Every flag of an app: frameSourceOptions(), the app's own flags, then the shared
 * flags of the stages it runs.
 *
 * Both: -config, -write_config, -threads, -cell_size, -window_size, -max_pyramid_level,
 * -fb_check, -v, -q. PipelineStages::all adds -seed, -no_tracking, -no_segmentation,
 * -backend, -max_frames and the shared outputs -objects, -objects_dir, -frames_report, -clouds_dir and
 * -clouds_every (runOutputPathsFromArguments()). Each parameter flag sets a key of
 * pipelineConfigTable() (its help names the key) and defaults to that key's value in
 * PipelineOptions(), so a flag means the same in every app and in a -config file.
 */
DYNVO_EXPORTS std::vector<Option> appOptions(PipelineStages stages,
                                             std::vector<Option> own);

/// The -h text: usage, what the app does, the flags, and every configuration key with its
/// default.
DYNVO_EXPORTS std::string
appHelp(const std::string& usage, const std::string& about, const Arguments& args);

/// Maps -v (PCL debug messages) and -q (errors only) to PCL's verbosity.
DYNVO_EXPORTS void setVerbosityFromArguments(const Arguments& args);

/** \brief The options of a run: PipelineOptions(), overridden by the -config file, the
 * intrinsics of -camera -fx -fy -cx -cy (intrinsicsFromArguments()), then the parameter
 * flags given.
 * \throws UsageError when a flag value is malformed or out of its key's range, or the
 *         options do not validate
 * \throws pcl::IOException when the -config file cannot be read or is invalid
 */
DYNVO_EXPORTS PipelineOptions pipelineOptionsFromArguments(const Arguments& args);

/** \brief With -write_config FILE: checks the path (it must not be the -config file),
 * writes options as YAML and prints "wrote FILE".
 * \return true when the file was written (the app then exits 0), false without the flag
 * \throws UsageError when the path is refused (prepareOutputs())
 * \throws pcl::IOException when the file cannot be written
 */
DYNVO_EXPORTS bool writeConfigIfRequested(const Arguments& args,
                                          const PipelineOptions& options);

/// -max_frames N: frames to process at most (0 = all, the default).
/// \throws UsageError when it is not a whole number >= 0
DYNVO_EXPORTS std::size_t maxFramesFromArguments(const Arguments& args);

/** \brief prepareOutputs() for a run over a recording: the app's outputs plus the
 * shared -objects, -objects_dir, -frames_report and -clouds_dir; the inputs are the source's files and
 * the -config file.
 * \throws UsageError naming the flag, the path and the problem
 */
DYNVO_EXPORTS void prepareRunOutputs(const Arguments& args,
                                     const FrameSource& source,
                                     std::vector<OutputPath> outputs);

/** \brief The outputs of a run: the app's trajectory and label folder ("" = none) plus
 * the shared -objects, -objects_dir, -frames_report, -clouds_dir and -clouds_every N
 * (default 1).
 * \throws UsageError when -clouds_every is not a whole number >= 1 or is given without
 *         -clouds_dir
 */
DYNVO_EXPORTS RunOutputPaths runOutputPathsFromArguments(const Arguments& args,
                                                         const std::string& trajectory,
                                                         const std::string& labels_dir);

/// How a run of the whole pipeline ended.
struct PipelineRunEnd {
  FrameLoopEnd
      loop; ///< frames processed and why the run stopped early ("" = it did not)
  RunReport report; ///< timings and counts, for printSummary()
};

/** \brief Runs OdometryPipeline(options) over the source, at most max_frames frames (0 =
 * all; see maxFramesFromArguments()). Each result goes to outputs, then to on_result (may be empty), then to the
 * report. Whatever stops the run (see processFrames()), outputs.finish() then writes what
 * was computed. read_ahead (-read_ahead): processFrames() reads the next frame beside the
 * pipeline; the results are the same.
 * \throws std::invalid_argument when the options are invalid
 * \throws pcl::IOException when outputs.finish() cannot write a file
 */
DYNVO_EXPORTS PipelineRunEnd
runPipeline(const PipelineOptions& options,
            std::size_t max_frames,
            FrameSource& source,
            RunOutputs& outputs,
            const std::function<void(const Frame&, const FrameResult&)>& on_result = {},
            bool read_ahead = false);

} // namespace dynvo::app
