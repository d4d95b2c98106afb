#include "snake/segment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "mesh/stage_clock.h"
#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/marching_cubes.h"
#include "mesh/normals.h"
#include "mesh/option_checks.h"
#include "snake/image_pyramid.h"
#include "snake/level_search.h"
#include "snake/pose.h"

namespace mrsnake {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

InitMode parse_init_mode(const std::string& name) {
  if (name == "auto") return InitMode::automatic;
  if (name == "register") return InitMode::registration;
  if (name == "register+fit") return InitMode::registration_and_fit;
  if (name == "pose") return InitMode::pose;
  if (name == "moments") return InitMode::moments;
  if (name == "moments+fit") return InitMode::moments_and_fit;
  if (name == "fit") return InitMode::fit;
  throw InputError("unknown initialization '" + name +
                   "'; use auto, pose, moments, moments+fit, fit, register or register+fit");
}

std::string to_string(InitMode mode) {
  switch (mode) {
    case InitMode::automatic: return "auto";
    case InitMode::registration: return "register";
    case InitMode::registration_and_fit: return "register+fit";
    case InitMode::pose: return "pose";
    case InitMode::moments: return "moments";
    case InitMode::moments_and_fit: return "moments+fit";
    case InitMode::fit: return "fit";
  }
  return "?";
}

ForceMode parse_force_mode(const std::string& name) {
  if (name == "auto") return ForceMode::automatic;
  if (name == "profile") return ForceMode::profile;
  if (name == "edge") return ForceMode::step_edge;
  throw InputError("unknown force '" + name + "'; use auto, profile or edge");
}

std::string to_string(ForceMode mode) {
  switch (mode) {
    case ForceMode::automatic: return "auto";
    case ForceMode::profile: return "profile";
    case ForceMode::step_edge: return "edge";
  }
  return "?";
}

void to_json(nlohmann::json& j, const MomentsOptions& o) {
  j = {{"roi_margin", o.roi_margin},
       {"rotate", o.rotate},
       {"min_axis_separation", o.min_axis_separation},
       {"max_rotation_deg", o.max_rotation_deg},
       {"threshold", std::isnan(o.threshold) ? nlohmann::json() : nlohmann::json(o.threshold)},
       {"bright_object", o.bright_object}};
}

void from_json(const nlohmann::json& j, MomentsOptions& o) {
  const MomentsOptions d;
  o.roi_margin = j.value("roi_margin", d.roi_margin);
  o.rotate = j.value("rotate", d.rotate);
  o.min_axis_separation = j.value("min_axis_separation", d.min_axis_separation);
  o.max_rotation_deg = j.value("max_rotation_deg", d.max_rotation_deg);
  const auto threshold = j.find("threshold");
  o.threshold = threshold == j.end() || threshold->is_null() ? d.threshold : threshold->get<double>();
  o.bright_object = j.value("bright_object", d.bright_object);
}

SnakeOptions fine_level_snake_options(const SnakeOptions& snake, const FineLevelOptions& fine, double edge_voxels) {
  SnakeOptions o = snake;
  // k passes of the 7-point average on a regular mesh of edge e: a variance of k·(3/7)·e².
  const double sigma_in_edges = fine.offset_smoothing_voxels / edge_voxels;
  const double passes = sigma_in_edges * sigma_in_edges / (3.0 / 7.0);
  if (std::isfinite(passes))
    o.offset_smoothing = std::max(o.offset_smoothing, static_cast<int>(std::lround(std::min(passes, 1000.0))));
  o.min_iterations = std::min(o.min_iterations, fine.min_iterations);
  o.patience = std::min(o.patience, fine.patience);
  return o;
}

SnakeOptions fine_level_snake_options(const SegmentOptions& options, double edge_voxels) {
  return fine_level_snake_options(options.snake, options.fine, edge_voxels);
}

namespace {

// The model has levels and a synthesis, and a stored appearance matches the levels before
// the profiles are used, and before the automatic choice reads them.
void check_model(const SnakeModel& model, ForceMode force) {
  const int L = model.finest_level();
  if (L < 0 || static_cast<int>(model.levels.size()) != L + 1 || !model.synthesize)
    throw InputError("the model has no usable levels", Remedy::rebuild_model);
  if (model.appearance && force != ForceMode::step_edge) {
    if (static_cast<int>(model.appearance->levels.size()) != L + 1)
      throw InputError("the model's appearance does not match its levels; rebuild the model");
    for (int j = 0; j <= L; ++j)
      if (model.appearance->levels[j].profiles.rows() != model.levels[j].rows())
        throw InputError("the model's appearance does not match its levels; rebuild the model");
  }
  if (force == ForceMode::profile && !model.appearance)
    throw InputError("the profile force needs a model built with an appearance", Remedy::rebuild_model_with_image);
}

struct ForceChoice {
  bool profiles = false;
  double step_residual = std::numeric_limits<double>::infinity();  ///< when chosen automatically
};

// Automatic: the profiles, unless what they learned is a clean step between two
// intensities; there the step-edge force, which fits the step at sub-voxel precision on
// every level, is both more accurate and faster (synthetic blobs at 128³: Dice
// 0.9941–0.9956 with profiles, 0.9956–0.9971 with the step).
ForceChoice choose_force(const SnakeModel& model, ForceMode force, double clean_step_max_residual) {
  ForceChoice c;
  c.step_residual = model.appearance && force == ForceMode::automatic
                        ? profile_step_residual(*model.appearance, model.connectivity.faces)
                        : std::numeric_limits<double>::infinity();
  c.profiles = force == ForceMode::profile || (force == ForceMode::automatic && model.appearance.has_value() &&
                                               !(c.step_residual <= clean_step_max_residual));
  return c;
}

LevelSearchOptions level_search_options(const SegmentOptions& o) {
  LevelSearchOptions s;
  s.edge_per_voxel = o.edge_per_voxel;
  s.step_voxels = o.step_voxels;
  s.window_voxels = o.window_voxels;
  s.max_edge_cost = o.max_edge_cost;
  s.max_profile_cost = o.max_profile_cost;
  s.profile_distance_penalty = o.profile_distance_penalty;
  s.edge_distance_penalty = o.edge_distance_penalty;
  s.min_gain = o.search_min_gain;
  s.ring_weight = o.cost_ring_weight;
  s.ring_full_weight_cost = o.cost_ring_full_weight_cost;
  s.max_range_voxels = o.max_range_voxels;
  return s;
}

InitialPoseOptions initial_pose_options(const SegmentOptions& o) {
  InitialPoseOptions p;
  p.moments = o.moments;
  p.fit = o.fit;
  p.fit_tolerance_voxels = o.fit_tolerance_voxels;
  p.fit_patience_after_registration = o.fit_patience_after_registration;
  p.fit_level = o.fit_level;
  p.coarse_range_edge_fraction = o.coarse_range_edge_fraction;
  p.fit_min_range_voxels = o.fit_min_range_voxels;
  p.profile_step_fraction = o.profile_step_fraction;
  return p;
}

// The settings of one level's deformation; each from the SegmentOptions field of the same name.
struct LevelOptions {
  SnakeOptions snake;
  FineLevelOptions fine;
  double range_edge_fraction = 0;
  double min_range_voxels = 0;
  double min_edge_voxels = 0;
  double profile_step_fraction = 0;
  bool undo_self_intersections = true;
};

LevelOptions level_options(const SegmentOptions& o) {
  LevelOptions l;
  l.snake = o.snake;
  l.fine = o.fine;
  l.range_edge_fraction = o.range_edge_fraction;
  l.min_range_voxels = o.min_range_voxels;
  l.min_edge_voxels = o.min_edge_voxels;
  l.profile_step_fraction = o.profile_step_fraction;
  l.undo_self_intersections = o.undo_self_intersections;
  return l;
}

// With profiles, a level finer than the image (mean edge below min_edge_voxels) is only
// synthesized when its profiles sit on the labels: they then sample the same voxels as its
// parent's, and on the real images its snake lost Dice. Profiles centred on the image's
// edges deform it, with their noise averaged over rings (FineLevelOptions).
// (The step-edge force fits sub-voxel steps; on synthetic volumes those levels help.)
bool finer_than_image(const LevelSearches& searches, int j, const LevelOptions& o, double image_voxel_mm) {
  return searches.profiles() && searches.edge_mm(j) < o.min_edge_voxels * image_voxel_mm;
}

// (Not far below the voxel either: the flag was set on the reference image's grid, and on
// a coarser image the profiles no longer resolve the level.)
bool deform_although_finer(const SnakeModel& model, const LevelSearches& searches, int j, const LevelOptions& o,
                           double image_voxel_mm) {
  return finer_than_image(searches, j, o, image_voxel_mm) && o.fine.deform_edge_centred &&
         model.appearance->levels[j].centre == ProfileCentre::edges &&
         searches.edge_mm(j) >= o.fine.min_edge_voxels * image_voxel_mm;
}

// Level j: S_j synthesized from the deformed S_{j−1} in V (j > 0), then deformed on its
// pyramid level and its self-intersections undone. V holds the deformed S_j on return.
LevelOutcome deform_level(int j, RowMatrixX3d& V, const SnakeModel& model, const LevelSearches& searches,
                          double image_voxel_mm, const RegionStats& stats, const LevelOptions& options) {
  const auto t_level = Clock::now();
  double synthesis_seconds = 0;
  if (j > 0) {
    const auto t_syn = Clock::now();
    V = model.synthesize(j - 1, V);
    synthesis_seconds = seconds_since(t_syn);
  }
  const double range = searches.range_mm(j, options.range_edge_fraction, options.min_range_voxels);
  const bool fine = deform_although_finer(model, searches, j, options, image_voxel_mm);
  const bool deform = fine || !finer_than_image(searches, j, options, image_voxel_mm);
  const SnakeOptions level_options =
      fine ? fine_level_snake_options(options.snake, options.fine, searches.edge_mm(j) / image_voxel_mm)
           : options.snake;
  const DeformableSurface snake(model.faces(j), model.levels[j], level_options);
  const auto [search, step] = searches.search(
      j, range, stats, &snake.rings(), fine ? options.fine.profile_step_fraction : options.profile_step_fraction);
  LevelOutcome out;
  out.level = j;
  out.pyramid_level = searches.pyramid_level(j);
  out.voxel_mm = searches.voxel_mm(j);
  out.range_mm = range;
  out.vertices = static_cast<int>(V.rows());
  out.synthesis_seconds = synthesis_seconds;
  const RowMatrixX3d V_level_start = V;
  SnakeLevelReport skipped;
  skipped.converged = true;
  out.snake = deform ? snake.run(V, search, step, range) : skipped;
  out.deformed = deform;
  out.offset_smoothing = deform ? level_options.offset_smoothing : 0;
  // The fold test inside the run is local; a surface can still pass through itself.
  // (A level only synthesized has not moved from its start: nothing to undo.)
  if (options.undo_self_intersections && out.deformed)
    out.rolled_back_vertices = undo_self_intersections(V, V_level_start, model.faces(j), snake.rings()).moved_vertices;
  out.seconds = seconds_since(t_level);
  out.surface = TriMesh{V, model.faces(j)};
  return out;
}

void check_snake_options(const std::string& at, const SnakeOptions& o) {
  for (const auto& [key, weight] : {std::pair<const char*, double>{"membrane_weight", o.membrane_weight},
                                    {"thin_plate_weight", o.thin_plate_weight},
                                    {"prior_weight", o.prior_weight},
                                    {"tangential_weight", o.tangential_weight},
                                    {"tolerance", o.tolerance}})
    require_at_least(at + key, weight, 0.0);
  require_at_least(at + "external_weight", o.external_weight, 0.0);
  require_positive(at + "time_step", o.time_step);
  require_positive(at + "max_step_fraction", o.max_step_fraction);
  for (const auto& [key, count] : {std::pair<const char*, int>{"offset_median", o.offset_median},
                                   {"offset_smoothing", o.offset_smoothing},
                                   {"min_iterations", o.min_iterations},
                                   {"patience", o.patience}})
    require_at_least(at + key, count, 0);
  require_in(at + "max_iterations", o.max_iterations, 0, kMaxSnakeIterations);
}

void check_search_options(const SegmentOptions& o) {
  for (const auto& [key, length] : {std::pair<const char*, double>{"range_edge_fraction", o.range_edge_fraction},
                                    {"coarse_range_edge_fraction", o.coarse_range_edge_fraction},
                                    {"step_voxels", o.step_voxels},
                                    {"profile_step_fraction", o.profile_step_fraction},
                                    {"window_voxels", o.window_voxels},
                                    {"edge_per_voxel", o.edge_per_voxel},
                                    {"cost_ring_full_weight_cost", o.cost_ring_full_weight_cost},
                                    {"fine.profile_step_fraction", o.fine.profile_step_fraction}})
    require_positive(key, length);
  for (const auto& [key, bound] : {std::pair<const char*, double>{"min_range_voxels", o.min_range_voxels},
                                   {"fit_min_range_voxels", o.fit_min_range_voxels},
                                   {"max_range_voxels", o.max_range_voxels},
                                   {"max_edge_cost", o.max_edge_cost},
                                   {"max_profile_cost", o.max_profile_cost},
                                   {"profile_distance_penalty", o.profile_distance_penalty},
                                   {"edge_distance_penalty", o.edge_distance_penalty},
                                   {"search_min_gain", o.search_min_gain},
                                   {"fit_tolerance_voxels", o.fit_tolerance_voxels},
                                   {"clean_step_max_residual", o.clean_step_max_residual},
                                   {"min_edge_voxels", o.min_edge_voxels},
                                   {"fine.min_edge_voxels", o.fine.min_edge_voxels},
                                   {"fine.offset_smoothing_voxels", o.fine.offset_smoothing_voxels}})
    require_at_least(key, bound, 0.0);
  require_in("cost_ring_weight", o.cost_ring_weight, 0.0, 1.0);
}

void check_registration_options(const RegistrationOptions& o) {
  const std::string at = "registration.itk.";
  for (const auto& [key, count] : {std::pair<const char*, int>{"samples_per_level", o.samples_per_level},
                                   {"evaluation_samples", o.evaluation_samples},
                                   {"convergence_window", o.convergence_window},
                                   {"threads", o.threads}})
    require_at_least(at + key, count, 1);
  require_in(at + "histogram_bins", o.histogram_bins, 5, 1024);
  require_at_least(at + "iterations_per_level", o.iterations_per_level, 0);
  require(!o.shrink_factors.empty() && o.shrink_factors.size() == o.smoothing_voxels.size(), at + "shrink_factors",
          "one factor per level, as many as smoothing_voxels");
  for (const int factor : o.shrink_factors) require_at_least(at + "shrink_factors[]", factor, 1);
  for (const double sigma : o.smoothing_voxels) require_at_least(at + "smoothing_voxels[]", sigma, 0.0);
  for (const auto& [key, length] : {std::pair<const char*, double>{"initial_step_voxels", o.initial_step_voxels},
                                    {"step_factor_per_level", o.step_factor_per_level},
                                    {"max_seconds", o.max_seconds}})
    require_positive(at + key, length);
  for (const auto& [key, bound] : {std::pair<const char*, double>{"min_step_voxels", o.min_step_voxels},
                                   {"min_relative_change", o.min_relative_change},
                                   {"moving_margin_fraction", o.moving_margin_fraction},
                                   {"moving_margin_voxels", o.moving_margin_voxels},
                                   {"rotation_radius_mm", o.rotation_radius_mm}})
    require_at_least(at + key, bound, 0.0);
  require_in(at + "relaxation", o.relaxation, 1e-3, 0.999);
}

void check_placement_options(const SegmentOptions& o) {
  for (const auto& [key, count] : {std::pair<const char*, int>{"fit.iterations", o.fit.iterations},
                                   {"fit.patience", o.fit.patience},
                                   {"fit_patience_after_registration", o.fit_patience_after_registration},
                                   {"fit_level", o.fit_level},
                                   {"fine.min_iterations", o.fine.min_iterations},
                                   {"fine.patience", o.fine.patience}})
    require_at_least(key, count, 0);
  require_in("fit.trim_fraction", o.fit.trim_fraction, 0.0, 0.9);
  require_at_least("moments.roi_margin", o.moments.roi_margin, 0.0);
  require_at_least("moments.min_axis_separation", o.moments.min_axis_separation, 0.0);
  require_in("moments.max_rotation_deg", o.moments.max_rotation_deg, 0.0, 180.0);
  require_positive("registration.min_scale", o.registration.min_scale);
  require_at_least("registration.max_scale", o.registration.max_scale, o.registration.min_scale);
  require_in("intensity_samples", o.intensity_samples, std::size_t{1024}, std::size_t{1} << 30);
  check_registration_options(o.registration.itk);
}

// How well the final surface matches the image, against how well the same search matches
// where the structure is not: a result that matches no better than chance found no structure
// (an erased one, an image of another body part, noise that buries the boundary).
void match_evidence(const LevelSearches& searches, const RegionStats& stats, const LevelOptions& options,
                    SegmentResult& result) {
  const auto last =
      std::find_if(result.levels.rbegin(), result.levels.rend(), [](const LevelOutcome& l) { return l.deformed; });
  if (last == result.levels.rend()) return;
  const int j = last->level;
  const RowMatrixX3d& V = last->surface.V;
  const RowMatrixX3i& F = last->surface.F;
  const double range = searches.range_mm(j, options.range_edge_fraction, options.min_range_voxels);
  const auto [search, step] = searches.search(j, range, stats, nullptr, options.profile_step_fraction);
  RowMatrixX3d N;
  vertex_normals(V, F, N);
  result.final_match_cost = search(V, N).costs.mean();
  const double radius = std::cbrt(3.0 * std::max(0.0, enclosed_volume(last->surface)) / (4.0 * M_PI));
  double chance = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {-1.0, 1.0}) {
      RowMatrixX3d moved = V;
      moved.col(axis).array() += sign * radius;
      chance += search(moved, N).costs.mean();
    }
  result.chance_match_cost = chance / 6.0;
}

}  // namespace

