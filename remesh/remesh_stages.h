#pragma once
/// \file remesh_stages.h
/// The stages that remesh() runs whatever its parameter domain (remesh/remesh.h): the choice of
/// resolution, the preparation of the input, the reprojection onto it and the measures of a
/// level. Internal to the remesh module.
#include <chrono>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/parallel.h"
#include "mesh/progress.h"
#include "mesh/trimesh.h"
#include "remesh/remesh.h"

namespace mrsnake::remesh_stages {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start);

/// Runs `stage`, records its wall time as `seconds[name]` (a level's `stage_seconds`), and
/// returns what it returns.
template <typename Stage>
auto timed(nlohmann::json& seconds, const char* name, Stage&& stage) {
  const auto start = Clock::now();
  if constexpr (std::is_void_v<std::invoke_result_t<Stage>>) {
    stage();
    seconds[name] = seconds_since(start);
  } else {
    auto result = stage();
    seconds[name] = seconds_since(start);
    return result;
  }
}

/// The hierarchy's shape: L levels of 1:4 splits over a base of n0 vertices.
struct Resolution {
  int levels;
  int base_vertices;
};

/// Levels L and base size n0 so that F0·4^L is near target_faces, with F0 in [128, 512).
void choose_resolution(int target_faces, int& levels, int& n0);

/// The levels L and the base size n0 that the options ask for.
Resolution initial_resolution(const RemeshOptions& options);

/// The wanted 3D point densities: `wanted` for the levels' relaxation, `base_density` for the
/// base vertices' spread (both relative, >= 1 where nothing asks for more).
struct SizingFields {
  Eigen::VectorXd wanted;
  Eigen::VectorXd base_density;
};

/// Curvature sizing on `surface` (the parameterized input). Where the bend bound
/// (remesh/sizing.h) asks for more than half of the base vertices (thin tubes, many tips), the
/// base grows 4x and the hierarchy loses a level, unless the levels were given or there is
/// only one. The grown base is spread by the bound, and the relaxation's density raised by the
/// same factor, so that the levels keep the base's grading.
SizingFields sizing_fields(const TriMesh& surface, const SizingOptions& sizing, const BaseMeshOptions& base,
                           bool levels_given, Resolution& resolution);

/// The input as it is parameterized: the original without unreferenced vertices, a
/// simplification of it when it is much finer than the finest level, or an isotropic remeshing
/// of it when more than SimplifyOptions::sliver_share of its triangles are slivers.
struct PreparedInput {
  TriMesh original;
  TriMesh work;
  bool simplified = false;       ///< work stands in for the original: levels are projected back onto it
  nlohmann::json simplify_info;  ///< simplify_seconds, or sliver_share, sliver_remeshed and sliver_remesh_seconds
};

/// The input for `options` (options.simplify at initial_resolution(options), progress to
/// options.progress), the same for both routes; the report's seconds count from `start`.
/// \throw TopologyError if the input is neither a disk nor a closed genus-0 surface, or its faces
/// are oriented inconsistently; AlgorithmError if the simplification or the remeshing of the
/// large slivers fails.
PreparedInput prepare_input(const TriMesh& input, const RemeshOptions& options, Clock::time_point start);

/// Runs `map` (the parameterization of input.work) on this core and, when needs_locator, builds
/// the original's closest-point tree on the other meanwhile (for the reprojection, the fit and
/// the report's distances). Returns the tree, or null.
template <class Map>
std::shared_ptr<SurfaceLocator> map_beside_locator(const PreparedInput& input, bool needs_locator, Map&& map) {
  std::shared_ptr<SurfaceLocator> locator;
  run_both_in_parallel(std::forward<Map>(map), [&] {
    if (needs_locator) locator = std::make_shared<SurfaceLocator>(input.original);
  });
  return locator;
}

/// Moves every row of X to its closest point on the locator's surface.
void reproject_onto(const SurfaceLocator& surface, RowMatrixX3d& X);

/// The finest level's vertices that its fit and untangling keep in place: a disk's rim, and the
/// tips snapped onto the input (`snapped`, empty or one flag per vertex).
std::vector<bool> held_vertices(const RowMatrixX3i& F, int num_vertices, const std::vector<bool>& snapped);

/// The last stage of the finest level (remesh/untangle.h), a disk's rim and the snapped tips
/// (`snapped`, empty or one flag per vertex) held: the record for level.stats["untangle"] where
/// the level had crossing face pairs, else null.
nlohmann::json untangle_finest(const RowMatrixX3i& F, RowMatrixX3d& X, const UntangleOptions& options,
                               const std::vector<bool>& snapped);

/// Quality, distance to the original input and self-intersecting face pairs
/// (count_self_intersections), into level.stats.
/// \throw TopologyError as count_self_intersections does (not on the levels remesh builds).
void measure_level(const TriMesh& original, const SurfaceLocator& locator, const RowMatrixX3i& F, RemeshLevel& level);

}  // namespace mrsnake::remesh_stages
