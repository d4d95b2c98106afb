#pragma once
/// \file remesh.h
/// Semi-regular remeshing (section 4 of the seed paper): parameterize the input on a convex
/// domain D, build a base mesh T0 in D, then for each level split 1:4, relax by the constrained
/// Lloyd iteration and lift to 3D. The result is a nested hierarchy S0..SL whose connectivity is
/// exactly `subdivide_connectivity(F0, n0, L)`.
///
/// Domain: a closed genus-0 input is mapped onto the unit sphere (the boundary of a convex
/// body; no seam), a disk input onto the unit disk (boundary on the circle).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/progress.h"
#include "mesh/subdivision.h"
#include "mesh/trimesh.h"
#include "remesh/base_mesh.h"
#include "remesh/feature_snap.h"
#include "remesh/parameterization.h"
#include "remesh/surface_fit.h"
#include "remesh/untangle.h"

namespace mrsnake {

/// Which vertices the constrained Lloyd iteration moves at each level.
enum class RelaxMode {
  all_vertices,       ///< every vertex of the level (default; coarse vertices move too)
  new_vertices_only,  ///< only the vertices the level adds: the paper's exact method (--strict)
  none,               ///< no relaxation: plain 1:4 split in D (the paper's baseline, --no-relax)
};

/// The parameter domain D on which the levels are built and relaxed.
enum class ParameterDomain {
  /// `sphere`; where the one-chart map of a closed surface fails and the automatic sphere map
  /// falls back on the hierarchical one (protrusions: legs, fingers, horns), `base_mesh` is
  /// built too, and the finest level with fewer self-intersections, then the higher mean
  /// quality, is kept; where the sphere route fails (AlgorithmError), the base mesh's result
  /// stands in for it (default).
  automatic,
  /// The input mapped as a whole onto the unit sphere (closed) or the unit disk (a disk):
  /// remesh/parameterization.h.
  sphere,
  /// The base mesh itself (MAPS, remesh/maps.h): the input simplified to the base, each patch
  /// mapped onto its base triangle, so that D follows the shape (remesh/base_domain.h).
  base_mesh,
};

/// Curvature sizing: where the levels should be denser than even in 3D (remesh/sizing.h).
struct SizingOptions {
  /// The wanted 3D point density is w = 1 + curvature_weight·min((κ/mean κ)^curvature_exponent, 3):
  /// smaller triangles where the surface bends, whose chord error grows as κh². 0 = even spacing.
  double curvature_weight = 0.5;
  /// The exponent p of κ/mean κ above; 2/3 would minimize the mean squared chord error for a
  /// given vertex count (spacing ∝ κ^(-1/3)).
  double curvature_exponent = 1.0;
  /// The Lloyd density is (stretch·w)^density_exponent, stretch = A3D/A_D: 2 makes the 3D
  /// spacing follow w (2D Lloyd spaces points as density^(-1/4)).
  double density_exponent = 2.0;
};

/// How the base mesh T0 is spread over the surface (remesh/base_mesh.h).
struct BaseMeshOptions {
  /// Farthest-point sampling of the base scales squared distances by w^density_exponent, so
  /// that more base vertices, and their irregular valences, sit where the surface bends, which
  /// they absorb. 0 = even in 3D.
  double density_exponent = 1.0;
  /// Passes of 1-ring averaging of that density, so that the base follows bends at its own
  /// scale, not voxel steps; -1 = about one base spacing, round(sqrt(input vertices / n0)).
  int density_smoothing = 3;
  /// The bend bound (remesh/sizing.h), in radians: no base edge should turn the surface's
  /// normal by much more. Where the bound asks for more than half of the base (tips, thin
  /// tubes), the base grows 4x once and the hierarchy has one level less; not with `levels`
  /// given, nor for a hierarchy of one level. 0 = off.
  double max_bend = 2.0;
  /// Disk inputs: a base rim vertex with fewer triangles than this is dropped (with 2 its
  /// corners stay obtuse at every level). 1 = keep all.
  int rim_min_triangles = 3;
  /// One-chart sphere maps: a base edge whose two facing angles on the surface sum to more
  /// than 180° plus this many degrees is flipped, where the sphere allows it (remesh/base_mesh.h:
  /// the sphere's Delaunay triangulation is long in 3D where the map stretches). 180 = off.
  double one_chart_flip_margin_deg = kOneChartFlipMarginDeg;
};

/// The relaxation of each level: Lloyd steps in D (remesh/lloyd.h), shape smoothing and the
/// surface relaxation (remesh/shape_smoothing.h). What moves is RemeshOptions::relax.
struct RelaxationOptions {
  /// Lloyd iterations per level (level 0 included unless relax == new_vertices_only).
  int lloyd_iterations = 8;
  /// With all_vertices: rounds per level of tangential smoothing toward equilateral 3D
  /// triangles, interleaved with the Lloyd iterations. The Lloyd step evens out sizes but is
  /// affine invariant, so it cannot repair shear; this can. 0 = the Lloyd step alone.
  int shape_iterations = 6;
  /// The base-mesh domain, with all_vertices: sweeps per level of the same smoothing after
  /// those, each move refused if it lowers the smallest Q of the vertex's triangles (unless
  /// one of them is flipped in D, which the move may then undo). That domain has no Lloyd
  /// step; these polish the shapes the free sweeps made without undoing them anywhere. 0 = off.
  int guarded_shape_iterations = 8;
  /// With all_vertices: iterations per level of relaxation on the surface after those rounds
  /// (SmoothingTarget::area_centroid): sizes even out where the parameterization's stretch
  /// changes too fast for the Lloyd step in D. 0 = off.
  int surface_iterations = 3;
  /// The surface relaxation refuses a move that lowers the smallest Q of the vertex's
  /// triangles below min(before, this), so that it keeps the shapes just made.
  double surface_quality_floor = 0.75;
  /// Disk inputs: rim vertices slide along the rim during shape smoothing and surface
  /// relaxation (toward the midpoint of their rim neighbours in 3D), staying on the circle in D.
  bool smooth_rim = true;
};

/// The repair of the worst triangles of each level (remesh/triangle_repair.h), with all_vertices.
struct RepairOptions {
  /// Sweeps per level: vertices of triangles with Q < threshold move tangentially, on the
  /// input, only when that raises the smallest Q around them. 0 = off.
  int sweeps = 6;
  double threshold = 0.85;
  /// Repair every level (true) or only the finest (false: coarse levels keep the Lloyd layout).
  /// The base-mesh domain repairs its finest level only, either way.
  bool coarse_levels = true;
  /// On the finest level, which is what is measured against the input, refuse moves that take
  /// triangles further from the surface (TriangleRepairOptions::guard_surface_error).
  bool guard_finest = true;
  /// The guard lets triangles move away from the surface by up to this x the mean edge length.
  double error_tolerance = 0.03;
  /// With a simplified or sliver-remeshed input: project each level onto the original input
  /// before the repair (which then moves vertices on the original) instead of after it, so that
  /// the repair sees the triangles the projection shears. The base-mesh domain repairs on the
  /// surface it parameterized, then projects (its repair moves vertices in its charts), either way.
  bool after_reprojection = true;
};

/// The simplification of a fine input, or the isotropic remeshing of one made of large slivers,
/// before the parameterization (remesh/simplify.h).
struct SimplifyOptions {
  /// Inputs with more faces than max(above_faces, 8 x the finest level's faces) are simplified
  /// to that size; the levels are then projected back onto the original. 0 = never simplify.
  int above_faces = 100000;
  /// An input with more than this share of large slivers (triangles of Q < 0.3 with an edge
  /// longer than the finest level's: that of equilateral triangles covering the input's area in
  /// the finest level's face count) is remeshed isotropically first (CGAL, 3 iterations, toward
  /// that edge), and the levels are projected back onto the original. The lift is affine on each
  /// input triangle, so a large sliver shears the level's triangles over it, and on the
  /// base-mesh domain no chart holds one longer than a base star. 1 = never.
  double sliver_share = 0.05;
};

/// Options of remesh(). Either `levels` or `target_faces` chooses the resolution. Everything
/// up to `untangle` is the method (JSON: remesh/remesh_options_json.h, the form of
/// `mrsnake remesh --config` and of report.json's "options"); the rest is for the caller only.
struct RemeshOptions {
  /// Number of 1:4 splits L (> 0), or 0 to derive it from target_faces.
  int levels = 0;
  /// Wanted face count of the finest level when levels == 0: the base size n0 and L are
  /// chosen so that F0·4^L is near it.
  int target_faces = 16000;
  /// Number of base vertices when `levels` is given (ignored with target_faces).
  int base_vertices = 32;
  RelaxMode relax = RelaxMode::all_vertices;
  ParameterDomain domain = ParameterDomain::automatic;
  /// How a closed genus-0 input is mapped onto the sphere (remesh/parameterization.h).
  SphereMap sphere_map = SphereMap::automatic;
  /// With the automatic domain: where the one-chart sphere map squeezes the shape past 12
  /// orders of magnitude of area stretch (OneChartFailure::squeezed), only the base-mesh domain
  /// is built, and the hierarchical sphere map only if the base mesh fails; false builds both
  /// and keeps the better, as where the one-chart map only flipped triangles.
  bool base_mesh_alone_when_squeezed = true;
  SimplifyOptions simplify;
  SizingOptions sizing;
  BaseMeshOptions base;
  RelaxationOptions relaxation;
  /// With all_vertices, on the finest level: up to snap.max_snaps vertices snap onto the
  /// input's vertices farthest from the level (its tips, which the Lloyd steps cut off), before
  /// the repair (remesh/feature_snap.h). max_snaps = 0: off.
  FeatureSnapOptions snap;
  RepairOptions repair;
  /// With all_vertices, after the repair: fit.rounds rounds of the least-squares fit of the
  /// finest level to the input along the vertex normals (remesh/surface_fit.h). The lifted
  /// vertices sit on the input, so every triangle is a chord; the fit centres the triangles on
  /// the surface. fit.rounds = 0: off.
  SurfaceFitOptions fit;
  /// With all_vertices, last on the finest level: the corners of crossing face pairs move to
  /// their neighbours' mean while the count of such pairs falls (remesh/untangle.h), which opens
  /// the folds a level makes around parts thinner than its edges. max_rounds = 0: off.
  UntangleOptions untangle;

