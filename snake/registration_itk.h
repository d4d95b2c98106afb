#pragma once
/// \file registration_itk.h
/// Image-to-image similarity registration with ITK's v4 framework, behind plain types: the
/// implementation is an ITK translation unit (ITK bundles its own Eigen), so this header
/// exposes nothing but mesh/volume.h and std types.
///
/// The result maps FIXED physical points to MOVING physical points (ITK's convention): with
/// the model's reference image as FIXED and the new image as MOVING, it carries the model's
/// vertices (which lie in the reference image's physical space) into the new image.
#include <array>
#include <string>
#include <vector>

#include "mesh/volume.h"

namespace mrsnake {

enum class RegistrationMetric {
  mattes,        ///< Mattes mutual information (any monotone intensity mapping)
  mean_squares,  ///< mean squared difference (same modality, normalized intensities)
};
/// \throw InputError for another name than "mattes" or "mean_squares".
RegistrationMetric parse_registration_metric(const std::string& name);
std::string to_string(RegistrationMetric metric);

struct RegistrationOptions {
  RegistrationMetric metric = RegistrationMetric::mattes;
  int histogram_bins = 32;  ///< Mattes only
  /// Coarse to fine: per level, both images are averaged over blocks of this many voxels per
  /// axis, then smoothed by a Gaussian of smoothing_voxels (in input voxels; 0 = none), and
  /// the transform found carries over to the next level.
  std::vector<int> shrink_factors{4, 2, 1};
  std::vector<double> smoothing_voxels{2.0, 1.0, 0.0};
  /// Metric samples per iteration and level (at most the voxels of that level), drawn on a
  /// regular grid with a random jitter from a fixed seed: results are reproducible.
  /// (1500 samples and 25 iterations: 0.05–0.1 s instead of 0.13–0.26 s on the benchmark's
  /// cases, the same final Dice within ±0.0005; docs/bench-segment.md.)
  int samples_per_level = 1500;
  int iterations_per_level = 25;
  /// Points of the regular grid on which the metric is evaluated at the start and at the
  /// result (full resolution), to judge the registration.
  int evaluation_samples = 4000;
  /// The optimizer's first step (regular step descent), in voxels of the fixed image (its
  /// largest side): lengths follow the images' scale, whether a mouse brain at 0.3 mm or an
  /// abdomen at 3 mm.
  double initial_step_voxels = 1.0;
  /// Radius at which rotations and scalings are measured against translations (parameter
  /// scales); <= 0: the RMS distance of the fixed image's edges from its centre.
  double rotation_radius_mm = 0;
  double step_factor_per_level = 0.5;  ///< first step of level l: initial_step_voxels · factor^l
  double min_step_voxels = 0.003;      ///< stop when the step falls below this (fixed image voxels)
  double relaxation = 0.6;             ///< step factor when the gradient turns back
  /// Stop a level early once the metric (on that level's samples) has changed by less than
  /// this fraction of its magnitude over the last `convergence_window` iterations (0: off):
  /// the optimizer then creeps along a flat minimum, which costs time and moves nothing.
  double min_relative_change = 0.002;
  int convergence_window = 5;
  /// The part of the MOVING image used: the fixed image's box mapped by the start
  /// transform, grown by this fraction of its size per side plus moving_margin_voxels voxels
  /// of the fixed image.
  double moving_margin_fraction = 0.25;
  double moving_margin_voxels = 4.0;
  /// A linear map applied to the moving image's intensities (e.g. its normalization, so
  /// that mean squares compares like with like).
  double moving_intensity_scale = 1.0, moving_intensity_offset = 0.0;
  /// The start: a translation (mm) of the fixed image (identity rotation and scale).
  std::array<double, 3> initial_translation{0, 0, 0};
  /// Stop the optimizer past this wall time: a guard against a runaway run only. The runs take
  /// 0.1-0.3 s, so that under any normal load the iteration counts stop it first and the
  /// result does not depend on timing; a run it stops says "time budget spent" in stop_condition.
  double max_seconds = 5.0;
  int threads = 1;  ///< ITK work units (1: one thread)
};

/// x ↦ matrix·x + offset, with matrix = scale·R (R a rotation), in physical space; also in
/// ITK's centred form x ↦ scale·R·(x − centre) + centre + translation.
struct RegistrationTransform {
  std::array<double, 9> matrix{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major, scale included
  std::array<double, 3> offset{0, 0, 0};
  std::array<double, 3> centre{0, 0, 0};
  std::array<double, 3> translation{0, 0, 0};
  std::array<double, 4> versor{0, 0, 0, 1};  ///< x, y, z, w of R
  double scale = 1.0;
  double angle_deg = 0.0;  ///< rotation angle of R

  std::array<double, 3> apply(const std::array<double, 3>& x) const;
};

struct RegistrationResult {
  RegistrationTransform transform;
  std::string metric;                                    ///< to_string of the metric used
  double initial_metric = 0;                             ///< at the start transform, on the full-resolution images
  double final_metric = 0;                               ///< the same evaluation at the result (lower is better)
  int valid_points_initial = 0, valid_points_final = 0;  ///< of the evaluation samples
  std::vector<int> iterations;                           ///< per level (0 for a level the time budget skipped)
  std::string stop_condition;                            ///< the optimizer's, at the last level
  int converged_levels = 0;                              ///< levels stopped by min_relative_change
  std::array<std::size_t, 3> moving_crop_size{0, 0, 0};
  double edge_radius_mm = 0;        ///< the radius the parameter scales used
  double seconds = 0;               ///< everything, crop and evaluations included
  double cpu_seconds = 0;           ///< process CPU time over the same span (all threads)
  double setup_seconds = 0;         ///< crop, copies, parameter scales
  double evaluation_seconds = 0;    ///< the two metric evaluations
  double optimization_seconds = 0;  ///< the levels: block means and ITK's optimization
};

/// Registers `fixed` to `moving` with a Similarity3DTransform (versor, translation, scale)
/// about the centre of the fixed image, starting from options.initial_translation (by
/// default the identity: both images in the same physical space), coarse to fine: per level
/// one single-level ImageRegistrationMethodv4 on block-averaged images, with the chosen metric
/// and regular step gradient descent (parameter scales from physical shifts). The moving
/// image is first cropped to where the fixed image can land. Nothing is judged here: the
/// caller compares initial and final metrics and the scale.
/// \pre both volumes have data of their size; the fixed image has at least 8 voxels per axis.
/// \throw InputError if the fixed image is too small or does not overlap the moving image.
/// \throw AlgorithmError if ITK fails (e.g. too few samples land in the moving image).
RegistrationResult register_similarity(const Volume& fixed, const Volume& moving,
                                       const RegistrationOptions& options = {});

/// The box of `image` (voxel indices, inclusive) covering the physical points, grown by
/// margin_fraction of its size per side plus margin_mm, clamped to the image. Returns false
/// if the box misses the image entirely (or a point is not finite).
/// \pre points is not empty.
bool index_box_of_points(const Volume& image, const std::vector<std::array<double, 3>>& points, double margin_fraction,
                         double margin_mm, std::array<long, 3>& lo, std::array<long, 3>& hi);

/// The voxels [lo, hi] (inclusive) of `image` as a volume of their own, in the same
/// physical place.
/// \pre 0 <= lo <= hi < size on each axis.
Volume crop_volume(const Volume& image, const std::array<long, 3>& lo, const std::array<long, 3>& hi);

}  // namespace mrsnake
