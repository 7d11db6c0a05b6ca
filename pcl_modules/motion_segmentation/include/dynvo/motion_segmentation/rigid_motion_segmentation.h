// SPDX-License-Identifier: BSD-3-Clause
// Rigid motion segmentation of a grid scene flow, tracked over a sequence (docs/algorithm.md §2-§6).
#pragma once

#include <dynvo/common/camera.h>
#include <dynvo/common/conventions.h>
#include <dynvo/common/export.h>
#include <dynvo/common/flow_grid.h>
#include <dynvo/common/point_types.h>
#include <dynvo/motion_segmentation/grid_flow_data.h>
#include <dynvo/motion_segmentation/pixel_label_refinement.h>
#include <dynvo/motion_segmentation/rigid_motion_segmentation_parameters.h>
#include <dynvo/motion_segmentation/segment_tracker.h>
#include <dynvo/motion_segmentation/spatial_segmentation.h>

#include <pcl/PointIndices.h>
#include <pcl/pcl_base.h>
#include <pcl/point_types.h> // pcl::Label
#include <pcl/point_cloud.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dynvo {

/** \brief Rigid motion segmentation and tracking of Lee, Son & Kim, "Robust Real-time RGB-D
 * Visual Odometry in Dynamic Environments via Rigid Motion Model", IROS 2019 (arXiv
 * 1907.08388), §III-B and §III-C.
 *
 * Input: the current organized cloud (frame k, where the grid is anchored) and the grid scene
 * flow from frame k-1 to k (GridSceneFlowEstimation). Every frame, rigid motion hypotheses are
 * sampled on the flow (entropy-weighted), refined, clustered by DBSCAN and turned into
 * segments (docs/algorithm.md §3). With tracking on (default), the segments are matched against
 * the last label maps to get persistent ids, label 1 being the static background (§4), and a
 * dual-mode per-cell model filters the labels over time (§5, §6).
 *
 * Output of segment(): element 0 is always the static background (label 1, possibly empty),
 * then one pcl::PointIndices per moving object in increasing id order; getSegmentLabels()
 * gives the ids and getMotions() one T_curr_prev per segment. Indices are linear pixel indices
 * (row * width + col); every pixel with finite depth belongs to exactly one segment, at
 * pixel accuracy (PixelLabelRefinement, docs/algorithm.md §6.1: cells without a label are
 * filled from the dual model or their depth-continuous neighbours, boundary cells are split
 * pixel by pixel), unless no cell of the frame has a label.
 * With tracking off, the segments are the two-frame ones, largest first (its label 1).
 * \code
 * dynvo::RigidMotionSegmentation<pcl::PointXYZRGB> segmentation;
 * segmentation.setCameraIntrinsics(intrinsics);
 * std::vector<pcl::PointIndices> segments;
 * for (each frame k >= 1, with its flow from GridSceneFlowEstimation) {
 *   segmentation.setInputCloud(cloud_k);
 *   segmentation.setInputFlow(flow_k);
 *   segmentation.setPredictedMotion(T_curr_prev_of_frame_k_minus_1);
 *   segmentation.segment(segments); // segments[0]: static background
 * }
 * \endcode
 * Each segment() (or segmentCells()) takes its frame as frame k and keeps it as the next
 * call's frame k-1, whose colours the ambiguity test reads (docs/algorithm.md §4.1): frames
 * are given in order, each once.
 * Not thread-safe; separate instances may run concurrently. Explicitly instantiated for
 * pcl::PointXYZRGB and pcl::PointXYZRGBA (other types: include the impl .hpp).
 */