void check_options(const SegmentOptions& options) {
  check_snake_options("snake.", options.snake);
  check_search_options(options);
  check_placement_options(options);
}

SegmentationImage prepare_segmentation_image(const Volume& image, const SegmentOptions& options,
                                             const ProgressFn& progress) {
  const auto t_start = Clock::now();
  check_options(options);
  SegmentationImage prepared;
  StageClock clock(prepared.stage_seconds);
  report(progress, "normalize", 0.0);
  prepared.window = robust_intensity_window(image, 1.0, 99.0, options.intensity_samples);
  clock.end("normalize");
  report(progress, "pyramid", 0.0);
  prepared.pyramid = std::make_unique<NormalizedPyramid>(image, prepared.window);
  clock.end("pyramid");
  prepared.seconds = seconds_since(t_start);
  return prepared;
}

namespace {

// The normalized cross-correlation of the reference crop with pyramid level `level` of the
// image under `pose`.
double crop_correlation(const Volume& reference, const NormalizedPyramid& pyramid, int level, const Similarity& pose) {
  const VolumeSampler& sampler = pyramid.samplers[level];
  const Volume& grid = *pyramid.levels[level];
  double n = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (std::size_t k = 0; k < reference.size[2]; ++k)
    for (std::size_t j = 0; j < reference.size[1]; ++j)
      for (std::size_t i = 0; i < reference.size[0]; ++i) {
        const auto p =
            reference.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        const Eigen::Vector3d idx = sampler.to_index(pose.apply(Eigen::Vector3d(p[0], p[1], p[2])));
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside = inside && idx[a] >= 0 && idx[a] <= static_cast<double>(grid.size[a] - 1);
        if (!inside) continue;
        const double a = reference.at(i, j, k), b = sampler.value_at_index(idx);
        n += 1;
        sa += a;
        sb += b;
        saa += a * a;
        sbb += b * b;
        sab += a * b;
      }
  if (n < 8) return 0.0;
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  return va > 0 && vb > 0 ? (sab - sa * sb / n) / std::sqrt(va * vb) : 0.0;
}

// SegmentResult::registration_correlation.
double registration_correlation(const SnakeModel& model, const NormalizedPyramid& pyramid,
                                const ReferenceRegistration& registration) {
  // At twice the registration's scale, where the voxels' noise is averaged out of both.
  const int level = std::min<int>(registration.pyramid_level + 1, static_cast<int>(pyramid.levels.size()) - 1);
  const Volume& crop = *model.reference_image;
  const bool halve =
      level > registration.pyramid_level && crop.size[0] >= 16 && crop.size[1] >= 16 && crop.size[2] >= 16;
  return crop_correlation(halve ? downsample_by_two(crop) : crop, pyramid, level, registration.pose);
}

}  // namespace

