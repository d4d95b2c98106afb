// Tests of the least-squares fit of a level to its input along the vertex normals
// (remesh/surface_fit.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "mesh/distance.h"
#include "mesh/mesh_io.h"
#include "mesh/normals.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "remesh/remesh.h"
#include "remesh/surface_fit.h"
#include "tests/remesh/remesh_shapes.h"
#include "tests/test_support.h"

namespace mrsnake {
namespace {

// Signed offset of every vertex along its normal on `before`.
Eigen::VectorXd normal_offsets(const TriMesh& before, const RowMatrixX3d& after) {
  RowMatrixX3d N;
  vertex_normals(before.V, before.F, N);
  return (after - before.V).cwiseProduct(N).rowwise().sum();
}

// An icosphere's triangles are chords of the unit sphere, their centroids inside by the sag
// s_c = 1 - |c|. With the corner-and-centroid rule, a vertex's least-squares offset is 3/4 of
// the centroid sag around it (corners weigh 1/4 with residual -t, the centroid 3/4 with s_c - t):
// the fit must find that, outward, and cut the distance to the sphere accordingly.
TEST(SurfaceFit, MovesAnIcosphereOutwardByThreeQuartersOfTheCentroidSag) {
  const TriMesh level = icosphere(2);   // 162 vertices, edges ~0.3: centroid sag ~0.015
  const TriMesh sphere = icosphere(6);  // the input: 40962 vertices, its own sag ~5e-5
  const SurfaceLocator locator(sphere);
  RowMatrixX3d X = level.V;
  const SurfaceFitStats stats = fit_to_surface(level.F, X, locator);
  const Eigen::VectorXd offset = normal_offsets(level, X);

  std::vector<double> sag_sum(level.V.rows(), 0.0), sag_count(level.V.rows(), 0.0);
  for (int f = 0; f < level.F.rows(); ++f) {
    const Eigen::Vector3d c =
        (level.V.row(level.F(f, 0)) + level.V.row(level.F(f, 1)) + level.V.row(level.F(f, 2))) / 3.0;
    for (int k = 0; k < 3; ++k) {
      sag_sum[level.F(f, k)] += 1.0 - c.norm();
      sag_count[level.F(f, k)] += 1;
    }
  }
  for (int v = 0; v < level.V.rows(); ++v) {
    const double expected = 0.75 * sag_sum[v] / sag_count[v];
    EXPECT_GT(offset(v), 0.0) << v;
    EXPECT_NEAR(offset(v), expected, 0.15 * expected) << v;
    // Only along the normal.
    EXPECT_NEAR((X.row(v) - level.V.row(v)).norm(), std::abs(offset(v)), 1e-12);
  }
  // The rule's own estimate, for a uniform sag s: before, sqrt(3/4) s (corners on the sphere);
  // after, with t = 3/4 s, sqrt(1/4 t^2 + 3/4 (s - t)^2) = sqrt(3/16) s: half.
  EXPECT_NEAR(stats.rms_after / stats.rms_before, 0.5, 0.05);
  EXPECT_EQ(stats.clamped_vertices, 0);
  EXPECT_EQ(stats.held_vertices, 0);
  const double rms_before = surface_distance(level, sphere).rms_mm;
  const double rms_after = surface_distance(TriMesh{X, level.F}, sphere).rms_mm;
  // The true integral weighs the corners less than the rule: for a uniform sag s the RMS goes
  // from sqrt(3/5) s to sqrt(3/80) s, a quarter (measured: 0.263).
  EXPECT_LT(rms_after, 0.35 * rms_before) << rms_before << " -> " << rms_after;
}

// A flat grid on a flat input has nothing to correct: no vertex moves.
TEST(SurfaceFit, LeavesAMeshOnAPlaneWhereItIs) {
  const TriMesh grid = test::flat_grid(8);
  TriMesh plane;  // larger, so that every closest point is inside it
  plane.V.resize(4, 3);
  plane.V << -5, -5, 0, 20, -5, 0, 20, 20, 0, -5, 20, 0;
  plane.F.resize(2, 3);
  plane.F << 0, 1, 2, 0, 2, 3;
  const SurfaceLocator locator(plane);
  RowMatrixX3d X = grid.V;
  SurfaceFitOptions options;
  options.rounds = 3;
  fit_to_surface(grid.F, X, locator, options);
  EXPECT_LT((X - grid.V).cwiseAbs().maxCoeff(), 1e-12);
}

// Fixed vertices keep their exact positions; with max_offset 0 nothing moves; with a quality
// floor of 1 no triangle may lose any quality, and none does.
TEST(SurfaceFit, HonoursFixedVerticesTheOffsetLimitAndTheQualityFloor) {
  const TriMesh level = icosphere(2);
  const TriMesh sphere = icosphere(5);
  const SurfaceLocator locator(sphere);
  std::vector<bool> fixed(level.V.rows(), false);
  for (int v = 0; v < level.V.rows(); v += 3) fixed[v] = true;
  RowMatrixX3d X = level.V;
  fit_to_surface(level.F, X, locator, {}, fixed);
  int moved = 0;
  for (int v = 0; v < level.V.rows(); ++v) {
    if (fixed[v])
      EXPECT_EQ(X.row(v), level.V.row(v)) << v;
    else
      moved += (X.row(v) - level.V.row(v)).norm() > 0;
  }
  EXPECT_GT(moved, level.V.rows() / 2);

  SurfaceFitOptions no_move;
  no_move.max_offset = 0;
  X = level.V;
  fit_to_surface(level.F, X, locator, no_move);
  EXPECT_EQ(X, level.V);

  // A jittered sphere, so that the fit would change triangle shapes.
  TriMesh jittered = level;
  for (int v = 0; v < jittered.V.rows(); ++v) jittered.V.row(v) *= 1.0 + 0.02 * std::sin(7.0 * v);
  SurfaceFitOptions strict;
  strict.quality_floor = 1.0;
  X = jittered.V;
  const SurfaceFitStats stats = fit_to_surface(jittered.F, X, locator, strict);
  EXPECT_GT(stats.held_vertices, 0);
  for (int f = 0; f < jittered.F.rows(); ++f) {
    auto q = [&](const RowMatrixX3d& P) {
      return frey_borouchaki_quality(P.row(jittered.F(f, 0)), P.row(jittered.F(f, 1)), P.row(jittered.F(f, 2)));
    };
    EXPECT_GE(q(X), q(jittered.V) - 1e-12) << f;
  }
  EXPECT_THROW(fit_to_surface(level.F, X, locator, {}, std::vector<bool>(3, false)), std::invalid_argument);
}

// In remesh(): the finest level is fitted (report key "fit"), the coarse ones stay on the input,
// and the finest level's distance to the input falls.
TEST(SurfaceFit, RemeshFitsOnlyTheFinestLevelAndItGetsCloser) {
  TriMesh ellipsoid = icosphere(5);
  ellipsoid.V.col(0) *= 2.0;
  ellipsoid.V.col(2) *= 0.7;
  RemeshOptions options;
  options.levels = 2;
  options.base_vertices = 24;
  options.fit.rounds = 0;
  const RemeshResult on_surface = remesh(ellipsoid, options);
  options.fit.rounds = 1;
  const RemeshResult fitted = remesh(ellipsoid, options);
  ASSERT_EQ(fitted.levels.size(), 3u);
  for (int j = 0; j < 2; ++j) {
    EXPECT_EQ(fitted.levels[j].positions, on_surface.levels[j].positions) << j;
    EXPECT_FALSE(fitted.levels[j].stats.contains("fit")) << j;
  }
  const nlohmann::json& finest = fitted.levels[2].stats;
  ASSERT_TRUE(finest.contains("fit"));
  EXPECT_EQ(fitted.levels[2].domain_positions, on_surface.levels[2].domain_positions);
  const double before = on_surface.levels[2].stats["distance"]["rms_pct"].get<double>();
  const double after = finest["distance"]["rms_pct"].get<double>();
  EXPECT_LT(after, 0.8 * before) << before << " -> " << after;
  EXPECT_GE(finest["quality"]["q_min"].get<double>(),
            std::min(0.75, on_surface.levels[2].stats["quality"]["q_min"].get<double>()) - 1e-12);

  // The paper's baseline and exact method are never fitted: every vertex stays on the input.
  const SurfaceLocator locator(ellipsoid);
  for (RelaxMode mode : {RelaxMode::none, RelaxMode::new_vertices_only}) {
    options.relax = mode;
    const RemeshResult paper = remesh(ellipsoid, options);
    EXPECT_FALSE(paper.levels[2].stats.contains("fit"));
    EXPECT_EQ(remesh_report(paper, options)["fit_rounds"].get<int>(), 0);
    EXPECT_LT(locator.distances(paper.levels[2].positions).maxCoeff(), 1e-9);
  }
}

// The heart at 32k faces snaps vertices onto (or part of the way to) input tips; the fit moves
// the other vertices of the finest level off the input, but the snapped ones stay where the
// snap put them, on the input: as many vertices as were snapped are the same with the fit and
// without it, and lie on the input.
TEST(SurfaceFit, SnappedTipsStayOnTheInput) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/heart.off");
  const TriMesh input = read_mesh(path);
  RemeshOptions options;
  options.target_faces = 32000;
  options.compute_stats = false;
  const RemeshResult fitted = remesh(input, options);
  options.fit.rounds = 0;
  const RemeshResult unfitted = remesh(input, options);
  const RemeshLevel& finest = fitted.levels.back();
  const int snapped = finest.stats["snapped_vertices"].get<int>();
  ASSERT_GT(snapped, 0) << "the heart no longer snaps a tip at 32k faces: pick another input";
  ASSERT_TRUE(finest.stats.contains("fit"));
  ASSERT_EQ(unfitted.levels.back().stats["snapped_vertices"].get<int>(), snapped);
  const SurfaceLocator on_input(input);
  const double tolerance = 1e-9 * bounding_box_diagonal(input.V);
  int kept_on_input = 0, moved = 0;
  for (int v = 0; v < finest.positions.rows(); ++v) {
    const Eigen::Vector3d x = finest.positions.row(v).transpose();
    if (finest.positions.row(v) != unfitted.levels.back().positions.row(v))
      ++moved;
    else if (on_input.closest(x).distance <= tolerance)
      ++kept_on_input;
  }
  // The fit leaves alone only the snapped vertices and those it holds back (a triangle around
  // them would turn or lose quality), each where it was.
  EXPECT_EQ(kept_on_input, snapped + finest.stats["fit"]["held_vertices"].get<int>());
  EXPECT_GT(moved, finest.positions.rows() / 2);  // the fit did move the others
}

}  // namespace
}  // namespace mrsnake