template <typename PointT> class RigidMotionSegmentation : public pcl::PCLBase<PointT> {
public:
  using Base = pcl::PCLBase<PointT>;
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudPtr = typename PointCloud::Ptr;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  using Ptr = pcl::shared_ptr<RigidMotionSegmentation<PointT>>;
  using ConstPtr = pcl::shared_ptr<const RigidMotionSegmentation<PointT>>;
  using FlowCloud = pcl::PointCloud<PointFlow>;
  using FlowCloudConstPtr = FlowCloud::ConstPtr;
  using Parameters = RigidMotionSegmentationParameters;
  using Motions =
      std::vector<Eigen::Matrix4f, Eigen::aligned_allocator<Eigen::Matrix4f>>;

  RigidMotionSegmentation() = default;

  /// Name used in log prefixes: "RigidMotionSegmentation".
  const std::string& getClassName() const { return class_name_; }

  /// Current frame k (organized, metres); the pixel indices of segment() refer to it. Clears
  /// the depth image of setInputDepth().
  void setInputCloud(const PointCloudConstPtr& cloud) override;

  /** \brief The input cloud's z as a row-major image (metres, NaN where the point has none),
   * such as GridSceneFlowEstimation::getInputDepth() after its compute() on the same cloud.
   * Optional: the pixel labels read it instead of the cloud's points (the same labels; the
   * points are 8 times larger than their z). Call it after setInputCloud(); ignored unless it
   * holds one value per point. Kept, not copied: its holder must not change it meanwhile.
   */
  void setInputDepth(const std::shared_ptr<const std::vector<float>>& depth)
  {
    input_depth_ = depth;
  }

  /// Grid scene flow from frame k-1 to frame k (organized, (width / w_grid) x (height / w_grid));
  /// the cell size w_grid is inferred from it (FlowGrid::fromFlow()).
  void setInputFlow(const FlowCloudConstPtr& flow);

  const FlowCloudConstPtr& getInputFlow() const { return flow_; }

  /** \brief Segments the current frame by rigid motion.
   * \param[out] segments element 0 = static background, then moving objects by id (see
   *             the class doc); empty when the inputs break the contract (null,
   *             unorganized, flow grid not matching the cloud), which is logged with PCL_ERROR
   * \throws std::invalid_argument (outputs left empty) when getParameters().validate()
   *         fails, e.g. max_trials < max_hypotheses after the per-field setters
   */
  void segment(std::vector<pcl::PointIndices>& segments);

  /** \brief The cell stage of segment(): the tracking and its results per cell (getCellGrid(),
   * hasBackground(), getSegmentLabels(), getMotions(), the noise gains), without the pixel
   * labels and indices, which computeSegments() adds; segment(segments) is the two in a row.
   *
   * The split lets a caller that needs only the cells next (the ego-motion fit) run
   * computeSegments() on another thread meanwhile. While it runs, only the const getters of
   * the cell stage may be called on this object.
   * \throws std::invalid_argument as segment()
   */
  void segmentCells();

  /** \brief The pixel stage of the last segmentCells(): pixel labels
   * (getPixelLabels()) and the segments.
   * \param[out] segments as segment(); empty when the cell stage gave no output
   */
  void computeSegments(std::vector<pcl::PointIndices>& segments);

  /** \brief As segment(segments), and the same pixel labels as an image.
   * \param[out] segments as segment(segments)
   * \param[out] labels organized like the input cloud: 0 no depth (or no labelled cell), 1
   *             static, 2.. objects; empty when the inputs break the contract
   */
  void segment(std::vector<pcl::PointIndices>& segments,
               pcl::PointCloud<pcl::Label>& labels);

  /** \brief Runs the tracking of the last segment() again from the state before it, with the
   * predicted motion and the guard tolerance set now (the two-frame segmentation is kept).
   *
   * For a frame on which no segment agreed with the prediction (hasBackground() false): its
   * measured ego-motion is a better reference for the background guard (docs/algorithm.md §4).
   * \param[out] segments as segment(); empty, and nothing changed, when the last segment()
   *             gave no output
   */
  void resegment(std::vector<pcl::PointIndices>& segments);

  /// A cell of the last segment() holds label 1: the guard found the background.
  bool hasBackground() const;

  /// Label of every pixel of the last segment() (row * width + col; 0 no depth), after
  /// PixelLabelRefinement; empty when the inputs broke the contract.
  const std::vector<std::uint8_t>& getPixelLabels() const { return pixel_labels_; }

  /// The cell-to-pixel step (its parameters: setPixelRefinementParameters()).
  const PixelLabelRefinement& getPixelRefinement() const { return refinement_; }

  /// Parameters of the cell-to-pixel step. \throws std::invalid_argument when invalid
  void setPixelRefinementParameters(const PixelLabelRefinement::Parameters& parameters)
  {
    refinement_.setParameters(parameters);
  }

  /// Label id of each segment of the last segment() (element 0 is 1).
  const std::vector<std::uint8_t>& getSegmentLabels() const { return segment_labels_; }

  /// T_curr_prev of each segment of the last segment() (maps frame k-1 points to frame k).
  const Motions& getMotions() const { return motions_; }

  /** \brief Label per grid cell (row-major, cols x rows of the flow): 0 none, 1 static, 2..
   * objects, the cells the ego-motion fit takes as static being those labelled 1. An object
   * younger than object_birth_frames, and every object of a frame with no cell labelled 1, is
   * here but not in the segments, the pixel labels or getSegmentLabels() (its pixels are
   * static there).
   */
  const std::vector<std::uint8_t>& getCellLabels() const { return cell_grid_.labels; }

  /// The grid of the last segment() with the label of each cell (getCellLabels()); empty
  /// when the inputs broke the contract.
  const FlowGrid& getCellGrid() const { return cell_grid_; }

  /// The two-frame segmentation of the last segment() (G, one motion per segment, docs/algorithm.md §3).
  const SpatialSegmentationResult& getSpatialSegmentation() const { return spatial_; }

  /// The tracker state (tracked labels Ghat, model labels L, docs/algorithm.md §4-§6).
  const SegmentTracker& getTracker() const { return tracker_; }

  /// The sensor model's gains {axial, lateral} for the next segment() (1 after reset()).
  const std::array<float, 2>& getNoiseGains() const { return noise_gains_; }

  /** \brief Forgets the sequence (label buffer and models): the next segment() starts a new
   * one. Parameter setters keep the sequence; a new grid size or max_labels restarts it.
   */
  void reset();

  /** \brief Constant-velocity prediction H_pred: the previous frame's ego-motion T_curr_prev
   * (metres). Used by the static-background guard (§4) and the compensation fallback (§6).
   * Default identity; the pipeline sets it before every segment().
   */
  void setPredictedMotion(const Eigen::Matrix4f& T_curr_prev);

  const Eigen::Matrix4f& getPredictedMotion() const { return predicted_motion_; }

  /// Intrinsics of the current frame (§6 reprojection). \throws std::invalid_argument when invalid
  void setCameraIntrinsics(const CameraIntrinsics& intrinsics);

  const CameraIntrinsics& getCameraIntrinsics() const { return intrinsics_; }

  /** \brief Threads (default 1) for the per-pixel index extraction (dynvo::forEachStripe); the
   * per-cell loops take microseconds and stay on the caller's thread. Results are identical
   * for any count.
   * \throws std::invalid_argument on 0
   */
  void setNumberOfThreads(unsigned threads);

  unsigned getNumberOfThreads() const { return threads_; }

  /// All knobs at once. \throws std::invalid_argument when parameters.validate() fails
  void setParameters(const Parameters& parameters);

  const Parameters& getParameters() const { return params_; }

  // One setter/getter pair per field of Parameters. A setter throws std::invalid_argument
  // when the value is outside the field's own range (RigidMotionSegmentationParameters::
  // table()) and keeps the old value; the rules tying two fields (max_trials >=
  // max_hypotheses, object_separation_hold <= object_separation_ratio) are checked by
  // segment(), so the setters may come in any order.
  DYNVO_PARAMETER_ACCESSORS(MaxHypotheses, max_hypotheses)
  DYNVO_PARAMETER_ACCESSORS(MaxTrials, max_trials)
  DYNVO_PARAMETER_ACCESSORS(SampleSize, sample_size)
  DYNVO_PARAMETER_ACCESSORS(SearchRadius, search_radius)
  DYNVO_PARAMETER_ACCESSORS(ResidualModel, residual_model)
  DYNVO_PARAMETER_ACCESSORS(InlierThreshold, inlier_threshold)
  DYNVO_PARAMETER_ACCESSORS(InlierChi2, inlier_chi2)
  DYNVO_PARAMETER_ACCESSORS(SensorEntropyLambda, sensor_entropy_lambda)
  DYNVO_PARAMETER_ACCESSORS(SensorDbscanEpsilon, sensor_dbscan_epsilon)
  DYNVO_PARAMETER_ACCESSORS(NoiseScaleMin, noise_scale_min)
  DYNVO_PARAMETER_ACCESSORS(NoiseScaleMax, noise_scale_max)
  DYNVO_PARAMETER_ACCESSORS(EntropyLambda, entropy_lambda)
  DYNVO_PARAMETER_ACCESSORS(EntropyDelta, entropy_delta)
  DYNVO_PARAMETER_ACCESSORS(RefineIterations, refine_iterations)
  DYNVO_PARAMETER_ACCESSORS(EntropyDone, entropy_done)
  DYNVO_PARAMETER_ACCESSORS(EntropySaturation, entropy_saturation)
  DYNVO_PARAMETER_ACCESSORS(DbscanMinPoints, dbscan_min_points)
  DYNVO_PARAMETER_ACCESSORS(DbscanEpsilon, dbscan_epsilon)
  DYNVO_PARAMETER_ACCESSORS(MinSegmentSize, min_segment_size)
  DYNVO_PARAMETER_ACCESSORS(Tracking, tracking)
  DYNVO_PARAMETER_ACCESSORS(MaxLabels, max_labels)
  DYNVO_PARAMETER_ACCESSORS(MaxAge, max_age)
  DYNVO_PARAMETER_ACCESSORS(BufferLength, buffer_length)
  DYNVO_PARAMETER_ACCESSORS(MinCorrelation, min_correlation)
  DYNVO_PARAMETER_ACCESSORS(StaticGuardTolerance, static_guard_tolerance)
  DYNVO_PARAMETER_ACCESSORS(StaticMinCells, static_min_cells)
  DYNVO_PARAMETER_ACCESSORS(ObjectSeparationRatio, object_separation_ratio)
  DYNVO_PARAMETER_ACCESSORS(ObjectSeparationHold, object_separation_hold)
  DYNVO_PARAMETER_ACCESSORS(ObjectBirthFrames, object_birth_frames)
  DYNVO_PARAMETER_ACCESSORS(ObjectBirthRatio, object_birth_ratio)
  DYNVO_PARAMETER_ACCESSORS(AmbiguitySearchRadius, ambiguity_search_radius)
  DYNVO_PARAMETER_ACCESSORS(Seed, seed)

protected:
  using Base::deinitCompute;
  using Base::input_;

  /// Non-null, organized input cloud and flow; logs PCL_ERROR and returns false otherwise.
  bool initCompute();

  /// The flow grid is the (width / w_grid) x (height / w_grid) grid of a cell size w_grid
  /// (FlowGrid::fromFlow()); sets the geometry of cell_grid_, logs PCL_ERROR otherwise.
  bool validateInputs();

  /// Pixel labels from the cell labels (PixelLabelRefinement), into pixel_labels_.
  void computeImplPixelLabels();

  /// Tracking (or the two-frame result), cell labels, segment ids, motions and noise gains.
  void computeImplLabels();

  /// Fills segments with the pixels of each label of pixel_labels_, in segment_labels_ order.
  void computeImplIndices(std::vector<pcl::PointIndices>& segments) const;

private:
  /// Stores checked parameters (the sequence state is kept).
  void assignParameters(const Parameters& parameters) { params_ = parameters; }

  /// Clears every output of segment().
  void clearOutputs();

  /// The grid's information matrices for the sensor model, with noise_gains_.
  void computeInformation();

  /// Fits noise_gains_ to the static cells' residuals under the background motion.
  void updateNoiseScale();

  /// Mean of fx and fy (px).
  float focalLength() const;

  std::string class_name_ = "RigidMotionSegmentation"; ///< log prefix
  Parameters params_;                                  ///< validated knobs
  CameraIntrinsics intrinsics_; ///< current-frame intrinsics (default preset)
  unsigned threads_ = 1;        ///< worker threads
  Eigen::Matrix4f predicted_motion_ =
      Eigen::Matrix4f::Identity();           ///< H_pred (T_curr_prev)
  FlowCloudConstPtr flow_;                   ///< scene flow k-1 -> k
  GridFlowData grid_;                        ///< flow on plain buffers
  SpatialSegmenter segmenter_;               ///< §3 with its scratch buffers
  SpatialSegmentationResult spatial_;        ///< §3 result of the last frame
  SegmentTracker tracker_;                   ///< §4-§6 state across frames
  SegmentTracker tracker_before_; ///< tracker_ before the last frame (resegment())
  FlowGrid cell_grid_;                       ///< geometry and label per cell (the fit's)
  FlowGrid output_grid_; ///< cell_grid_ with objects younger than n_birth static
  std::vector<std::uint8_t> segment_labels_; ///< id of each output segment
  Motions motions_;                          ///< T_curr_prev of each output segment
  PixelLabelRefinement refinement_;          ///< cell labels to pixel labels
  std::vector<std::uint8_t> pixel_labels_;   ///< label per pixel of the last segment()
  std::shared_ptr<const std::vector<float>> input_depth_; ///< setInputDepth(); null: the cloud's z
  PointCloudConstPtr previous_input_; ///< frame k-1: the last segmentCells()'s but one
  PointCloudConstPtr last_input_;     ///< the input of the last segmentCells()
  /// s_axial, s_lateral: the sensor model's gains on its axial and lateral sigma, fitted
  /// over the frames
  std::array<float, 2> noise_gains_{1.0f, 1.0f};
  std::array<float, 2> noise_gains_before_{1.0f, 1.0f}; ///< before the last frame
};

} // namespace dynvo

#ifdef DYNVO_NO_PRECOMPILE
#include <dynvo/motion_segmentation/impl/rigid_motion_segmentation.hpp>
#endif