std::optional<ReferenceRegistration> register_structures(const SegmentationImage& image, const SnakeModel& model,
                                                         const SegmentOptions& options, const ProgressFn& progress) {
  const InitMode init = resolve_init_mode(options.init, model);
  if (!registers(init)) return std::nullopt;
  report(progress, "register", 0.0);
  return register_model_reference(model, *image.pyramid, init, options.registration, options.moments);
}

SegmentResult segment(const SegmentationImage& image, const SnakeModel& model, const SegmentOptions& options,
                      const ProgressFn& progress, const ReferenceRegistration* registration) {
  const auto t_start = Clock::now();
  check_options(options);
  check_model(model, options.force);
  const int L = model.finest_level();
  const ForceChoice force = choose_force(model, options.force, options.clean_step_max_residual);
  SegmentResult result;
  result.force = force.profiles ? "profile" : "step_edge";
  result.profile_step_residual = force.step_residual;
  result.window = image.window;
  StageClock clock(result.stage_seconds);
  const NormalizedPyramid& pyramid = *image.pyramid;
  // Which pyramid level each mesh level runs on, and its search.
  const LevelSearches searches(model, pyramid, force.profiles, level_search_options(options));

  // Initialization of the coarse mesh.
  report(progress, "initialize", 0.0);
  const InitMode init = resolve_init_mode(options.init, model);
  if (registers(init)) {
    if (registration != nullptr) {
      result.registration = *registration;
    } else {
      result.registration = register_structures(image, model, options, progress);
      clock.end("register");
    }
  }
  InitialPose start = initial_pose(model, pyramid, searches, result.registration, init, initial_pose_options(options));
  result.init = start.init;
  result.initial_pose = start.pose;
  result.fit_iterations = start.fit_iterations;
  result.fit_start = start.fit_start;
  result.region = start.region;
  clock.end("initialize");

  // Coarse to fine.
  const auto t_levels = Clock::now();
  RowMatrixX3d V = std::move(start.coarse);
  const LevelOptions level = level_options(options);
  for (int j = 0; j <= L; ++j) {
    report(progress, "level " + std::to_string(j), static_cast<double>(j) / (L + 1));
    result.levels.push_back(deform_level(j, V, model, searches, pyramid.spacings[0], result.region, level));
  }
  result.stage_seconds.emplace_back("levels", seconds_since(t_levels));
  clock.restart();
  match_evidence(searches, result.region, level, result);
  if (result.registration && result.registration->accepted && model.reference_image)
    result.registration_correlation = registration_correlation(model, pyramid, *result.registration);
  clock.end("match_evidence");
  result.surface = TriMesh{V, model.faces(L)};
  result.compute_seconds = seconds_since(t_start);
  report(progress, "levels", 1.0);
  if (options.count_self_intersections) {
    report(progress, "self-intersections", 0.0);
    result.self_intersections = count_self_intersections(result.surface);
    clock.end("self_intersections");
  }
  return result;
}

