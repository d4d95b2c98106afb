#include "remesh/remesh.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <cmath>
#include <stdexcept>

#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/parallel.h"
#include "mesh/quality.h"
#include "remesh/base_mesh.h"
#include "remesh/domain.h"
#include "remesh/feature_snap.h"
#include "remesh/lift.h"
#include "remesh/lloyd.h"
#include "remesh/parameterization.h"
#include "remesh/shape_smoothing.h"
#include "remesh/simplify.h"
#include "remesh/sizing.h"
#include "remesh/surface_fit.h"
#include "remesh/remesh_options_json.h"
#include "remesh/triangle_repair.h"
#include "mesh/topology.h"

namespace mrsnake {
namespace {

using Clock = std::chrono::steady_clock;

/// Points measured per surface for the per-level distance statistics.
constexpr long long kMaxStatsSamples = 50000;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

const char* relax_name(RelaxMode mode) {
  switch (mode) {
    case RelaxMode::all_vertices: return "all_vertices";
    case RelaxMode::new_vertices_only: return "new_vertices_only";
    case RelaxMode::none: return "none";
  }
  return "?";
}

// Levels L and base size n0 so that F0·4^L is near the target, with F0 in [128, 512): a base
// of ~65-260 vertices spread over the shape absorbs its curvature, and since about half of
// them are irregular, they stay under 1% of the finest level's vertices.
void choose_resolution(int target_faces, int& levels, int& n0) {
  levels = 1;
  double f0 = target_faces / 4.0;
  while (f0 >= 512) {
    f0 /= 4;
    ++levels;
  }
  n0 = std::max(8, static_cast<int>(std::lround(f0 / 2 + 2)));
}

// Moves every row of X to its closest point on the locator's surface.
void reproject_onto(const SurfaceLocator& surface, RowMatrixX3d& X) {
  parallel_ranges(static_cast<std::size_t>(X.rows()), [&](std::size_t begin, std::size_t end) {
    for (auto v = static_cast<Eigen::Index>(begin); v < static_cast<Eigen::Index>(end); ++v)
      X.row(v) = surface.closest(X.row(v).transpose()).point.transpose();
  });
}

// Edge rings in about one base spacing: sqrt(input vertices / base vertices).
int base_spacing_rings(const TriMesh& surface, int n0) {
  return static_cast<int>(std::lround(std::sqrt(surface.num_vertices() / static_cast<double>(n0))));
}

// The wanted 3D point densities: `wanted` for the levels' relaxation, `base_density` for the
// base vertices' spread (both relative, >= 1 where nothing asks for more).
struct SizingFields {
  Eigen::VectorXd wanted;
  Eigen::VectorXd base_density;
};

// Curvature sizing. Where the bend bound (remesh/sizing.h) asks for more than half of the base
// vertices (thin tubes, many tips), the base grows 4x and the hierarchy loses a level, unless
// the levels were given or there is only one. The grown base is spread by the bound, and the
// relaxation's density raised by the same factor, so that the levels keep the base's grading.
SizingFields sizing_fields(const TriMesh& surface, const RemeshOptions& options, int& levels, int& n0) {
  const int n = surface.num_vertices();
  const Eigen::VectorXd kappa = vertex_curvature(surface, 8);
  SizingFields s{Eigen::VectorXd::Ones(n), Eigen::VectorXd::Ones(n)};
  if (const double mean = kappa.mean(); options.sizing.curvature_weight > 0 && mean > 0)
    // Capped, so that a few sharp spots (voxel steps of a marching-cubes surface) cannot pull
    // the spacing down so fast that triangle shapes suffer.
    s.wanted.array() +=
        options.sizing.curvature_weight * (kappa.array() / mean).pow(options.sizing.curvature_exponent).min(3.0);
  // Averaged over about a base spacing (sqrt(n / n0) edge rings): the base follows where the
  // surface bends at its own scale, not voxel steps.
  if (options.base.density_exponent > 0) {
    const int passes =
        options.base.density_smoothing < 0 ? base_spacing_rings(surface, n0) : options.base.density_smoothing;
    s.base_density = smooth_vertex_field(surface, s.wanted, passes).array().pow(options.base.density_exponent).matrix();
  }
  const double max_bend = options.base.max_bend;
  if (!(max_bend > 0)) return s;
  const Eigen::VectorXd bend_kappa = smooth_vertex_field(surface, kappa, base_spacing_rings(surface, n0));
  const double bound_points = bend_bound_points(surface, bend_kappa, max_bend);
  // Below that, the curvature sizing alone spreads the base: the bound moved base vertices
  // onto small bent features such as a bear's ears (Q mean -0.013 at 16k faces).
  if (options.levels != 0 || levels == 1 || bound_points <= 0.5 * n0) return s;
  // Once: a base 16x larger leaves a hierarchy of two levels with 10 % irregular vertices (the
  // octopus at 16k faces), and a marching-cubes staircase's voxel steps, which the curvature
  // measure sees as bends, ask for it too (the liver).
  n0 = 4 * n0 - 6;
  --levels;
  const Eigen::VectorXd grown_kappa = smooth_vertex_field(surface, kappa, base_spacing_rings(surface, n0));
  const Eigen::VectorXd bounded = bend_bounded_density(surface, s.base_density, grown_kappa, n0, max_bend);
  s.wanted = s.wanted.cwiseProduct(bounded.cwiseQuotient(s.base_density));
  s.base_density = bounded;
  return s;
}

}  // namespace

RemeshResult remesh(const TriMesh& input, const RemeshOptions& options) {
  if (options.levels < 0 || options.levels > 12) throw std::invalid_argument("levels must be in [0, 12]");
  if (options.levels == 0 && options.target_faces < 16) throw std::invalid_argument("target_faces must be at least 16");
  if (options.relaxation.lloyd_iterations < 0) throw std::invalid_argument("lloyd_iterations must be >= 0");
  if (options.relaxation.shape_iterations < 0) throw std::invalid_argument("shape_iterations must be >= 0");
  if (!(options.base.density_exponent >= 0 && options.base.density_exponent <= 4))
    throw std::invalid_argument("base_density_exponent must be in [0, 4]");
  if (!(options.base.max_bend >= 0)) throw std::invalid_argument("max_base_bend must be >= 0");
  if (options.base.density_smoothing < -1) throw std::invalid_argument("base_density_smoothing must be >= -1");
  if (options.snap.max_snaps < 0) throw std::invalid_argument("snap_tips must be >= 0");
  if (options.fit.rounds < 0) throw std::invalid_argument("fit_rounds must be >= 0");
  if (options.relaxation.surface_iterations < 0) throw std::invalid_argument("surface_relax_iterations must be >= 0");
  if (!(options.relaxation.surface_quality_floor >= 0 && options.relaxation.surface_quality_floor <= 1))
    throw std::invalid_argument("surface_relax_quality_floor must be in [0, 1]");
  if (!(options.sizing.curvature_exponent > 0 && options.sizing.curvature_exponent <= 4))
    throw std::invalid_argument("curvature_exponent must be in (0, 4]");
  if (options.repair.sweeps < 0) throw std::invalid_argument("repair_sweeps must be >= 0");
  if (!(options.repair.threshold > 0 && options.repair.threshold <= 1))
    throw std::invalid_argument("repair_threshold must be in (0, 1]");
  if (!(options.repair.error_tolerance >= 0)) throw std::invalid_argument("repair_error_tolerance must be >= 0");
  if (options.base.rim_min_triangles < 1 || options.base.rim_min_triangles > 3)
    throw std::invalid_argument("rim_min_triangles must be in [1, 3]");
  if (options.base_vertices < 6) throw std::invalid_argument("base_vertices must be at least 6");
  if (!(options.sizing.density_exponent >= 0 && options.sizing.density_exponent <= 8))
    throw std::invalid_argument("density_exponent must be in [0, 8]");
  if (input.empty()) throw InputError("the mesh has no faces");

  RemeshResult result;
  const auto simplify_start = Clock::now();
  const TriMesh original = remove_unreferenced_vertices(input);
  const TopologyReport topology = topology_report(original);
  require_disk_or_sphere(topology, "the input surface");
  int levels = options.levels, n0 = options.base_vertices;
  if (levels == 0) choose_resolution(options.target_faces, levels, n0);

  // A much finer input is simplified before the (costly) parameterization.
  TriMesh work = original;
  bool simplified = false;
  const double finest_faces = 2.0 * n0 * std::pow(4.0, levels);
  const double limit = std::max<double>(options.simplify.above_faces, 8 * finest_faces);
  if (options.simplify.above_faces > 0 && original.num_faces() > limit) {
    report(options.progress, "simplify", 0);
    TriMesh simplified_mesh = simplify_to_faces(original, static_cast<int>(limit));
    result.parameterization["simplify_seconds"] = seconds_since(simplify_start);
    const TopologyReport after = topology_report(simplified_mesh);
    if (after.is_disk() == topology.is_disk() && after.is_closed_genus0() == topology.is_closed_genus0()) {
      work = std::move(simplified_mesh);
      simplified = true;
    }
  }

  report(options.progress, "parameterize", 0);
  ParameterizationOptions param_options;
  param_options.sphere_map = options.sphere_map;
  Parameterization param;
  // The input's closest-point tree (for the reprojection, the fit and the report's distances)
  // is built on the other core while the map is solved.
  std::shared_ptr<SurfaceLocator> input_locator;
  // Like the snap and the repair, the fit is part of the full method only: --no-relax and
  // --strict stay the paper's baseline and exact method, with every vertex on the input.
  const int fit_rounds = options.relax == RelaxMode::all_vertices ? options.fit.rounds : 0;
  const bool needs_locator = simplified || fit_rounds > 0 || options.compute_stats || options.keep_input_locator;
  run_both_in_parallel([&] { param = parameterize(work, param_options); },
                       [&] {
                         if (needs_locator) input_locator = std::make_shared<SurfaceLocator>(original);
                       });
  result.input_locator = input_locator;
  const SurfaceLocator* reproject = simplified ? input_locator.get() : nullptr;
  result.domain = param.kind == DomainKind::sphere ? "sphere" : "disk";
  const nlohmann::json simplify_info = result.parameterization;
  result.parameterization = param.summary;
  if (simplify_info.is_object()) result.parameterization.update(simplify_info);
  result.parameterization["input_faces"] = original.num_faces();
  result.parameterization["parameterized_faces"] = work.num_faces();
  result.parameterization["seconds"] = seconds_since(simplify_start);  // input checks and simplification included

  const auto base_start = Clock::now();
  const DomainMesh domain_mesh(param.domain, param.surface.F);
  report(options.progress, "base mesh", 0);
  const SizingFields sizing = sizing_fields(param.surface, options, levels, n0);
  const Eigen::VectorXd& wanted = sizing.wanted;
  const Eigen::VectorXd& base_density = sizing.base_density;
  const BaseMesh base = build_base_mesh(param, n0, options.base.rim_min_triangles, &base_density);
  n0 = static_cast<int>(base.domain.rows());
  result.connectivity = subdivide_connectivity(base.faces, n0, levels);
  result.parameterization["base_vertices"] = n0;
  result.parameterization["base_faces"] = base.faces.rows();
  result.parameterization["base_surface_flips"] = base.surface_flips;
  result.parameterization["base_valence_flips"] = base.valence_flips;
  result.parameterization["base_dropped_rim_samples"] = base.dropped_rim_samples;

  DensityField density{&domain_mesh,
                       param.vertex_stretch.cwiseProduct(wanted).array().pow(options.sizing.density_exponent).matrix()};
  const DomainKind kind = param.kind;

  RowMatrixX3d U = base.domain;
  std::vector<int> hints(n0, 0);
  for (int i = 0; i < n0; ++i) hints[i] = domain_mesh.locate(U.row(i).transpose(), 0).face;

  LloydOptions lloyd;
  lloyd.iterations = options.relaxation.lloyd_iterations;
  double setup_seconds = seconds_since(base_start);

  for (int j = 0; j <= levels; ++j) {
    const auto start = Clock::now();
    const RowMatrixX3i& F = result.connectivity.faces[j];
    if (j > 0) {
      U = midpoint_refine(result.connectivity, j - 1, U);
      const std::vector<bool> boundary = kind == DomainKind::disk ? boundary_vertices(F, static_cast<int>(U.rows()))
                                                                  : std::vector<bool>(U.rows(), false);
      const int previous = result.connectivity.vertex_count(j - 1);
      hints.resize(U.rows());
      for (int v = previous; v < U.rows(); ++v) {
        U.row(v) = project_to_domain(kind, U.row(v).transpose(), boundary[v]).transpose();
        hints[v] = hints[result.connectivity.parents(v)[0]];
      }
    }
    LloydStats relax_stats;
    RemeshLevel level;
    int shape_moves = 0;
    if (options.relax == RelaxMode::all_vertices && options.relaxation.shape_iterations > 0) {
      // Lloyd (sizes) and shape smoothing (angles) pull against each other; interleaving
      // them in rounds balances the two better than running one after the other.
      const int rounds = options.relaxation.shape_iterations;
      ShapeSmoothingOptions shape;
      shape.iterations = 1;
      shape.move_rim = options.relaxation.smooth_rim;
      lloyd.first_movable = 0;
      for (int round = 0; round < rounds; ++round) {
        lloyd.iterations = options.relaxation.lloyd_iterations * (round + 1) / rounds -
                           options.relaxation.lloyd_iterations * round / rounds;
        const LloydStats s = constrained_lloyd(kind, F, density, U, hints, lloyd);
        relax_stats.moves += s.moves;
        relax_stats.shortened_moves += s.shortened_moves;
        relax_stats.rejected_moves += s.rejected_moves;
        relax_stats.mean_shift = s.mean_shift;
        level.positions = lift_to_surface(domain_mesh, param.surface.V, U, hints);
        shape_moves += smooth_shapes_in_domain(kind, F, domain_mesh, param.surface.V, U, level.positions, hints, shape);
      }
    } else {
      const bool relax =
          options.relax == RelaxMode::all_vertices || (options.relax == RelaxMode::new_vertices_only && j > 0);
      if (relax) {
        lloyd.iterations = options.relaxation.lloyd_iterations;
        lloyd.first_movable =
            options.relax == RelaxMode::new_vertices_only ? result.connectivity.vertex_count(j - 1) : 0;
        relax_stats = constrained_lloyd(kind, F, density, U, hints, lloyd);
      }
      level.positions = lift_to_surface(domain_mesh, param.surface.V, U, hints);
    }
    // Sizes last: the area-centroid target evens out what the Lloyd step in D left uneven
    // where the stretch changes fast; its quality floor keeps the shapes just made.
    if (options.relax == RelaxMode::all_vertices && options.relaxation.surface_iterations > 0) {
      ShapeSmoothingOptions surface;
      surface.iterations = options.relaxation.surface_iterations;
      surface.target = SmoothingTarget::area_centroid;
      surface.surface_density = &wanted;
      surface.move_rim = options.relaxation.smooth_rim;
      surface.quality_floor = options.relaxation.surface_quality_floor;
      shape_moves += smooth_shapes_in_domain(kind, F, domain_mesh, param.surface.V, U, level.positions, hints, surface);
    }
    int snapped = 0;
    std::vector<bool> snapped_mask;
    if (options.relax == RelaxMode::all_vertices && options.snap.max_snaps > 0 && j == levels) {
      snapped = snap_to_input_tips(kind, F, domain_mesh, param.surface.V, U, level.positions, hints, options.snap,
                                   &snapped_mask);
    }
    // Onto the original input before the repair, so that the repair sees (and keeps) the
    // final triangles: the projection onto a marching-cubes staircase shears a few of them.
    const bool project_first = reproject && options.repair.after_reprojection;
    if (project_first) reproject_onto(*reproject, level.positions);
    TriangleRepairStats repair;
    if (options.relax == RelaxMode::all_vertices && options.repair.sweeps > 0 &&
        (options.repair.coarse_levels || j == levels)) {
      TriangleRepairOptions repair_options;
      repair_options.sweeps = options.repair.sweeps;
      repair_options.threshold = options.repair.threshold;
      // Not against a staircase: its voxel steps, not the triangles, make the guard's distances.
      repair_options.guard_surface_error = options.repair.guard_finest && j == levels && !project_first;
      repair_options.error_tolerance = options.repair.error_tolerance;
      if (project_first) repair_options.project_onto = reproject;
      if (snapped > 0) repair_options.fixed = &snapped_mask;  // the tips stay exactly on the input
      repair = repair_worst_triangles(kind, F, domain_mesh, param.surface.V, U, level.positions, hints, repair_options);
    }
    report(options.progress, "level " + std::to_string(j), 0.5);
    if (reproject && !project_first) reproject_onto(*reproject, level.positions);
    const int flipped = count_flipped(U, F);
    if (flipped > 0)
      throw AlgorithmError("level " + std::to_string(j) + " has " + std::to_string(flipped) +
                           " flipped triangles in the domain; the surface cannot be remeshed well");
    SurfaceFitStats fit;
    if (fit_rounds > 0 && j == levels) {
      // Against the original input. A disk's rim stays on the input's rim, and the snapped
      // tips stay exactly on the input's tips (they were kept for lowering the largest distance).
      SurfaceFitOptions fit_options = options.fit;
      fit_options.rounds = fit_rounds;
      std::vector<bool> fixed =
          kind == DomainKind::disk ? boundary_vertices(F, static_cast<int>(U.rows())) : std::vector<bool>{};
      if (snapped > 0) {
        if (fixed.empty()) fixed.assign(snapped_mask.size(), false);
        for (std::size_t v = 0; v < snapped_mask.size(); ++v) fixed[v] = fixed[v] || snapped_mask[v];
      }
      fit = fit_to_surface(F, level.positions, *input_locator, fit_options, fixed);
    }
    level.domain_positions = U;
    level.flipped_triangles = flipped;
    level.seconds = seconds_since(start) + (j == 0 ? setup_seconds : 0.0);
    nlohmann::json& s = level.stats;
    s["level"] = j;
    s["vertices"] = level.positions.rows();
    s["faces"] = F.rows();
    s["flipped_triangles"] = flipped;
    s["seconds"] = level.seconds;
    s["lloyd_shortened_moves"] = relax_stats.shortened_moves;
    s["lloyd_rejected_moves"] = relax_stats.rejected_moves;
    s["lloyd_last_mean_shift"] = relax_stats.mean_shift;
    s["shape_moves"] = shape_moves;
    s["repair_moves"] = repair.moves;
    s["snapped_vertices"] = snapped;
    if (fit_rounds > 0 && j == levels)
      s["fit"] = {{"rms_before_mm", fit.rms_before},          {"rms_after_mm", fit.rms_after},
                  {"mean_offset_mm", fit.mean_offset},        {"max_offset_mm", fit.max_offset},
                  {"clamped_vertices", fit.clamped_vertices}, {"held_vertices", fit.held_vertices}};
    if (repair.moves > 0) {
      s["repair_q_min_before"] = repair.q_min_before;
      s["repair_q_min_after"] = repair.q_min_after;
    }
    if (options.compute_stats) {
      const TriMesh mesh{level.positions, F};
      s["quality"] = mesh_quality(mesh);
      // Metro-style sampling of both surfaces, then a uniform random subset of at most 50k
      // points per surface: a marching-cubes input has hundreds of thousands of faces, and
      // 50k points estimate the RMS to well under 1 % (the Hausdorff distance is the largest
      // over the subset).
      DistanceOptions sampling;
      sampling.samples_per_face =
          std::clamp(static_cast<int>(5e5 / std::max(original.num_faces(), mesh.num_faces())), 1, 10);
      sampling.max_samples_per_mesh = kMaxStatsSamples;
      s["distance"] = surface_distance(mesh, original, *input_locator, sampling);
      s["distance"]["samples_per_face"] = sampling.samples_per_face;
      s["distance"]["max_samples_per_mesh"] = sampling.max_samples_per_mesh;
    }
    result.levels.push_back(std::move(level));
    report(options.progress, "level " + std::to_string(j), 1.0);
  }
  return result;
}

nlohmann::json remesh_report(const RemeshResult& result, const RemeshOptions& options) {
  nlohmann::json j;
  j["domain"] = result.domain;
  j["levels"] = result.connectivity.levels();
  // The options as `mrsnake remesh --config` reads them: the run can be repeated exactly.
  j["options"] = options;
  // The method's main settings at the top level too (the report page shows some of them).
  j["relax"] = relax_name(options.relax);
  j["density_exponent"] = options.sizing.density_exponent;
  j["curvature_weight"] = options.sizing.curvature_weight;
  j["curvature_exponent"] = options.sizing.curvature_exponent;
  j["surface_relax_iterations"] = options.relax == RelaxMode::all_vertices ? options.relaxation.surface_iterations : 0;
  j["surface_relax_quality_floor"] = options.relaxation.surface_quality_floor;
  j["smooth_rim"] = options.relaxation.smooth_rim;
  j["base_density_exponent"] = options.base.density_exponent;
  j["repair_after_reprojection"] = options.repair.after_reprojection;
  j["snap_tips"] = options.relax == RelaxMode::all_vertices ? options.snap.max_snaps : 0;
  j["fit_rounds"] = options.relax == RelaxMode::all_vertices ? options.fit.rounds : 0;
  j["base_density_smoothing"] = options.base.density_smoothing;
  j["max_base_bend"] = options.base.max_bend;
  j["lloyd_iterations"] = options.relaxation.lloyd_iterations;
  j["shape_iterations"] = options.relax == RelaxMode::all_vertices ? options.relaxation.shape_iterations : 0;
  j["repair_sweeps"] = options.relax == RelaxMode::all_vertices ? options.repair.sweeps : 0;
  j["repair_threshold"] = options.repair.threshold;
  j["repair_coarse_levels"] = options.repair.coarse_levels;
  j["repair_guard_finest"] = options.repair.guard_finest;
  j["repair_error_tolerance"] = options.repair.error_tolerance;
  j["rim_min_triangles"] = options.base.rim_min_triangles;
  j["parameterization"] = result.parameterization;
  double total = result.parameterization.value("seconds", 0.0);
  nlohmann::json per_level = nlohmann::json::array();
  for (const auto& level : result.levels) {
    per_level.push_back(level.stats);
    total += level.seconds;
  }
  j["per_level"] = per_level;
  j["seconds"] = total;
  return j;
}

}  // namespace mrsnake
