#include "remesh/remesh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <future>
#include <iomanip>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/option_checks.h"
#include "mesh/parallel.h"
#include "mesh/quality.h"
#include "remesh/base_mesh.h"
#include "remesh/base_route.h"
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
#include "remesh/remesh_stages.h"
#include "remesh/triangle_repair.h"
#include "mesh/topology.h"

namespace mrsnake {
namespace {

using namespace remesh_stages;

void check_resolution_and_relaxation(const RemeshOptions& o, const std::string& at) {
  require_in(at + "levels", o.levels, 0, 12);
  if (o.levels == 0) require_at_least(at + "target_faces", o.target_faces, 16);
  require_at_least(at + "base_vertices", o.base_vertices, 6);
  require_at_least(at + "simplify.above_faces", o.simplify.above_faces, 0);
  require_in(at + "simplify.sliver_share", o.simplify.sliver_share, 0.0, 1.0);
  require_at_least(at + "relaxation.lloyd_iterations", o.relaxation.lloyd_iterations, 0);
  require_at_least(at + "relaxation.shape_iterations", o.relaxation.shape_iterations, 0);
  require_at_least(at + "relaxation.guarded_shape_iterations", o.relaxation.guarded_shape_iterations, 0);
  require_at_least(at + "relaxation.surface_iterations", o.relaxation.surface_iterations, 0);
  require_in(at + "relaxation.surface_quality_floor", o.relaxation.surface_quality_floor, 0.0, 1.0);
  // The paper's exact method relaxes new vertices in one domain chart; the base mesh's levels
  // have no such mode.
  if (o.domain == ParameterDomain::base_mesh && o.relax == RelaxMode::new_vertices_only)
    throw OptionsError("the option " + at +
                       "relax new_vertices_only (--strict, the paper's exact method) runs on "
                       "the sphere domain only; drop it or the domain base_mesh");
}

void check_sizing_and_finish(const RemeshOptions& o, const std::string& at) {
  require_at_least(at + "sizing.curvature_weight", o.sizing.curvature_weight, 0.0);
  require_in(at + "sizing.density_exponent", o.sizing.density_exponent, 0.0, 8.0);
  require_positive(at + "sizing.curvature_exponent", o.sizing.curvature_exponent);
  require_in(at + "sizing.curvature_exponent", o.sizing.curvature_exponent, 0.0, 4.0);
  require_in(at + "base.density_exponent", o.base.density_exponent, 0.0, 4.0);
  require_at_least(at + "base.max_bend", o.base.max_bend, 0.0);
  require_at_least(at + "base.density_smoothing", o.base.density_smoothing, -1);
  require_in(at + "base.rim_min_triangles", o.base.rim_min_triangles, 1, 3);
  require_in(at + "base.one_chart_flip_margin_deg", o.base.one_chart_flip_margin_deg, 0.0, 180.0);
  require_at_least(at + "snap.max_snaps", o.snap.max_snaps, 0);
  require_at_least(at + "snap.min_distance", o.snap.min_distance, 0.0);
  require_at_least(at + "snap.min_gain", o.snap.min_gain, 0.0);
  require_in(at + "snap.min_quality", o.snap.min_quality, 0.0, 1.0);
  require_in(at + "snap.min_share_of_largest", o.snap.min_share_of_largest, 0.0, 1.0);
  require_in(at + "snap.min_angle_deg", o.snap.min_angle_deg, 0.0, 60.0);
  require_at_least(at + "fit.rounds", o.fit.rounds, 0);
  require_positive(at + "fit.regularization", o.fit.regularization);
  require_at_least(at + "fit.max_offset", o.fit.max_offset, 0.0);
  require_positive(at + "fit.max_sample_distance", o.fit.max_sample_distance);
  require_in(at + "fit.quality_floor", o.fit.quality_floor, 0.0, 1.0);
  require_at_least(at + "untangle.max_rounds", o.untangle.max_rounds, 0);
  require_at_least(at + "repair.sweeps", o.repair.sweeps, 0);
  require_positive(at + "repair.threshold", o.repair.threshold);
  require_in(at + "repair.threshold", o.repair.threshold, 0.0, 1.0);
  require_at_least(at + "repair.error_tolerance", o.repair.error_tolerance, 0.0);
}

}  // namespace

void check_options(const RemeshOptions& options, const std::string& at) {
  check_resolution_and_relaxation(options, at);
  check_sizing_and_finish(options, at);
}

namespace {

// The parameterization of the prepared input, and the original's closest-point tree (for the
// reprojection, the fit and the report's distances) built on the other core meanwhile.
struct MappedInput {
  Parameterization param;
  std::shared_ptr<SurfaceLocator> locator;  ///< null unless asked for
};

MappedInput map_onto_domain(const PreparedInput& input, SphereMap sphere_map, bool needs_locator,
                            const ProgressFn& progress, const HierarchicalFallbackFn& on_hierarchical_fallback) {
  report(progress, "parameterize", 0);
  ParameterizationOptions param_options;
  param_options.sphere_map = sphere_map;
  param_options.on_hierarchical_fallback = on_hierarchical_fallback;
  MappedInput m;
  m.locator = map_beside_locator(input, needs_locator, [&] { m.param = parameterize(input.work, param_options); });
  return m;
}

nlohmann::json parameterization_summary(const MappedInput& mapped, const PreparedInput& input,
                                        Clock::time_point start) {
  nlohmann::json summary = mapped.param.summary;
  if (input.simplify_info.is_object()) summary.update(input.simplify_info);
  summary["input_faces"] = input.original.num_faces();
  summary["parameterized_faces"] = input.work.num_faces();
  summary["seconds"] = seconds_since(start);  // input checks and any stand-in for the input included
  return summary;
}

// The base mesh T0 in D, spread by the sizing's base density; sets n0 to its vertex count, and
// the result's connectivity and the base's keys of its parameterization summary.
BaseMesh build_base(const Parameterization& param, const BaseMeshOptions& options, const SizingFields& sizing,
                    Resolution& resolution, RemeshResult& result) {
  BaseMesh base = build_base_mesh(param, resolution.base_vertices, options.rim_min_triangles, &sizing.base_density,
                                  options.one_chart_flip_margin_deg);
  const int n0 = static_cast<int>(base.domain.rows());
  resolution.base_vertices = n0;
  result.connectivity = subdivide_connectivity(base.faces, n0, resolution.levels);
  result.parameterization["base_vertices"] = n0;
  result.parameterization["base_faces"] = base.faces.rows();
  result.parameterization["base_surface_flips"] = base.surface_flips;
  result.parameterization["base_valence_flips"] = base.valence_flips;
  result.parameterization["base_dropped_rim_samples"] = base.dropped_rim_samples;
  return base;
}

// The Lloyd density in D: (stretch·wanted)^density_exponent per vertex of the domain mesh.
DensityField lloyd_density(const DomainMesh& domain_mesh, const Parameterization& param, const SizingFields& sizing,
                           const SizingOptions& options) {
  return DensityField{&domain_mesh,
                      param.vertex_stretch.cwiseProduct(sizing.wanted).array().pow(options.density_exponent).matrix()};
}

// The level being built, in D: positions, and a face of the domain mesh under each vertex.
struct DomainLayout {
  RowMatrixX3d U;
  std::vector<int> hints;
};

DomainLayout base_layout(const BaseMesh& base, const DomainMesh& domain_mesh) {
  DomainLayout layout{base.domain, std::vector<int>(base.domain.rows(), 0)};
  for (int i = 0; i < static_cast<int>(base.domain.rows()); ++i)
    layout.hints[i] = domain_mesh.locate(layout.U.row(i).transpose(), 0).face;
  return layout;
}

// What every level is built on.
struct LevelContext {
  DomainKind kind;
  const DomainMesh& domain_mesh;    ///< the parameterized surface in D
  const RowMatrixX3d& surface_V;    ///< and in 3D
  const DensityField& density;      ///< the Lloyd density
  const Eigen::VectorXd& wanted;    ///< the wanted 3D density per vertex of the parameterized surface
  const TriMesh& original;          ///< the input without unreferenced vertices
  const SurfaceLocator* locator;    ///< its closest points, if built
  const SurfaceLocator* reproject;  ///< the same, when a stand-in for the input was parameterized; else null
  const SubdivisionConnectivity& connectivity;
  int fit_rounds;  ///< 0 unless the full method fits the finest level
};

// Level j > 0: the 1:4 split of level j-1 in D, new vertices projected onto D.
void split_level(const SubdivisionConnectivity& c, int j, DomainKind kind, DomainLayout& layout) {
  RowMatrixX3d& U = layout.U;
  U = midpoint_refine(c, j - 1, U);
  const std::vector<bool> boundary = kind == DomainKind::disk
                                         ? boundary_vertices(c.faces[j], static_cast<int>(U.rows()))
                                         : std::vector<bool>(U.rows(), false);
  const int previous = c.vertex_count(j - 1);
  layout.hints.resize(U.rows());
  for (int v = previous; v < U.rows(); ++v) {
    U.row(v) = project_to_domain(kind, U.row(v).transpose(), boundary[v]).transpose();
    layout.hints[v] = layout.hints[c.parents(v)[0]];
  }
}

struct RelaxStats {
  LloydStats lloyd;
  int shape_moves = 0;
};

// Lloyd steps in D, with the full method interleaved with shape smoothing in rounds (sizes and
// angles pull against each other; rounds balance the two better than one after the other),
// then the lift X.
RelaxStats relax_in_domain(const LevelContext& ctx, RelaxMode mode, const RelaxationOptions& options, int j,
                           DomainLayout& layout, RowMatrixX3d& X) {
  const RowMatrixX3i& F = ctx.connectivity.faces[j];
  RelaxStats stats;
  LloydOptions lloyd;
  if (mode == RelaxMode::all_vertices && options.shape_iterations > 0) {
    const int rounds = options.shape_iterations;
    ShapeSmoothingOptions shape;
    shape.iterations = 1;
    shape.move_rim = options.smooth_rim;
    lloyd.first_movable = 0;
    for (int round = 0; round < rounds; ++round) {
      lloyd.iterations = options.lloyd_iterations * (round + 1) / rounds - options.lloyd_iterations * round / rounds;
      const LloydStats s = constrained_lloyd(ctx.kind, F, ctx.density, layout.U, layout.hints, lloyd);
      stats.lloyd.moves += s.moves;
      stats.lloyd.shortened_moves += s.shortened_moves;
      stats.lloyd.rejected_moves += s.rejected_moves;
      stats.lloyd.mean_shift = s.mean_shift;
      X = lift_to_surface(ctx.domain_mesh, ctx.surface_V, layout.U, layout.hints);
      stats.shape_moves +=
          smooth_shapes_in_domain(ctx.kind, F, ctx.domain_mesh, ctx.surface_V, layout.U, X, layout.hints, shape);
    }
    return stats;
  }
  if (mode == RelaxMode::all_vertices || (mode == RelaxMode::new_vertices_only && j > 0)) {
    lloyd.iterations = options.lloyd_iterations;
    lloyd.first_movable = mode == RelaxMode::new_vertices_only ? ctx.connectivity.vertex_count(j - 1) : 0;
    stats.lloyd = constrained_lloyd(ctx.kind, F, ctx.density, layout.U, layout.hints, lloyd);
  }
  X = lift_to_surface(ctx.domain_mesh, ctx.surface_V, layout.U, layout.hints);
  return stats;
}

// Sizes last: the area-centroid target evens out what the Lloyd step in D left uneven where the
// stretch changes fast; its quality floor keeps the shapes just made. Returns the moves.
int relax_on_surface(const LevelContext& ctx, const RelaxationOptions& options, int j, DomainLayout& layout,
                     RowMatrixX3d& X) {
  ShapeSmoothingOptions surface;
  surface.iterations = options.surface_iterations;
  surface.target = SmoothingTarget::area_centroid;
  surface.surface_density = &ctx.wanted;
  surface.move_rim = options.smooth_rim;
  surface.quality_floor = options.surface_quality_floor;
  return smooth_shapes_in_domain(ctx.kind, ctx.connectivity.faces[j], ctx.domain_mesh, ctx.surface_V, layout.U, X,
                                 layout.hints, surface);
}

// The finest level's vertices snapped onto the input's tips; `snapped` marks them.
int snap_tips(const LevelContext& ctx, const FeatureSnapOptions& options, int j, DomainLayout& layout, RowMatrixX3d& X,
              std::vector<bool>& snapped) {
  return snap_to_input_tips(ctx.kind, ctx.connectivity.faces[j], ctx.domain_mesh, ctx.surface_V, layout.U, X,
                            layout.hints, options, &snapped);
}

// The repair of the worst triangles; on the original input when the level was projected onto it
// first. Snapped tips (`snapped`, if any) stay exactly on the input.
TriangleRepairStats repair_level(const LevelContext& ctx, const RepairOptions& options, int j, bool project_first,
                                 const std::vector<bool>* snapped, DomainLayout& layout, RowMatrixX3d& X) {
  TriangleRepairOptions repair;
  repair.sweeps = options.sweeps;
  repair.threshold = options.threshold;
  // Not against a staircase: its voxel steps, not the triangles, make the guard's distances.
  repair.guard_surface_error = options.guard_finest && j == ctx.connectivity.levels() && !project_first;
  repair.error_tolerance = options.error_tolerance;
  if (project_first) repair.project_onto = ctx.reproject;
  repair.fixed = snapped;
  return repair_worst_triangles(ctx.kind, ctx.connectivity.faces[j], ctx.domain_mesh, ctx.surface_V, layout.U, X,
                                layout.hints, repair);
}

// The fit of the finest level to the original input. A disk's rim stays on the input's rim, and
// the snapped tips stay exactly on the input's tips (they were kept for lowering the largest
// distance).
SurfaceFitStats fit_finest(const LevelContext& ctx, const SurfaceFitOptions& options, int j,
                           const std::vector<bool>& snapped, RowMatrixX3d& X) {
  const RowMatrixX3i& F = ctx.connectivity.faces[j];
  SurfaceFitOptions fit = options;
  fit.rounds = ctx.fit_rounds;
  return fit_to_surface(F, X, *ctx.locator, fit, held_vertices(F, static_cast<int>(X.rows()), snapped));
}

// What the stages did, for RemeshLevel::stats.
struct LevelRecord {
  RelaxStats relax;
  int snapped = 0;
  TriangleRepairStats repair;
  bool fitted = false;
  SurfaceFitStats fit;
  nlohmann::json untangle;                                  ///< null unless the finest level had crossing face pairs
  nlohmann::json stage_seconds = nlohmann::json::object();  ///< per stage that ran
};

nlohmann::json level_stats(int j, const RemeshLevel& level, const RowMatrixX3i& F, const LevelRecord& r) {
  nlohmann::json s;
  s["level"] = j;
  s["vertices"] = level.positions.rows();
  s["faces"] = F.rows();
  s["flipped_triangles"] = level.flipped_triangles;
  s["seconds"] = level.seconds;
  s["lloyd_shortened_moves"] = r.relax.lloyd.shortened_moves;
  s["lloyd_rejected_moves"] = r.relax.lloyd.rejected_moves;
  s["lloyd_last_mean_shift"] = r.relax.lloyd.mean_shift;
  s["shape_moves"] = r.relax.shape_moves;
  s["repair_moves"] = r.repair.moves;
  s["snapped_vertices"] = r.snapped;
  s["stage_seconds"] = r.stage_seconds;
  if (r.fitted)
    s["fit"] = {{"rms_before_mm", r.fit.rms_before},          {"rms_after_mm", r.fit.rms_after},
                {"mean_offset_mm", r.fit.mean_offset},        {"max_offset_mm", r.fit.max_offset},
                {"clamped_vertices", r.fit.clamped_vertices}, {"held_vertices", r.fit.held_vertices}};
  if (!r.untangle.is_null()) s["untangle"] = r.untangle;
  if (r.repair.moves > 0) {
    s["repair_q_min_before"] = r.repair.q_min_before;
    s["repair_q_min_after"] = r.repair.q_min_after;
  }
  return s;
}

// Level j: split (j > 0), relax in D and on the surface; with the full method, snap the tips
// (finest level), repair, fit and untangle (finest level); the projection onto the original
// input when a stand-in for it (a simplification, a sliver remeshing) was parameterized.
// `extra_seconds` is added to the level's time.
// \throw AlgorithmError if a triangle is flipped in D.
RemeshLevel build_level(const LevelContext& ctx, const RemeshOptions& options, int j, DomainLayout& layout,
                        double extra_seconds) {
  const auto start = Clock::now();
  const RowMatrixX3i& F = ctx.connectivity.faces[j];
  const bool finest = j == ctx.connectivity.levels();
  const bool full = options.relax == RelaxMode::all_vertices;
  RemeshLevel level;
  LevelRecord r;
  nlohmann::json& stage = r.stage_seconds;
  if (j > 0) timed(stage, "split", [&] { split_level(ctx.connectivity, j, ctx.kind, layout); });
  r.relax = timed(stage, "relax_in_domain",
                  [&] { return relax_in_domain(ctx, options.relax, options.relaxation, j, layout, level.positions); });
  if (full && options.relaxation.surface_iterations > 0)
    r.relax.shape_moves += timed(stage, "relax_on_surface",
                                 [&] { return relax_on_surface(ctx, options.relaxation, j, layout, level.positions); });
  std::vector<bool> snapped;
  if (full && options.snap.max_snaps > 0 && finest)
    r.snapped = timed(stage, "snap", [&] { return snap_tips(ctx, options.snap, j, layout, level.positions, snapped); });
  // Onto the original input before the repair, so that the repair sees (and keeps) the final
  // triangles: the projection onto a marching-cubes staircase shears a few of them.
  const bool project_first = ctx.reproject && options.repair.after_reprojection;
  if (project_first) reproject_onto(*ctx.reproject, level.positions);
  if (full && options.repair.sweeps > 0 && (options.repair.coarse_levels || finest))
    r.repair = timed(stage, "repair", [&] {
      return repair_level(ctx, options.repair, j, project_first, r.snapped > 0 ? &snapped : nullptr, layout,
                          level.positions);
    });
  report(options.progress, "level " + std::to_string(j), 0.5);
  if (ctx.reproject && !project_first) reproject_onto(*ctx.reproject, level.positions);
  const int flipped = count_flipped(layout.U, F);
  if (flipped > 0)
    throw AlgorithmError("level " + std::to_string(j) + " has " + std::to_string(flipped) +
                         " flipped triangles in the domain; the surface cannot be remeshed well");
  r.fitted = ctx.fit_rounds > 0 && finest;
  if (r.fitted) r.fit = timed(stage, "fit", [&] { return fit_finest(ctx, options.fit, j, snapped, level.positions); });
  if (full && finest && options.untangle.max_rounds > 0)
    r.untangle =
        timed(stage, "untangle", [&] { return untangle_finest(F, level.positions, options.untangle, snapped); });
  level.domain_positions = layout.U;
  level.flipped_triangles = flipped;
  level.seconds = seconds_since(start) + extra_seconds;
  level.stats = level_stats(j, level, F, r);
  if (options.compute_stats) measure_level(ctx.original, *ctx.locator, F, level);
  return level;
}

// The sphere route: the input mapped onto the unit sphere or disk, the base in D, the levels.
// `on_hierarchical_fallback` is called when the one-chart sphere map fails (and may stop the route there).
// `prepared` is prepare_input(input, options, ...); the report's seconds count from `start`.
RemeshResult remesh_on_sphere(const PreparedInput& prepared, const RemeshOptions& options, Clock::time_point start,
                              const HierarchicalFallbackFn& on_hierarchical_fallback = {}) {
  RemeshResult result;
  Resolution resolution = initial_resolution(options);
  // Like the snap and the repair, the fit is part of the full method only: --no-relax and
  // --strict stay the paper's baseline and exact method, with every vertex on the input.
  const int fit_rounds = options.relax == RelaxMode::all_vertices ? options.fit.rounds : 0;
  const bool needs_locator =
      prepared.simplified || fit_rounds > 0 || options.compute_stats || options.keep_input_locator;
  const MappedInput mapped =
      map_onto_domain(prepared, options.sphere_map, needs_locator, options.progress, on_hierarchical_fallback);
  const Parameterization& param = mapped.param;
  result.input_locator = mapped.locator;
  result.domain = param.kind == DomainKind::sphere ? "sphere" : "disk";
  result.parameterization = parameterization_summary(mapped, prepared, start);

  const auto base_start = Clock::now();
  const DomainMesh domain_mesh(param.domain, param.surface.F);
  report(options.progress, "base mesh", 0);
  const SizingFields sizing =
      sizing_fields(param.surface, options.sizing, options.base, options.levels != 0, resolution);
  const BaseMesh base = build_base(param, options.base, sizing, resolution, result);
  const DensityField density = lloyd_density(domain_mesh, param, sizing, options.sizing);
  DomainLayout layout = base_layout(base, domain_mesh);
  const LevelContext context{param.kind,           domain_mesh,
                             param.surface.V,      density,
                             sizing.wanted,        prepared.original,
                             mapped.locator.get(), prepared.simplified ? mapped.locator.get() : nullptr,
                             result.connectivity,  fit_rounds};
  const double setup_seconds = seconds_since(base_start);

  for (int j = 0; j <= resolution.levels; ++j) {
    result.levels.push_back(build_level(context, options, j, layout, j == 0 ? setup_seconds : 0.0));
    report(options.progress, "level " + std::to_string(j), 1.0);
  }
  return result;
}

RemeshResult remesh_on_sphere(const TriMesh& input, const RemeshOptions& options) {
  const auto start = Clock::now();
  return remesh_on_sphere(prepare_input(input, options, start), options, start);
}

// What the automatic domain compares of two finest levels.
struct FinestLevelScore {
  int self_intersections = 0;
  double q_mean = 0;
};

FinestLevelScore finest_level_score(const RemeshResult& r) {
  const TriMesh finest = r.mesh(static_cast<int>(r.levels.size()) - 1);
  return {count_self_intersections(finest), mesh_quality(finest).q_mean};
}

nlohmann::json score_json(const FinestLevelScore& s) {
  return {{"self_intersections", s.self_intersections}, {"q_mean", s.q_mean}};
}

// The hierarchical map stood in for the one-chart sphere map, which failed: the shape has
// protrusions that one chart squeezes, and the base mesh may hold it better.
bool on_the_hierarchical_map(const RemeshResult& r) {
  return r.domain == "sphere" && r.parameterization.value("sphere_map", "") == "hierarchical";
}

// The options with every progress stage named after `prefix` (the second domain's stages
// repeat the first's names) and reported under `lock`: the two domains report from two threads.
RemeshOptions with_locked_progress(const RemeshOptions& options, const std::shared_ptr<std::mutex>& lock,
                                   const std::string& prefix) {
  RemeshOptions locked = options;
  if (options.progress)
    locked.progress = [progress = options.progress, lock, prefix](const std::string& stage, double fraction) {
      const std::lock_guard<std::mutex> hold(*lock);
      progress(prefix + stage, fraction);
    };
  return locked;
}

// The base-mesh route's result and score, or why it failed.
struct BaseOutcome {
  std::optional<RemeshResult> result;
  FinestLevelScore score;
  std::string error;
};

// The base-mesh route, run on another thread from the moment the sphere route's one-chart map
// fails, beside the hierarchical map and the sphere's levels: the automatic domain then takes
// about the longer route's time instead of both routes' sum. Its failure, for any reason, is
// kept, not thrown. Destroyed while running (the sphere route threw), it waits for the end.
// `prepared` must outlive it: its thread reads it (declare it first).
class BaseRouteBeside {
 public:
  BaseRouteBeside(const PreparedInput& prepared, RemeshOptions options)
      : prepared_(prepared), options_(std::move(options)) {}
  BaseRouteBeside(const BaseRouteBeside&) = delete;  // the running thread holds `this`
  BaseRouteBeside& operator=(const BaseRouteBeside&) = delete;