SegmentResult segment(const Volume& image, const SnakeModel& model, const SegmentOptions& options,
                      const ProgressFn& progress) {
  check_options(options);
  check_model(model, options.force);
  const SegmentationImage prepared = prepare_segmentation_image(image, options, progress);
  SegmentResult result = segment(prepared, model, options, progress);
  // The image's stages first, as one run of the whole pipeline reports them.
  result.stage_seconds.insert(result.stage_seconds.begin(), prepared.stage_seconds.begin(),
                              prepared.stage_seconds.end());
  result.compute_seconds += prepared.seconds;
  return result;
}

nlohmann::json segment_report(const SegmentResult& r) {
  nlohmann::json j;
  j["force"] = r.force;
  if (std::isfinite(r.profile_step_residual)) j["profile_step_residual"] = r.profile_step_residual;
  j["compute_seconds"] = r.compute_seconds;
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, s] : r.stage_seconds) stages[name] = s;
  j["stage_seconds"] = stages;
  j["intensity_window"] = {{"low", r.window.low}, {"high", r.window.high}};
  j["region"] = {{"inside", r.region.inside}, {"outside", r.region.outside}};
  const Eigen::AngleAxisd aa(r.initial_pose.rotation);
  j["initial_pose"] = {
      {"scale", r.initial_pose.scale},
      {"rotation_deg", aa.angle() * 180.0 / M_PI},
      {"translation_mm",
       {r.initial_pose.translation.x(), r.initial_pose.translation.y(), r.initial_pose.translation.z()}},
      {"fit_iterations", r.fit_iterations}};
  if (!r.fit_start.empty()) j["initial_pose"]["fit_start"] = r.fit_start;
  j["init_used"] = to_string(r.init);
  if (r.registration) {
    const ReferenceRegistration& g = *r.registration;
    nlohmann::json reg{
        {"accepted", g.accepted}, {"ran", g.ran}, {"seconds", g.seconds}, {"pyramid_level", g.pyramid_level}};
    if (!g.accepted) {
      reg["rejection"] = g.rejection;
      reg["fallback"] = to_string(r.init);
    }
    if (!g.first_rejection.empty()) {
      // The start from the model's pose was rejected; this is the retry from the moments' shift.
      reg["first_rejection"] = g.first_rejection;
      reg["retry_start_translation_mm"] = g.retry_translation;
    }
    if (g.ran) {
      const RegistrationResult& x = g.result;
      reg["metric"] = x.metric;
      reg["initial_metric"] = x.initial_metric;
      reg["final_metric"] = x.final_metric;
      reg["valid_points"] = {x.valid_points_initial, x.valid_points_final};
      reg["iterations_per_level"] = x.iterations;
      reg["stop_condition"] = x.stop_condition;
      reg["levels_stopped_on_metric_change"] = x.converged_levels;
      reg["moving_crop_size"] = x.moving_crop_size;
      reg["edge_radius_mm"] = x.edge_radius_mm;
      reg["cpu_seconds"] = x.cpu_seconds;
      reg["seconds_setup"] = x.setup_seconds;
      reg["seconds_evaluation"] = x.evaluation_seconds;
      reg["seconds_optimization"] = x.optimization_seconds;
      reg["transform"] = {{"scale", x.transform.scale},
                          {"rotation_deg", x.transform.angle_deg},
                          {"versor_xyzw", x.transform.versor},
                          {"centre_mm", x.transform.centre},
                          {"translation_mm", x.transform.translation},
                          {"matrix", x.transform.matrix},
                          {"offset_mm", x.transform.offset}};
    }
    j["registration"] = reg;
  }
  nlohmann::json levels = nlohmann::json::array();
  bool all_converged = true;
  for (const LevelOutcome& l : r.levels) {
    all_converged = all_converged && l.snake.converged;
    levels.push_back({{"level", l.level},
                      {"vertices", l.vertices},
                      {"pyramid_level", l.pyramid_level},
                      {"voxel_mm", l.voxel_mm},
                      {"search_range_mm", l.range_mm},
                      {"iterations", l.snake.iterations},
                      {"converged", l.snake.converged},
                      {"seconds", l.seconds},
                      {"synthesis_seconds", l.synthesis_seconds},
                      {"energy", l.snake.energy},
                      {"external_energy", l.snake.external_energy},
                      {"internal_energy", l.snake.internal_energy},
                      {"mean_abs_offset_mm", l.snake.mean_abs_offset_mm},
                      {"rejected_steps", l.snake.rejected_steps},
                      {"rolled_back_vertices", l.rolled_back_vertices},
                      {"deformed", l.deformed},
                      {"offset_smoothing", l.offset_smoothing},
                      {"flipped_faces", l.snake.flipped_faces}});
  }
  j["levels"] = levels;
  j["converged"] = all_converged;
  j["final_energy"] = r.levels.empty() ? 0.0 : r.levels.back().snake.energy;
  j["self_intersections"] = r.self_intersections;
  j["vertices"] = r.surface.num_vertices();
  j["faces"] = r.surface.num_faces();
  return j;
}

}  // namespace mrsnake
