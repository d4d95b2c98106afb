#include "remesh/base_route.h"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "mesh/errors.h"
#include "mesh/parallel.h"
#include "remesh/base_domain.h"
#include "remesh/base_flips.h"
#include "remesh/base_levels.h"
#include "remesh/base_lift.h"
#include "remesh/domain.h"
#include "remesh/maps.h"
#include "remesh/remesh_stages.h"
#include "remesh/sizing.h"
#include "remesh/surface_fit.h"

namespace mrsnake {
namespace {

using namespace remesh_stages;

// The MAPS map of the prepared input, and the original's closest-point tree built on the other
// core meanwhile.
struct MappedOnBase {
  MapsParameterization maps;
  BaseFlipStats flips;
  std::shared_ptr<SurfaceLocator> locator;
};

MappedOnBase map_onto_base(const PreparedInput& input, int base_vertices, bool needs_locator,
                           const ProgressFn& progress) {
  report(progress, "parameterize", 0);
  MapsOptions options;
  options.base_vertices = base_vertices;
  MappedOnBase m;
  m.locator = map_beside_locator(input, needs_locator, [&] {
    m.maps = maps_parameterize(input.work, options);
    m.flips = flip_base_edges(m.maps);
  });
  return m;
}

// How far K lies from the input it stands for: the largest distance from an input vertex to
// its point on K, in K's mean edge lengths. Where K's faces cut across a protrusion, the
// protrusion's points lie many edges away.
double base_offset(const TriMesh& work, const MapsParameterization& maps, const BaseDomain& domain) {
  const TriMesh& K = maps.base;
  double edges = 0;
  for (int f = 0; f < K.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) edges += (K.V.row(K.F(f, k)) - K.V.row(K.F(f, (k + 1) % 3))).norm();
  const double mean_edge = edges / (3.0 * K.num_faces());
  double largest = 0;
  for (int v = 0; v < work.num_vertices(); ++v)
    largest = std::max(largest, (work.V.row(v).transpose() - domain.position(maps.location[v])).norm());
  return mean_edge > 0 ? largest / mean_edge : 0.0;
}

nlohmann::json base_summary(const MappedOnBase& mapped, const BaseDomain& domain, const BaseLift& lift,
                            const PreparedInput& input, Clock::time_point start) {
  nlohmann::json s;
  if (input.simplify_info.is_object()) s.update(input.simplify_info);
  s["method"] = "MAPS: simplification to the base mesh, each patch mapped onto its base triangle";
  s["domain"] = "base_mesh";
  s["base_vertices"] = mapped.maps.base.num_vertices();
  s["base_faces"] = mapped.maps.base.num_faces();
  s["removed_vertices"] = mapped.maps.removed_vertices;
  s["refused_removals"] = mapped.maps.refused_removals;
  s["surface_flips"] = mapped.flips.delaunay_flips;
  s["valence_flips"] = mapped.flips.valence_flips;
  s["unmapped_triangles"] = lift.unmapped_triangles();
  s["base_offset_edges"] = base_offset(input.work, mapped.maps, domain);
  s["input_faces"] = input.original.num_faces();
  s["parameterized_faces"] = input.work.num_faces();
  s["seconds"] = seconds_since(start);
  return s;
}

// The lift is straight on each input triangle in one chart, and charts kink across K's edges,
// so where input triangles are larger than the finest level's, nearby points of D lift through
// different charts onto overlapping or gapped parts of a triangle, and the level's triangles
// collapse or fold in 3D. Such an input is split 1:4 flat, which keeps its surface, until it
// has at least the finest level's faces; `density` (per input vertex) is carried to the
// new vertices as the mean of their parents'.
void refine_coarse_input(PreparedInput& input, long long finest_faces, Eigen::VectorXd& density) {
  int splits = 0;
  for (long long faces = input.work.num_faces(); faces < finest_faces; faces *= 4) ++splits;
  if (splits == 0) return;
  const SubdivisionConnectivity c = subdivide_connectivity(input.work.F, input.work.num_vertices(), splits);
  RowMatrixX3d V = input.work.V, w = RowMatrixX3d::Zero(density.size(), 3);
  w.col(0) = density;
  for (int j = 0; j < splits; ++j) {
    V = midpoint_refine(c, j, V);
    w = midpoint_refine(c, j, w);
  }
  input.work = TriMesh{V, c.faces[splits]};
  density = w.col(0);
}

// What every level is built on.
struct BaseContext {
  const BaseDomain& domain;
  const BaseLift& lift;
  const TriMesh& original;
  const SurfaceLocator* locator;    ///< the original's closest points, if built
  const SurfaceLocator* reproject;  ///< the same, when a stand-in for the input was parameterized; else null
  const SubdivisionConnectivity& connectivity;
  const Eigen::VectorXd& wanted;  ///< the wanted 3D point density per vertex of the parameterized input
};

// Shapes first (equilateral apexes): free sweeps, then guarded ones that never lower the
// smallest Q around a vertex (free sweeps alone trade a few triangles for the rest: 14 of them
// took the horse's smallest angle at 32k faces from 12.7° to 2.9°); then sizes with a quality
// floor (area centroids), as the sphere route's surface relaxation. Returns the moves.
int relax_level(const BaseContext& ctx, const RelaxationOptions& options, int j, BaseLayout& layout) {
  const RowMatrixX3i& F = ctx.connectivity.faces[j];
  BaseSmoothingOptions shapes;
  shapes.iterations = options.shape_iterations;
  shapes.slide_rim = options.smooth_rim;
  int moves = smooth_on_base(F, ctx.domain, ctx.lift, layout, shapes);
  shapes.iterations = options.guarded_shape_iterations;
  shapes.quality_floor = 1.0;  // min(before, 1): never lower
  moves += smooth_on_base(F, ctx.domain, ctx.lift, layout, shapes);
  BaseSmoothingOptions sizes;
  sizes.iterations = options.surface_iterations;
  sizes.target = SmoothingTarget::area_centroid;
  sizes.quality_floor = options.surface_quality_floor;
  sizes.surface_density = &ctx.wanted;
  sizes.slide_rim = options.smooth_rim;
  moves += smooth_on_base(F, ctx.domain, ctx.lift, layout, sizes);
  return moves;
}

// The layouts a level starts from: the split of the level before as relaxed, and as split
// only (every vertex at dyadic barycentric coordinates of one face of K).
struct LevelStart {
  BaseLayout relaxed;
  BaseLayout dyadic;
};

struct LaidOutLevel {
  BaseLayout layout;
  int moves = 0;
  bool from_dyadic = false;
};

// Level j laid out: the relaxed level before, split, untangled and relaxed, if every edge has
// a chart and that leaves no flip; else the dyadic split relaxed, which starts with none: each
// of its triangles lies in one face of K, where every chart is an affine image of the face.
// Charts disagree across K's edges, so the split of a relaxed sliver can fold; the relaxation
// never adds a flip and mostly undoes the folds it starts with.
LaidOutLevel lay_out_level(const BaseContext& ctx, const RemeshOptions& options, int j, LevelStart& start) {
  if (j == 0) return {start.relaxed, 0, true};  // K: its vertices where MAPS kept them
  const RowMatrixX3i& F = ctx.connectivity.faces[j];
  const bool full = options.relax == RelaxMode::all_vertices;
  const auto relaxed = [&](BaseLayout layout) {
    const int moves = full ? relax_level(ctx, options.relaxation, j, layout) : 0;
    return LaidOutLevel{std::move(layout), moves, false};
  };
  if (!split_on_base(ctx.connectivity, j, ctx.domain, ctx.lift, start.dyadic))
    throw std::logic_error("level " + std::to_string(j) + ": the dyadic split has an edge that no chart holds");
  if (split_on_base(ctx.connectivity, j, ctx.domain, ctx.lift, start.relaxed)) {
    untangle_on_base(F, ctx.domain, ctx.lift, start.relaxed);
    LaidOutLevel level = relaxed(std::move(start.relaxed));
    if (count_flipped_on_base(ctx.domain, F, level.layout.points) == 0) return level;
  }
  LaidOutLevel level = relaxed(start.dyadic);
  level.from_dyadic = true;
  return level;
}

// The repair of the finest level's worst triangles (repair_on_base), as the sphere route
// repairs them, with the surface guard. Coarse levels are not repaired here (whatever
// options.coarse_levels says): the next level's relaxation starts from them, and repairing them
// measured worse at the finest level (human at 16k faces: Q mean 0.831 -> 0.810; horse at 16k:
// Hausdorff distance 0.50 -> 0.94 % of the diagonal). Returns its record.
// \pre j is the finest level and options.sweeps > 0 (the caller runs it only there).
nlohmann::json repair_level_on_base(const BaseContext& ctx, const RepairOptions& options, int j,
                                    const std::vector<bool>& snapped, BaseLayout& layout) {
  BaseRepairOptions repair;
  repair.fixed = &snapped;
  repair.sweeps = options.sweeps;
  repair.threshold = options.threshold;
  if (options.guard_finest) repair.error_tolerance = options.error_tolerance;
  const BaseRepairStats s = repair_on_base(ctx.connectivity.faces[j], ctx.domain, ctx.lift, layout, repair);
  return {{"moves", s.moves}, {"q_min_before", s.q_min_before}, {"q_min_after", s.q_min_after}};
}

// Level j: laid out (lay_out_level); on the finest level its tips snapped and its worst
// triangles repaired; back onto the original when a stand-in for it was parameterized; the
// flip test in D; and the fit and the untangling of the finest level.
// \throw AlgorithmError if a triangle is flipped in D.
RemeshLevel build_base_level(const BaseContext& ctx, const RemeshOptions& options, int j, LevelStart& start,
                             double extra_seconds) {
  const auto clock_start = Clock::now();
  const RowMatrixX3i& F = ctx.connectivity.faces[j];
  // The snap, the repair, the fit and the untangling run on the finest level, and with the full
  // method only.
  const bool finest_full = options.relax == RelaxMode::all_vertices && j == ctx.connectivity.levels();
  nlohmann::json stage_seconds = nlohmann::json::object();
  LaidOutLevel laid_out = timed(stage_seconds, "lay_out", [&] { return lay_out_level(ctx, options, j, start); });
  BaseLayout& layout = laid_out.layout;
  // The finest level's tips first, then its worst triangles around them (the snapped stay).
  std::vector<bool> snapped(layout.points.size(), false);
  int snaps = 0;
  if (finest_full && options.snap.max_snaps > 0)
    snaps = timed(stage_seconds, "snap",
                  [&] { return snap_on_base(F, ctx.domain, ctx.lift, layout, options.snap, &snapped); });
  nlohmann::json repair;
  if (finest_full && options.repair.sweeps > 0)
    repair =
        timed(stage_seconds, "repair", [&] { return repair_level_on_base(ctx, options.repair, j, snapped, layout); });
  RemeshLevel level;
  level.positions = layout.X;
  if (ctx.reproject) reproject_onto(*ctx.reproject, level.positions);
  const int flipped = count_flipped_on_base(ctx.domain, F, layout.points);
  if (flipped > 0)
    throw AlgorithmError("level " + std::to_string(j) + " has " + std::to_string(flipped) +
                         " flipped triangles in the base domain; the surface cannot be remeshed well");
  nlohmann::json fit;
  if (finest_full && options.fit.rounds > 0 && ctx.locator) {
    const std::vector<bool> fixed = held_vertices(F, static_cast<int>(level.positions.rows()), snapped);
    const SurfaceFitStats s = timed(
        stage_seconds, "fit", [&] { return fit_to_surface(F, level.positions, *ctx.locator, options.fit, fixed); });
    fit = {{"rms_before_mm", s.rms_before}, {"rms_after_mm", s.rms_after}, {"max_offset_mm", s.max_offset}};
  }
  nlohmann::json untangle;
  if (finest_full && options.untangle.max_rounds > 0)
    untangle = timed(stage_seconds, "untangle",
                     [&] { return untangle_finest(F, level.positions, options.untangle, snapped); });
  level.domain_positions.resize(layout.points.size(), 3);
  for (std::size_t v = 0; v < layout.points.size(); ++v)
    level.domain_positions.row(v) = ctx.domain.position(layout.points[v]).transpose();
  level.flipped_triangles = flipped;
  start.relaxed = std::move(layout);
  level.seconds = seconds_since(clock_start) + extra_seconds;
  level.stats = {{"level", j},
                 {"vertices", level.positions.rows()},
                 {"faces", F.rows()},
                 {"flipped_triangles", flipped},
                 {"seconds", level.seconds},
                 {"shape_moves", laid_out.moves},
                 {"stage_seconds", stage_seconds},
                 {"started_from", laid_out.from_dyadic ? "dyadic split" : "relaxed split"}};
  if (!fit.is_null()) level.stats["fit"] = fit;
  if (!repair.is_null()) level.stats["repair"] = repair;
  if (!untangle.is_null()) level.stats["untangle"] = untangle;
  if (j == ctx.connectivity.levels()) level.stats["snapped_vertices"] = snaps;
  if (options.compute_stats && ctx.locator) measure_level(ctx.original, *ctx.locator, F, level);
  return level;
}

}  // namespace

RemeshResult remesh_on_base_mesh(const TriMesh& input, const RemeshOptions& options) {
  const auto start = Clock::now();
  return remesh_on_base_mesh(prepare_input(input, options, start), options, start);
}

RemeshResult remesh_on_base_mesh(remesh_stages::PreparedInput prepared, const RemeshOptions& options,
                                 remesh_stages::Clock::time_point start) {
  RemeshResult result;
  Resolution resolution = initial_resolution(options);
  // MAPS spreads the base by its removal order, so only the grown size and density are used.
  Eigen::VectorXd wanted =
      sizing_fields(prepared.work, options.sizing, options.base, options.levels != 0, resolution).wanted;
  const long long finest_faces = 2LL * (resolution.base_vertices - 2) << (2 * resolution.levels);
  refine_coarse_input(prepared, finest_faces, wanted);
  const bool needs_locator = prepared.simplified || options.relax == RelaxMode::all_vertices || options.compute_stats ||
                             options.keep_input_locator;
  const MappedOnBase mapped = map_onto_base(prepared, resolution.base_vertices, needs_locator, options.progress);
  const BaseDomain domain(mapped.maps.base);
  const BaseLift lift(prepared.work, domain, mapped.maps.location);
  result.input_locator = mapped.locator;
  result.domain = "base_mesh";
  result.parameterization = base_summary(mapped, domain, lift, prepared, start);
  result.connectivity = subdivide_connectivity(mapped.maps.base.F, mapped.maps.base.num_vertices(), resolution.levels);
  const BaseContext context{domain,
                            lift,
                            prepared.original,
                            mapped.locator.get(),
                            prepared.simplified ? mapped.locator.get() : nullptr,
                            result.connectivity,
                            wanted};
  LevelStart level_start{base_vertices_layout(domain, lift), base_vertices_layout(domain, lift)};
  for (int j = 0; j <= resolution.levels; ++j) {
    result.levels.push_back(build_base_level(context, options, j, level_start, 0.0));
    report(options.progress, "level " + std::to_string(j), 1.0);
  }
  return result;
}

}  // namespace mrsnake