  // Starts the route on another thread (once); without a thread, outcome() runs it.
  void start() {
    if (running_.valid()) return;
    try {
      running_ = std::async(std::launch::async, [this] {
        const ThreadAtWork at_work;  // beside the sphere route: the two fill two cores
        return run();
      });
    } catch (...) {  // std::system_error (no thread) or std::bad_alloc
    }
  }

  // The route's outcome; the calling thread leaves its core to the route while it waits.
  BaseOutcome outcome() {
    if (!running_.valid()) return run();
    const ThreadWaiting waiting;
    return running_.get();
  }

 private:
  BaseOutcome run() const {
    BaseOutcome out;
    try {
      // From a copy, which the route refines. Its seconds start here: the shared preparation
      // counts with the sphere route's (the domain choice's seconds), where the base mesh wins.
      out.result = remesh_on_base_mesh(prepared_, options_, Clock::now());
      out.score = finest_level_score(*out.result);
    } catch (const std::exception& e) {
      out.result.reset();
      out.error = e.what();
    }
    return out;
  }

  const PreparedInput& prepared_;  // read by both routes, changed by neither
  const RemeshOptions options_;
  std::future<BaseOutcome> running_;
};

// A result's own time: its parameterization's and its levels'.
double own_seconds(const RemeshResult& r) {
  double seconds = r.parameterization.value("seconds", 0.0);
  for (const auto& level : r.levels) seconds += level.seconds;
  return seconds;
}

// `kept` with its parameterization's "domain_choice": `choice` (the domains' scores or errors),
// the domain kept, the rule that kept it, and the "seconds": the wall time since `start` less
// the kept result's own (the other domain, where it did not overlap, and the comparison), so
// that remesh_report's total is the wall time up to the choice.
RemeshResult with_domain_choice(RemeshResult kept, nlohmann::json choice, const std::string& rule,
                                Clock::time_point start) {
  choice["chosen"] = kept.domain;
  choice["rule"] = rule;
  choice["seconds"] = std::max(0.0, seconds_since(start) - own_seconds(kept));
  kept.parameterization["domain_choice"] = std::move(choice);
  return kept;
}

// Both domains' finest levels compared: fewer self-intersections, then the higher mean
// quality. If the base mesh failed, the sphere's valid result is kept and the failure
// recorded.
RemeshResult better_of_both_domains(RemeshResult on_sphere, BaseOutcome on_base, Clock::time_point start) {
  const FinestLevelScore sphere_score = finest_level_score(on_sphere);
  nlohmann::json choice = {{"sphere", score_json(sphere_score)},
                           {"sphere_map_fallback", on_sphere.parameterization.value("sphere_map_fallback", "")}};
  RemeshResult chosen;
  if (on_base.result) {
    choice["base_mesh"] = score_json(on_base.score);
    const bool base_wins = on_base.score.self_intersections != sphere_score.self_intersections
                               ? on_base.score.self_intersections < sphere_score.self_intersections
                               : on_base.score.q_mean > sphere_score.q_mean;
    chosen = base_wins ? std::move(*on_base.result) : std::move(on_sphere);
  } else {
    choice["base_mesh"] = {{"error", on_base.error}};
    chosen = std::move(on_sphere);
  }
  return with_domain_choice(std::move(chosen), std::move(choice),
                            "fewer self-intersections at the finest level, then the higher mean quality", start);
}

// The sphere route failed (an AlgorithmError, `sphere_failure`): the base mesh's result, when it
// has one, with the failure recorded, else the sphere's failure rethrown.
RemeshResult base_instead_of_sphere(BaseOutcome on_base, const std::exception_ptr& sphere_failure,
                                    Clock::time_point start) {
  if (!on_base.result) std::rethrow_exception(sphere_failure);
  std::string sphere_error;
  try {
    std::rethrow_exception(sphere_failure);
  } catch (const std::exception& e) {
    sphere_error = e.what();
  }
  nlohmann::json choice = {{"sphere", {{"error", sphere_error}}}, {"base_mesh", score_json(on_base.score)}};
  return with_domain_choice(std::move(*on_base.result), std::move(choice), "the sphere's route failed", start);
}

// The one-chart map squeezed the shape (`reason`), so the sphere route stopped there: the base
// mesh's result, which holds protrusions; if it failed, the sphere route on the hierarchical
// map after all (straight away: the one-chart map is known to fail), with the base mesh's
// failure recorded.
RemeshResult base_alone_or_hierarchical_sphere(BaseOutcome on_base, const std::string& reason,
                                               const PreparedInput& prepared, RemeshOptions sphere_options,
                                               Clock::time_point start) {
  nlohmann::json choice = {{"sphere_map_fallback", reason}};
  if (on_base.result) {
    choice["sphere"] = {{"skipped", "the one-chart map's squeeze: protrusions, which the base mesh holds"}};
    choice["base_mesh"] = score_json(on_base.score);
    return with_domain_choice(std::move(*on_base.result), std::move(choice),
                              "the one-chart map squeezed the shape: the base mesh alone", start);
  }
  sphere_options.sphere_map = SphereMap::hierarchical;
  RemeshResult on_sphere = remesh_on_sphere(prepared, sphere_options, Clock::now());
  choice["sphere"] = score_json(finest_level_score(on_sphere));
  choice["base_mesh"] = {{"error", on_base.error}};
  return with_domain_choice(std::move(on_sphere), std::move(choice), "the base mesh's route failed", start);
}

// Quality and distance to the input of every level, as build_level measures them.
// \pre result.input_locator was kept (RemeshOptions::keep_input_locator).
void measure_levels(const TriMesh& input, RemeshResult& result) {
  const TriMesh original = remove_unreferenced_vertices(input);
  for (int j = 0; j < static_cast<int>(result.levels.size()); ++j)
    measure_level(original, *result.input_locator, result.connectivity.faces[j], result.levels[j]);
}

// `options` with the steps that did not run for `result` set to off, for the report's summary:
// --strict and --no-relax have no shape smoothing, surface relaxation (so no rim sliding), snap,
// fit, untangling or repair; the sphere and the disk have no guarded shape sweeps; and the
// base-mesh domain has no Lloyd step in D (it relaxes by shape smoothing and area centroids) and
// repairs its finest level only, before any projection onto the original (remesh/base_route.cpp).
RemeshOptions options_as_run(const RemeshResult& result, RemeshOptions options) {
  if (options.relax != RelaxMode::all_vertices) {
    options.relaxation.shape_iterations = 0;
    options.relaxation.guarded_shape_iterations = 0;
    options.relaxation.surface_iterations = 0;
    options.relaxation.smooth_rim = false;
    options.snap.max_snaps = 0;
    options.fit.rounds = 0;
    options.untangle.max_rounds = 0;
    options.repair.sweeps = 0;
  }
  if (result.domain != "base_mesh") options.relaxation.guarded_shape_iterations = 0;
  if (result.domain == "base_mesh") {
    options.relaxation.lloyd_iterations = 0;
    options.repair.coarse_levels = false;
    options.repair.after_reprojection = false;
  }
  return options;
}

}  // namespace

RemeshResult remesh(const TriMesh& input, const RemeshOptions& options) {
  check_options(options);
  if (input.empty()) throw InputError("the mesh has no faces");
  if (options.domain == ParameterDomain::base_mesh) return remesh_on_base_mesh(input, options);
  // The paper's variants (--strict, --no-relax) stay on the sphere, as the paper builds them,
  // and so does a sphere map the caller chose.
  if (options.domain == ParameterDomain::sphere || options.relax != RelaxMode::all_vertices ||
      options.sphere_map != SphereMap::automatic)
    return remesh_on_sphere(input, options);
  const auto start = Clock::now();
  // The levels are measured once the kept domain is known: the other domain's would be thrown
  // away. Both domains' times then leave the measuring out, as a single domain's do.
  RemeshOptions unmeasured = options;
  unmeasured.compute_stats = false;
  unmeasured.keep_input_locator = options.keep_input_locator || options.compute_stats;
  const auto progress_lock = std::make_shared<std::mutex>();
  const RemeshOptions sphere_options = with_locked_progress(unmeasured, progress_lock, "");
  // Both routes start from the same prepared input (a simplification or a remeshing of large
  // slivers, on some inputs the longest stage of all): prepared once.
  const PreparedInput prepared = prepare_input(input, sphere_options, start);
  BaseRouteBeside on_base(prepared, with_locked_progress(unmeasured, progress_lock, "base-mesh domain: "));
  std::optional<std::string> squeeze;  // why the sphere route stopped at its one-chart map, if it did
  const auto on_fallback = [&](const OneChartFailure& failure) {
    on_base.start();
    // A squeeze means protrusions: on every such input measured, the base mesh's finest level
    // was the better (docs/remesh.md, "The automatic domain"), so the hierarchical map is not
    // built beside it.
    if (options.base_mesh_alone_when_squeezed && failure.squeezed()) squeeze = failure.reason();
    return !squeeze;
  };
  std::optional<RemeshResult> on_sphere;
  std::exception_ptr sphere_failure;
  try {
    on_sphere = remesh_on_sphere(prepared, sphere_options, start, on_fallback);
  } catch (const AlgorithmError&) {  // the base mesh may still hold the shape (built now, if not begun)
    sphere_failure = std::current_exception();
  }
  RemeshResult kept;
  if (squeeze)
    kept = base_alone_or_hierarchical_sphere(on_base.outcome(), *squeeze, prepared, sphere_options, start);
  else if (!on_sphere)
    kept = base_instead_of_sphere(on_base.outcome(), sphere_failure, start);
  else if (on_the_hierarchical_map(*on_sphere))
    kept = better_of_both_domains(std::move(*on_sphere), on_base.outcome(), start);
  else
    kept = std::move(*on_sphere);
  if (options.compute_stats) measure_levels(input, kept);
  return kept;
}

std::optional<std::vector<std::string>> finest_level_doubts(const RemeshResult& result) {
  if (result.levels.empty() || !result.levels.back().stats.contains("distance")) return std::nullopt;
  const nlohmann::json& finest = result.levels.back().stats;
  std::vector<std::string> doubts;
  const int pairs = finest.at("self_intersections").get<int>();
  if (pairs > 0) doubts.push_back("the finest level passes through itself at " + std::to_string(pairs) + " face pairs");
  const double hausdorff = finest.at("distance").at("hausdorff_mm").get<double>();
  const double edge = finest.at("quality").at("edge_length_mean").get<double>();
  if (hausdorff > edge) {
    std::ostringstream s;
    s << "the finest level misses part of the input by more than its mean edge length (Hausdorff distance "
      << std::fixed << std::setprecision(2) << hausdorff / edge << " mean edges, " << std::defaultfloat
      << finest.at("distance").at("hausdorff_pct").get<double>()
      << " % of the diagonal), probably a sharp tip or corner, or a part thinner than an edge, cut off";
    doubts.push_back(s.str());
  }
  return doubts;
}

nlohmann::json remesh_report(const RemeshResult& result, const RemeshOptions& options) {
  nlohmann::json j;
  j["domain"] = result.domain;
  j["levels"] = result.connectivity.levels();
  // The options as `mrsnake remesh --config` reads them: the run can be repeated exactly.
  j["options"] = options;
  // The method's main settings at the top level too, as they ran (the report page shows some).
  const RemeshOptions ran = options_as_run(result, options);
  j["relax"] = ran.relax;
  j["density_exponent"] = ran.sizing.density_exponent;
  j["curvature_weight"] = ran.sizing.curvature_weight;
  j["curvature_exponent"] = ran.sizing.curvature_exponent;
  j["surface_relax_iterations"] = ran.relaxation.surface_iterations;
  j["surface_relax_quality_floor"] = ran.relaxation.surface_quality_floor;
  j["smooth_rim"] = ran.relaxation.smooth_rim;
  j["base_density_exponent"] = ran.base.density_exponent;
  j["repair_after_reprojection"] = ran.repair.after_reprojection;
  j["snap_tips"] = ran.snap.max_snaps;
  j["fit_rounds"] = ran.fit.rounds;
  j["untangle_max_rounds"] = ran.untangle.max_rounds;
  j["base_density_smoothing"] = ran.base.density_smoothing;
  j["max_base_bend"] = ran.base.max_bend;
  j["lloyd_iterations"] = ran.relaxation.lloyd_iterations;
  j["shape_iterations"] = ran.relaxation.shape_iterations;
  j["guarded_shape_iterations"] = ran.relaxation.guarded_shape_iterations;
  j["repair_sweeps"] = ran.repair.sweeps;
  j["repair_threshold"] = ran.repair.threshold;
  j["repair_coarse_levels"] = ran.repair.coarse_levels;
  j["repair_guard_finest"] = ran.repair.guard_finest;
  j["repair_error_tolerance"] = ran.repair.error_tolerance;
  j["rim_min_triangles"] = ran.base.rim_min_triangles;
  j["parameterization"] = result.parameterization;
  double total = own_seconds(result);
  // Where both domains were built, the one not kept took its time too.
  if (const auto choice = result.parameterization.find("domain_choice"); choice != result.parameterization.end())
    total += choice->value("seconds", 0.0);
  nlohmann::json per_level = nlohmann::json::array();
  for (const auto& level : result.levels) per_level.push_back(level.stats);
  j["per_level"] = per_level;
  if (const auto doubts = finest_level_doubts(result)) {  // judged where measured
    j["suspect"] = !doubts->empty();
    j["suspect_reasons"] = *doubts;
  }
  j["seconds"] = total;
  return j;
}

}  // namespace mrsnake