  // For the caller only; not part of the method, not in the JSON.
  /// Build RemeshResult::input_locator even if nothing here needs it (a caller that measures
  /// against the input then gets the tree built on the other core while the map is solved).
  bool keep_input_locator = false;
  /// Compute quality and distance per level into RemeshLevel::stats (costs time).
  bool compute_stats = true;
  ProgressFn progress;
};

/// One level of the result.
struct RemeshLevel {
  RowMatrixX3d positions;         ///< 3D positions, n_j rows (on the input; the finest moved by fit, untangling)
  RowMatrixX3d domain_positions;  ///< positions in D, n_j rows (unit sphere, or z = 1 plane for a disk)
  int flipped_triangles = 0;      ///< triangles with non-positive orientation in D (always 0)
  double seconds = 0;             ///< time spent building this level
  /// Per-level report: vertices, faces, quality (mesh/quality.h keys), distance
  /// (mesh/distance.h keys, % of the input's diagonal), flipped_triangles, seconds.
  nlohmann::json stats;
};

/// What remesh() returns.
struct RemeshResult {
  SubdivisionConnectivity connectivity;  ///< faces[j] = subdivide_connectivity(F0, n0, L).faces[j]
  std::vector<RemeshLevel> levels;       ///< levels[j] for j = 0..L
  /// "sphere", "disk" or "base_mesh".
  std::string domain;
  /// Summary of the parameterization: method, distortion range, seconds.
  nlohmann::json parameterization;
  /// Closest points on the input (vertices renumbered without unreferenced ones), built while
  /// the map was solved, for the reprojection, the fit and the distances; a caller that
  /// measures against the input reuses it. Null when none of those needed it and
  /// RemeshOptions::keep_input_locator was off.
  std::shared_ptr<const SurfaceLocator> input_locator;

