#include "snake/pose.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mesh/errors.h"
#include "snake/appearance.h"
#include "snake/surface_geometry.h"

namespace mrsnake {

InitMode resolve_init_mode(InitMode mode, const SnakeModel& model) {
  if (mode != InitMode::automatic) return mode;
  return model.reference_image ? InitMode::registration_and_fit : InitMode::moments_and_fit;
}

bool registers(InitMode mode) { return mode == InitMode::registration || mode == InitMode::registration_and_fit; }

namespace {
bool from_moments(InitMode mode) { return mode == InitMode::moments || mode == InitMode::moments_and_fit; }
bool fits(InitMode mode) {
  return mode == InitMode::moments_and_fit || mode == InitMode::fit || mode == InitMode::registration_and_fit;
}
}  // namespace

Similarity model_moments_pose(const SnakeModel& model, const NormalizedPyramid& pyramid,
                              const MomentsOptions& options) {
  const int p = std::min<int>(2, static_cast<int>(pyramid.levels.size()) - 1);
  const int jm = std::min(model.finest_level(), 2);
  MomentsOptions mo = options;
  if (model.appearance && std::isnan(mo.threshold)) {
    mo.threshold =
        model.appearance->region.outside + 0.7 * (model.appearance->region.inside - model.appearance->region.outside);
    mo.bright_object = model.appearance->region.inside > model.appearance->region.outside;
  }
  return moments_alignment(*pyramid.levels[p], TriMesh{model.levels[jm], model.faces(jm)}, mo);
}

ReferenceRegistration register_model_reference(const SnakeModel& model, const NormalizedPyramid& pyramid, InitMode mode,
                                               const ReferenceRegistrationOptions& options,
                                               const MomentsOptions& moments) {
  if (!model.reference_image)
    throw InputError("the initialization " + to_string(mode) + " needs a model with a reference image",
                     Remedy::rebuild_model_with_image);
  const double s0 = pyramid.level0_raw ? pyramid.level0_scale : 1.0;
  const double o0 = pyramid.level0_raw ? pyramid.level0_offset : 0.0;
  ReferenceRegistration registration = register_reference(*model.reference_image, pyramid.levels, s0, o0, options);
  if (registration.accepted) return registration;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  bool have_shift = false;
  try {
    const Eigen::Vector3d c = model.levels[0].colwise().mean().transpose();
    shift = model_moments_pose(model, pyramid, moments).apply(c) - c;
    have_shift = true;
  } catch (const AlgorithmError&) {  // nothing to align to: no second start
  }
  if (!have_shift || !(shift.norm() > 0.5 * model.reference_image->max_spacing())) return registration;
  const double first_seconds = registration.seconds;
  const std::string first_rejection = registration.rejection;
  registration = register_reference(*model.reference_image, pyramid.levels, s0, o0, options, shift);
  registration.seconds += first_seconds;
  registration.first_rejection = first_rejection;
  for (int a = 0; a < 3; ++a) registration.retry_translation[a] = shift[a];
  return registration;
}

std::vector<FitStart> fit_starts(const Similarity& pose, InitMode mode, bool registered, const RowMatrixX3d& level0) {
  std::vector<FitStart> starts{{pose, registered ? "registration" : from_moments(mode) ? "moments" : "model pose"}};
  if (!registered && pose.rotation_angle_deg() > 1.0) {
    const Eigen::Vector3d c = level0.colwise().mean().transpose();
    Similarity unrotated = pose;
    unrotated.rotation.setIdentity();
    unrotated.translation = pose.apply(c) - pose.scale * c;
    starts.push_back({unrotated, "moments without rotation"});
  }
  if (mode == InitMode::moments_and_fit) starts.push_back({Similarity{}, "model pose"});
  return starts;
}

RegionStats threshold_region_stats(const NormalizedPyramid& pyramid, const RowMatrixX3d& V,
                                   const Appearance* appearance) {
  std::array<long, 3> lo{}, hi{};
  mesh_index_box(*pyramid.levels[0], V, 0.15, lo, hi);
  ThresholdClasses c = threshold_classes(*pyramid.levels[0],
                                         *pyramid.levels[std::min<std::size_t>(1, pyramid.levels.size() - 1)], lo, hi);
  if (pyramid.level0_raw) {  // the medians come from the raw full-resolution image
    c.upper_median = pyramid.level0_scale * c.upper_median + pyramid.level0_offset;
    c.lower_median = pyramid.level0_scale * c.lower_median + pyramid.level0_offset;
  }
  const bool bright = !appearance || appearance->region.inside >= appearance->region.outside;
  return bright ? RegionStats{c.upper_median, c.lower_median} : RegionStats{c.lower_median, c.upper_median};
}

FittedPose best_fitted_pose(const std::vector<FitStart>& starts, const RowMatrixX3d& V, const RowMatrixX3i& F,
                            const ExternalSearch& search, const TargetFitOptions& options) {
  FittedPose best;
  best.pose = starts.front().pose;
  double best_cost = std::numeric_limits<double>::infinity();
  RowMatrixX3d N;
  for (const FitStart& start : starts) {
    RowMatrixX3d W = start.pose.apply(V);
    int iterations = 0;
    const Similarity fitted = fit_similarity_to_targets(W, F, search, options, &iterations);
    vertex_normals(W, F, N);
    const double cost = search(W, N).costs.mean();
    if (cost < best_cost) {
      best_cost = cost;
      best.pose = fitted.compose(start.pose);
      best.iterations = iterations;
      best.start = start.name;
    }
  }
  return best;
}

InitialPose initial_pose(const SnakeModel& model, const NormalizedPyramid& pyramid, const LevelSearches& searches,
                         const std::optional<ReferenceRegistration>& registration, InitMode mode,
                         const InitialPoseOptions& options) {
  const int L = model.finest_level();
  const Appearance* appearance = model.appearance ? &*model.appearance : nullptr;
  InitialPose start;
  RowMatrixX3d& V = start.coarse;
  V = model.levels[0];
  const bool registered = registration && registration->accepted;
  if (registered) {
    start.pose = registration->pose;
    V = start.pose.apply(V);
  } else if (registration) {
    mode = mode == InitMode::registration ? InitMode::moments : InitMode::moments_and_fit;
  }
  start.init = mode;
  if (from_moments(mode)) {
    start.pose = model_moments_pose(model, pyramid, options.moments);
    V = start.pose.apply(V);
  }
  const std::vector<FitStart> starts = fit_starts(start.pose, mode, registered, model.levels[0]);
  start.region = searches.profiles() ? model.appearance->region : threshold_region_stats(pyramid, V, appearance);
  if (fits(mode)) {
    // Fit the whole mesh of a level with enough vertices to carry the shape; synthesis
    // follows a similarity, so the pose found there applies to S_0 as well.
    const int jf = std::min(L, options.fit_level);
    const double range = searches.range_mm(jf, options.coarse_range_edge_fraction, options.fit_min_range_voxels);
    const ExternalSearch search =
        searches.search(jf, range, start.region, nullptr, options.profile_step_fraction).first;
    TargetFitOptions fit_options = options.fit;
    fit_options.tolerance_mm = options.fit_tolerance_voxels * pyramid.spacings[0];
    if (registered) fit_options.patience = options.fit_patience_after_registration;
    const FittedPose fitted = best_fitted_pose(starts, model.levels[jf], model.faces(jf), search, fit_options);
    start.pose = fitted.pose;
    start.fit_iterations = fitted.iterations;
    start.fit_start = fitted.start;
    V = start.pose.apply(model.levels[0]);
    if (!searches.profiles())
      start.region = threshold_region_stats(pyramid, start.pose.apply(model.levels[L]), appearance);
  }
  if (!searches.profiles() && !(std::abs(start.region.inside - start.region.outside) > 1e-6))
    throw AlgorithmError("no contrast between the inside and the outside of the initial surface; check the pose");
  return start;
}

}  // namespace mrsnake
