#include "snake/segment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "mesh/distance.h"
#include "mesh/errors.h"
#include "snake/image_pyramid.h"
#include "snake/sampler.h"

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

SnakeOptions fine_level_snake_options(const SegmentOptions& options, double edge_voxels) {
  SnakeOptions o = options.snake;
  // k passes of the 7-point average on a regular mesh of edge e: a variance of k·(3/7)·e².
  const double sigma_in_edges = options.fine.offset_smoothing_voxels / edge_voxels;
  const double passes = sigma_in_edges * sigma_in_edges / (3.0 / 7.0);
  if (std::isfinite(passes))
    o.offset_smoothing = std::max(o.offset_smoothing, static_cast<int>(std::lround(std::min(passes, 1000.0))));
  o.min_iterations = std::min(o.min_iterations, options.fine.min_iterations);
  o.patience = std::min(o.patience, options.fine.patience);
  return o;
}

SegmentResult segment(const Volume& image, const SnakeModel& model, const SegmentOptions& options,
                      const ProgressFn& progress) {
  const auto t_start = Clock::now();
  const int L = model.finest_level();
  if (L < 0 || static_cast<int>(model.levels.size()) != L + 1 || !model.synthesize)
    throw InputError("the model has no usable levels; rebuild it with mrsnake build-model");
  // A stored appearance must match the levels before the profiles are used, and before the
  // automatic choice reads them.
  if (model.appearance && options.force != ForceMode::step_edge) {
    if (static_cast<int>(model.appearance->levels.size()) != L + 1)
      throw InputError("the model's appearance does not match its levels; rebuild the model");
    for (int j = 0; j <= L; ++j)
      if (model.appearance->levels[j].profiles.rows() != model.levels[j].rows())
        throw InputError("the model's appearance does not match its levels; rebuild the model");
  }
  if (options.force == ForceMode::profile && !model.appearance)
    throw InputError("--force profile needs a model built with an appearance (build-model --image)");
  // Automatic: the profiles, unless what they learned is a clean step between two
  // intensities; there the step-edge force, which fits the step at sub-voxel precision on
  // every level, is both more accurate and faster (synthetic blobs at 128³: Dice
  // 0.9941–0.9956 with profiles, 0.9956–0.9971 with the step).
  const double step_residual = model.appearance && options.force == ForceMode::automatic
                                   ? profile_step_residual(*model.appearance, model.connectivity.faces)
                                   : std::numeric_limits<double>::infinity();
  const bool use_profiles =
      options.force == ForceMode::profile || (options.force == ForceMode::automatic && model.appearance.has_value() &&
                                              !(step_residual <= options.clean_step_max_residual));
  SegmentResult result;
  result.force = use_profiles ? "profile" : "step_edge";
  result.profile_step_residual = step_residual;
  auto stage_timer = Clock::now();
  const auto end_stage = [&](const std::string& name) {
    result.stage_seconds.emplace_back(name, seconds_since(stage_timer));
    stage_timer = Clock::now();
  };

  // Image side: robust normalization and the pyramid.
  report(progress, "normalize", 0.0);
  // The full-resolution image is not copied: its sampler normalizes on the fly, and only
  // the (8× smaller and below) pyramid levels are stored normalized.
  result.window = robust_intensity_window(image, 1.0, 99.0, std::max<std::size_t>(1024, options.intensity_samples));
  const double norm_scale = 1.0 / (result.window.high - result.window.low);
  const double norm_offset = -result.window.low * norm_scale;
  end_stage("normalize");
  report(progress, "pyramid", 0.0);
  std::vector<Volume> owned;  // levels 1.. (level 0 too when the image is too small for a pyramid)
  owned.reserve(8);
  std::vector<const Volume*> pyramid{&image};
  while (pyramid.size() < 8) {
    bool ok = true;
    for (int a = 0; a < 3; ++a)
      if (pyramid.back()->size[a] > 1 && (pyramid.back()->size[a] + 1) / 2 < 16) ok = false;
    if (!ok) break;
    owned.push_back(downsample_by_two(*pyramid.back()));
    if (pyramid.size() == 1) apply_intensity_window(owned.back(), result.window);
    pyramid.push_back(&owned.back());
  }
  if (pyramid.size() == 1) {  // a tiny image: normalize a copy
    owned.push_back(image);
    apply_intensity_window(owned.back(), result.window);
    pyramid[0] = &owned.back();
  }
  const bool level0_raw = pyramid[0] == &image;
  std::vector<double> spacings;
  for (const Volume* v : pyramid) spacings.push_back(v->max_spacing());
  std::vector<VolumeSampler> samplers;
  samplers.reserve(pyramid.size());
  for (std::size_t k = 0; k < pyramid.size(); ++k)
    samplers.emplace_back(*pyramid[k], k == 0 && level0_raw ? norm_scale : 1.0,
                          k == 0 && level0_raw ? norm_offset : 0.0);
  end_stage("pyramid");

  // Which pyramid level each mesh level runs on, and its search.
  std::vector<int> pyr(L + 1);
  std::vector<double> edges(L + 1);
  for (int j = 0; j <= L; ++j) {
    edges[j] = mean_edge_length(model.levels[j], model.faces(j));
    pyr[j] = pyramid_level_for_edge(edges[j], spacings, options.edge_per_voxel);
  }
  // With profiles, a level finer than the image (mean edge below min_edge_voxels) is only
  // synthesized when its profiles sit on the labels: they then sample the same voxels as its
  // parent's, and on the real images its snake lost Dice. Profiles centred on the image's
  // edges deform it, with their noise averaged over rings (FineLevelOptions).
  // (The step-edge force fits sub-voxel steps; on synthetic volumes those levels help.)
  const auto finer_than_image = [&](int j) { return use_profiles && edges[j] < options.min_edge_voxels * spacings[0]; };
  const auto deform_although_finer = [&](int j) {
    // (Not far below the voxel either: the flag was set on the reference image's grid, and on
    // a coarser image the profiles no longer resolve the level.)
    return finer_than_image(j) && options.fine.deform_edge_centred &&
           model.appearance->levels[j].centre == ProfileCentre::edges &&
           edges[j] >= options.fine.min_edge_voxels * spacings[0];
  };
  // profile_step_fraction: of the profile spacing, for the profile search.
  const auto search_for = [&](int j, double range_mm, RegionStats stats, const VertexRings* rings,
                              double profile_step_fraction) -> std::pair<ExternalSearch, double> {
    const int p = pyr[j];
    const VolumeSampler* sampler = &samplers[p];
    NormalSearchOptions so;
    so.range_mm = range_mm;
    so.min_gain = options.search_min_gain;
    so.rings = rings;
    so.ring_weight = options.cost_ring_weight;
    so.ring_full_weight_cost = options.cost_ring_full_weight_cost;
    if (use_profiles) {
      const LevelAppearance* la = &model.appearance->levels[j];
      so.step_mm = profile_step_fraction * la->spacing_mm;
      so.max_cost = options.max_profile_cost;
      so.distance_penalty = options.profile_distance_penalty;
      return {[sampler, la, so](const RowMatrixX3d& V, const RowMatrixX3d& N) {
                return search_profiles(*sampler, V, N, la->profiles, la->spacing_mm, so);
              },
              so.step_mm};
    }
    so.step_mm = options.step_voxels * spacings[p];
    so.window_mm = options.window_voxels * spacings[p];
    so.max_cost = options.max_edge_cost;
    so.distance_penalty = options.edge_distance_penalty;
    return {[sampler, stats, so](const RowMatrixX3d& V, const RowMatrixX3d& N) {
              return search_step_edges(*sampler, V, N, stats, so);
            },
            so.step_mm};
  };
  const auto range_for = [&](int j, double fraction, double min_voxels) {
    double r = std::max(min_voxels * spacings[pyr[j]], fraction * edges[j]);
    if (options.max_range_voxels > 0) r = std::min(r, options.max_range_voxels * spacings[pyr[j]]);
    return r;
  };

  // Initialization of the coarse mesh.
  report(progress, "initialize", 0.0);
  RowMatrixX3d V = model.levels[0];
  Similarity pose;
  InitMode init = options.init;
  if (init == InitMode::automatic)
    init = model.reference_image ? InitMode::registration_and_fit : InitMode::moments_and_fit;
  const auto moments_pose = [&] {
    // Moments on a coarse level (noise averaged out), of a mid-resolution model level.
    const int p = std::min<int>(2, static_cast<int>(pyramid.size()) - 1);
    const int jm = std::min(L, 2);
    MomentsOptions mo = options.moments;
    if (model.appearance && std::isnan(mo.threshold)) {
      // Towards the inside class: a neighbour of intermediate intensity stays out.
      mo.threshold =
          model.appearance->region.outside + 0.7 * (model.appearance->region.inside - model.appearance->region.outside);
      mo.bright_object = model.appearance->region.inside > model.appearance->region.outside;
    }
    return moments_alignment(*pyramid[p], TriMesh{model.levels[jm], model.faces(jm)}, mo);
  };
  if (init == InitMode::registration || init == InitMode::registration_and_fit) {
    // Register the model's reference image to this one, from the model's pose; if that is
    // rejected, once more from the moments' translation; then the moments route.
    if (!model.reference_image)
      throw InputError("--init " + to_string(init) + " needs a model with a reference image (build-model --image)");
    report(progress, "register", 0.0);
    const double s0 = level0_raw ? norm_scale : 1.0, o0 = level0_raw ? norm_offset : 0.0;
    result.registration = register_reference(*model.reference_image, pyramid, s0, o0, options.registration);
    if (!result.registration->accepted) {
      Eigen::Vector3d shift = Eigen::Vector3d::Zero();
      bool have_shift = false;
      try {
        const Eigen::Vector3d c = model.levels[0].colwise().mean().transpose();
        shift = moments_pose().apply(c) - c;
        have_shift = true;
      } catch (const AlgorithmError&) {  // nothing to align to: no second start
      }
      if (have_shift && shift.norm() > 0.5 * model.reference_image->max_spacing()) {
        const double first_seconds = result.registration->seconds;
        const std::string first_rejection = result.registration->rejection;
        result.registration = register_reference(*model.reference_image, pyramid, s0, o0, options.registration, shift);
        result.registration->seconds += first_seconds;
        result.registration->first_rejection = first_rejection;
        for (int a = 0; a < 3; ++a) result.registration->retry_translation[a] = shift[a];
      }
    }
    end_stage("register");
    if (result.registration->accepted) {
      pose = result.registration->pose;
      V = pose.apply(V);
    } else {
      init = init == InitMode::registration ? InitMode::moments : InitMode::moments_and_fit;
    }
  }
  const bool registered = result.registration && result.registration->accepted;
  result.init = init;
  if (init == InitMode::moments || init == InitMode::moments_and_fit) {
    pose = moments_pose();
    V = pose.apply(V);
  }
  // Start hypotheses for the fit: the pose found, and the same without its rotation about
  // the centroid (principal axes can mislead on elongated or curved shapes). After moments,
  // the model's own pose too: a neighbour of the organ's intensity (the liver's kidney, the
  // hippocampus' grey matter) drags the threshold's moments far off, while scans of a study
  // are usually framed like the reference. The fit with the lowest search cost wins (every
  // start is scored with the same statistics).
  const bool from_moments = init == InitMode::moments || init == InitMode::moments_and_fit;
  std::vector<std::pair<Similarity, std::string>> starts{{pose, registered     ? "registration"
                                                                : from_moments ? "moments"
                                                                               : "model pose"}};
  if (!registered && pose.rotation_angle_deg() > 1.0) {
    const Eigen::Vector3d c = model.levels[0].colwise().mean().transpose();
    Similarity unrotated = pose;
    unrotated.rotation.setIdentity();
    unrotated.translation = pose.apply(c) - pose.scale * c;
    starts.emplace_back(unrotated, "moments without rotation");
  }
  if (init == InitMode::moments_and_fit) starts.emplace_back(Similarity{}, "model pose");
  RegionStats stats;
  RowMatrixX3d N;
  const auto estimate_stats = [&](const RowMatrixX3d& W) {
    // Two classes near the surface, at full resolution: independent of how well the
    // surface is placed, so a poor start cannot teach the force the wrong contrast.
    std::array<long, 3> lo{}, hi{};
    mesh_index_box(*pyramid[0], W, 0.15, lo, hi);
    ThresholdClasses c = threshold_classes(*pyramid[0], *pyramid[std::min<std::size_t>(1, pyramid.size() - 1)], lo, hi);
    if (level0_raw) {  // the medians come from the raw full-resolution image
      c.upper_median = norm_scale * c.upper_median + norm_offset;
      c.lower_median = norm_scale * c.lower_median + norm_offset;
    }
    const bool bright = !model.appearance || model.appearance->region.inside >= model.appearance->region.outside;
    return bright ? RegionStats{c.upper_median, c.lower_median} : RegionStats{c.lower_median, c.upper_median};
  };
  if (use_profiles) {
    stats = model.appearance->region;
  } else {
    stats = estimate_stats(V);
  }
  if (init == InitMode::moments_and_fit || init == InitMode::fit || init == InitMode::registration_and_fit) {
    // Fit the whole mesh of a level with enough vertices to carry the shape; synthesis
    // follows a similarity, so the pose found there applies to S_0 as well.
    const int jf = std::min(L, options.fit_level);
    // (One similarity moves the whole mesh here: every vertex keeps its own evidence.)
    const double fit_range = range_for(jf, options.coarse_range_edge_fraction, options.fit_min_range_voxels);
    const auto [search, step] = search_for(jf, fit_range, stats, nullptr, options.profile_step_fraction);
    (void)step;
    TargetFitOptions fit_options = options.fit;
    fit_options.tolerance_mm = options.fit_tolerance_voxels * spacings[0];
    if (registered) fit_options.patience = options.fit_patience_after_registration;
    double best_cost = std::numeric_limits<double>::infinity();
    for (const auto& [start, start_name] : starts) {
      RowMatrixX3d W = start.apply(model.levels[jf]);
      int iterations = 0;
      const Similarity fitted = fit_similarity_to_targets(W, model.faces(jf), search, fit_options, &iterations);
      vertex_normals(W, model.faces(jf), N);
      const double cost = search(W, N).costs.mean();
      if (cost < best_cost) {
        best_cost = cost;
        pose = fitted.compose(start);
        result.fit_iterations = iterations;
        result.fit_start = start_name;
      }
    }
    V = pose.apply(model.levels[0]);
    if (!use_profiles) stats = estimate_stats(pose.apply(model.levels[L]));
  }
  if (!use_profiles && !(std::abs(stats.inside - stats.outside) > 1e-6))
    throw AlgorithmError("no contrast between the inside and the outside of the initial surface; check the pose");
  result.initial_pose = pose;
  result.region = stats;
  end_stage("initialize");

  // Coarse to fine.
  const auto t_levels = Clock::now();
  for (int j = 0; j <= L; ++j) {
    const auto t_level = Clock::now();
    report(progress, "level " + std::to_string(j), static_cast<double>(j) / (L + 1));
    double synthesis_seconds = 0;
    if (j > 0) {
      const auto t_syn = Clock::now();
      V = model.synthesize(j - 1, V);
      synthesis_seconds = seconds_since(t_syn);
    }
    const double range = range_for(j, options.range_edge_fraction, options.min_range_voxels);
    const bool fine = deform_although_finer(j);
    const bool deform = fine || !finer_than_image(j);
    const SnakeOptions level_options = fine ? fine_level_snake_options(options, edges[j] / spacings[0]) : options.snake;
    const DeformableSurface snake(model.faces(j), model.levels[j], level_options);
    const auto [search, step] = search_for(j, range, stats, &snake.rings(),
                                           fine ? options.fine.profile_step_fraction : options.profile_step_fraction);
    LevelOutcome out;
    out.level = j;
    out.pyramid_level = pyr[j];
    out.voxel_mm = spacings[pyr[j]];
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
      out.rolled_back_vertices =
          undo_self_intersections(V, V_level_start, model.faces(j), snake.rings()).moved_vertices;
    out.seconds = seconds_since(t_level);
    out.surface = TriMesh{V, model.faces(j)};
    result.levels.push_back(std::move(out));
  }
  result.stage_seconds.emplace_back("levels", seconds_since(t_levels));
  stage_timer = Clock::now();
  result.surface = TriMesh{V, model.faces(L)};
  result.compute_seconds = seconds_since(t_start);
  report(progress, "levels", 1.0);
  if (options.count_self_intersections) {
    report(progress, "self-intersections", 0.0);
    result.self_intersections = count_self_intersections(result.surface);
    end_stage("self_intersections");
  }
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