  /// The 3D mesh of level j.
  TriMesh mesh(int level) const { return {levels[level].positions, connectivity.faces[level]}; }
};

/// Refuses options out of their range, by their options-file keys, each prefixed with `at`
/// ("remesh." where the options sit inside another command's): remesh() and the commands call
/// it before any work.
/// \throw OptionsError naming the first such option, or relax new_vertices_only on the
///        base_mesh domain, which has no such mode.
void check_options(const RemeshOptions& options, const std::string& at = "");

/// Remeshes a disk or closed genus-0 surface into a nested semi-regular hierarchy.
/// \pre input has at least one face; options.levels >= 0, options.target_faces > 0.
/// \throw TopologyError if the input is not a disk or a closed genus-0 surface (the message
///        names what was found).
/// \throw AlgorithmError if the parameterization fails or is too distorted, or a level cannot
///        be built without flipped triangles (on the automatic domain: on both domains, with
///        the sphere route's message); nothing partial is returned.
/// \throw OptionsError if check_options refuses the options.
RemeshResult remesh(const TriMesh& input, const RemeshOptions& options);

/// Why the finest level is probably unfit for use, one sentence each (empty: nothing is
/// doubtful), or nullopt where the levels were not measured (options.compute_stats off). Two
/// faults that the quality figures do not show: the level passes through itself, or it misses
/// a part of the input by more than its mean edge length (a sharp tip or corner, or a tube
/// thinner than an edge, was cut off, or a fold was opened away from the input). The edge is
/// the unit because a Lloyd step cannot follow a feature narrower than it (docs/remesh.md,
/// "Doubtful results"). The distance is the level's measured Hausdorff distance, over at most
/// 50k sampled points per surface: on a larger input, a lower bound.
/// \pre result's levels were measured as remesh() measures them, or not at all.
/// \throw nlohmann::json::exception if the finest level's stats lack a figure the rule reads.
std::optional<std::vector<std::string>> finest_level_doubts(const RemeshResult& result);

/// The report.json document of a result: options, parameterization, every level's stats, and,
/// where the levels were measured, `suspect` with `suspect_reasons` (finest_level_doubts).
nlohmann::json remesh_report(const RemeshResult& result, const RemeshOptions& options);

}  // namespace mrsnake
