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
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/progress.h"
#include "mesh/subdivision.h"
#include "mesh/trimesh.h"
#include "remesh/parameterization.h"

namespace mrsnake {

/// Which vertices the constrained Lloyd iteration moves at each level.
enum class RelaxMode {
  all_vertices,       ///< every vertex of the level (default; coarse vertices move too)
  new_vertices_only,  ///< only the vertices the level adds: the paper's exact method (--strict)
  none,               ///< no relaxation: plain 1:4 split in D (the paper's baseline, --no-relax)
};

/// Options of remesh(). Either `levels` or `target_faces` chooses the resolution.
struct RemeshOptions {
  /// Number of 1:4 splits L (> 0), or 0 to derive it from target_faces.
  int levels = 0;
  /// Wanted face count of the finest level when levels == 0: the base size n0 and L are
  /// chosen so that F0·4^L is near it.
  int target_faces = 16000;
  /// Number of base vertices when `levels` is given (ignored with target_faces).
  int base_vertices = 32;
  RelaxMode relax = RelaxMode::all_vertices;
  /// How a closed genus-0 input is mapped onto the sphere (remesh/parameterization.h).
  SphereMap sphere_map = SphereMap::automatic;
  /// The Lloyd density is stretch^density_exponent, stretch = A3D/A_D. 2 makes the 3D
  /// spacing even (2D Lloyd spaces points as density^(-1/4)).
  double density_exponent = 2.0;
  /// Curvature sizing: the wanted 3D point density is w = 1 + curvature_weight·κ/mean(κ)
  /// (remesh/sizing.h) and the Lloyd density (stretch·w)^density_exponent. 0 = even 3D spacing.
  /// 0.5: on bench/remesh's 12 rows, 1.0 left the bear at 16k faces with Q mean 0.889 (its
  /// sizes spread more than a regular connectivity can follow with equilateral triangles) and
  /// 0.5 gave Q mean >= 0.91 on every row with RMS still below CGAL's (docs/bench-remesh.md).
  double curvature_weight = 0.5;
  /// Curvature sizing exponent p: w = 1 + curvature_weight·min((κ/mean κ)^p, 3). The chord
  /// error of a triangle of size h is ~κh², so spacing ∝ κ^(-1/3) (p = 2/3) minimizes the mean
  /// squared distance for a given vertex count.
  double curvature_exponent = 1.0;
  /// Base vertices are spread by farthest-point sampling with squared distances scaled by
  /// w^base_density_exponent (w: the curvature sizing's wanted density): more base vertices,
  /// and so more irregular ones, where the surface bends, which they absorb. 0 = even in 3D.
  /// 1 against 0: RMS -20 % on the bear (below CGAL's at 16k faces), -7 % on blobby 16k.
  double base_density_exponent = 1.0;
  /// The bend bound (remesh/sizing.h): no base edge should turn the surface's normal by much
  /// more than this (radians). Where the bound asks for more than half of the base, as a base
  /// spread by the curvature sizing alone would cut off tips, bends and thin tubes, the base
  /// grows 4x, once (the hierarchy has one level less), and is spread by the bound. Not with
  /// `levels` given, nor for a hierarchy of one level. 2 against 0: on horse, armadillo, human
  /// and the lateral ventricles at 16k faces, Hausdorff 2.5, 5.8, 1.6 and 1.2 % fell to 0.46,
  /// 1.0, 0.73 and 0.56 %, and Q mean rose by 0.03 to 0.12; the price is interior valence 6 at
  /// ~98 % instead of 99 % where the base grows. 0 = off.
  double max_base_bend = 2.0;
  /// Passes of 1-ring averaging of that density first; -1 = about one base spacing,
  /// round(sqrt(input vertices / n0)). 3: without it the liver's base followed voxel steps
  /// (Hausdorff 1.25 % at 16k faces); with 6 or more the bear lost its gain.
  int base_density_smoothing = 3;
  /// Lloyd iterations per level (level 0 included unless relax == new_vertices_only).
  int lloyd_iterations = 8;
  /// With all_vertices: iterations per level of tangential smoothing toward equilateral 3D
  /// triangles, moved in D (remesh/shape_smoothing.h). The Lloyd step evens out sizes but is
  /// affine invariant, so it cannot repair shear; this can. 0 = the Lloyd step alone.
  /// 6 against 3: Q mean +0.01 on every bench input at ~+2 % RMS (docs/bench-remesh.md).
  int shape_iterations = 6;
  /// With all_vertices: iterations per level of tangential relaxation on the surface after the
  /// Lloyd and shape rounds (remesh/shape_smoothing.h, SmoothingTarget::area_centroid): each vertex
  /// moves toward the density x area weighted mean of its 3D triangles' centroids, so sizes even
  /// out where the parameterization's stretch changes too fast for the Lloyd step in D. 0 = off.
  /// 3: RMS -3 to -10 % on bear, heart and mushroom for Q mean -0.005 to -0.01.
  int surface_relax_iterations = 3;
  /// The surface relaxation refuses a move that lowers the smallest Q of the vertex's triangles
  /// below min(before, this): without it the min angle fell below 30° on the liver (32k faces).
  double surface_relax_quality_floor = 0.75;
  /// Disk inputs: rim vertices slide along the rim during shape smoothing and surface relaxation
  /// (toward the midpoint of their rim neighbours in 3D), staying on the circle in D.
  bool smooth_rim = true;
  /// With all_vertices: sweeps per level of the final repair of the worst triangles
  /// (remesh/triangle_repair.h): vertices of triangles with Q < repair_threshold move
  /// tangentially, on the input, only when that raises the smallest Q around them. 0 = off.
  int repair_sweeps = 6;
  /// 0.85 against 0.8: Q mean +0.005 to +0.01; 0.9 pushed the heart's Hausdorff past 0.5 %.
  double repair_threshold = 0.85;
  /// Repair every level (true) or only the finest (false; coarse levels keep the Lloyd layout).
  bool repair_coarse_levels = true;
  /// On the finest level, refuse repair moves that take triangles further from the surface
  /// (TriangleRepairOptions::guard_surface_error): the finest level is what is measured
  /// against the input; coarse levels only shape the layout.
  bool repair_guard_finest = true;
  /// The guard lets triangles move away from the surface by up to this x the mean edge length.
  double repair_error_tolerance = 0.03;
  /// With all_vertices, on the finest level: up to this many vertices snap onto the input's
  /// vertices farthest from the level (its tips, which the Lloyd steps cut off), before the
  /// repair (remesh/feature_snap.h). 0 = off.
  int snap_tips = 32;
  /// With a simplified input: project each level onto the original input before the repair
  /// (which then moves vertices on the original) instead of after it, so the repair sees the
  /// triangles the projection shears (on the liver's staircase it cost Q min 0.59).
  bool repair_after_reprojection = true;
  /// Disk inputs: a base rim vertex with fewer triangles than this is dropped from the base
  /// mesh (remesh/base_mesh.h); with 2 its corners stay obtuse at every level. 1 = keep all.
  int rim_min_triangles = 3;
  /// Inputs with more faces than max(simplify_above_faces, 8 x the finest level's faces) are
  /// simplified to that size before parameterization (remesh/simplify.h); the result is then
  /// projected back onto the original input. 0 = never simplify.
  int simplify_above_faces = 100000;
  /// Rounds of the least-squares fit of the finest level to the input along the vertex normals
  /// (remesh/surface_fit.h), after the repair: the lifted vertices sit on the input, so every
  /// triangle is a chord, one-sided on a curved patch; the fit centres the triangles on the
  /// surface. Only the finest level, which is what is measured against the input (a model's
  /// coarse levels are recomputed from it by the wavelet analysis). With all_vertices only, like
  /// the snap and the repair. 0 = off: every vertex stays exactly on the input, as in the paper.
  /// 1: RMS -9 to -51 % on the bench meshes (bench/remesh).
  int fit_rounds = 1;
  /// Build RemeshResult::input_locator even if nothing here needs it (a caller that measures
  /// against the input then gets the tree built on the other core while the map is solved).
  bool keep_input_locator = false;
  /// Compute quality and distance per level into RemeshLevel::stats (costs time).
  bool compute_stats = true;
  ProgressFn progress;
};

/// One level of the result.
struct RemeshLevel {
  RowMatrixX3d positions;         ///< 3D positions, n_j rows (on the input surface; the finest off it by the fit)
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
  /// "sphere" or "disk".
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

/// Remeshes a disk or closed genus-0 surface into a nested semi-regular hierarchy.
/// \pre input has at least one face; options.levels >= 0, options.target_faces > 0.
/// \throw TopologyError if the input is not a disk or a closed genus-0 surface (the message
///        names what was found).
/// \throw AlgorithmError if the parameterization fails or is too distorted, or a level cannot
///        be built without flipped triangles; nothing partial is returned.
/// \throw std::invalid_argument on bad options.
RemeshResult remesh(const TriMesh& input, const RemeshOptions& options);

/// The report.json document of a result: options, parameterization and every level's stats.
nlohmann::json remesh_report(const RemeshResult& result, const RemeshOptions& options);

}  // namespace mrsnake
