// Tests of the base mesh's density-scaled farthest-point sampling, the 1-ring smoothing of a
// vertex field, and the triangle repair that projects its moves onto another surface (the
// original input of a simplified one).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "mesh/distance.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "remesh/base_mesh.h"
#include "remesh/domain.h"
#include "remesh/feature_snap.h"
#include "remesh/lift.h"
#include "remesh/parameterization.h"
#include "remesh/sizing.h"
#include "remesh/triangle_repair.h"
#include "tests/remesh/remesh_shapes.h"

namespace mrsnake {
namespace {

using test::ellipsoid;

// Point density 4 on the x > 0 half: farthest points with squared distances scaled by it
// space the samples half as far apart there (about 4 x as many); without it both halves get
// about as many. Either way the base triangulation is valid and uses every sample.
TEST(BaseMeshDensity, PutsMoreBaseVerticesWhereTheDensityIsHigher) {
  const TriMesh input = ellipsoid(4);
  const Parameterization param = parameterize(input);
  Eigen::VectorXd density(param.surface.num_vertices());
  for (int v = 0; v < density.size(); ++v) density[v] = param.surface.V(v, 0) > 0 ? 4.0 : 1.0;
  auto halves = [&](const BaseMesh& base) {
    int positive = 0, negative = 0;
    for (int s : base.samples) (param.surface.V(s, 0) > 0 ? positive : negative)++;
    EXPECT_EQ(count_flipped(base.domain, base.faces), 0);
    EXPECT_EQ(base.faces.rows(), 2 * static_cast<int>(base.samples.size()) - 4);
    return static_cast<double>(positive) / negative;
  };
  const double even = halves(build_base_mesh(param, 60, 3, nullptr));
  const double dense = halves(build_base_mesh(param, 60, 3, &density));
  EXPECT_NEAR(even, 1.0, 0.3);
  EXPECT_GT(dense, 2.5);
}

// Averaging keeps a constant field, spreads a spike to its neighbours and never leaves the
// range of the values.
TEST(Sizing, SmoothingAVertexFieldSpreadsASpikeAndKeepsConstants) {
  const TriMesh mesh = icosphere(2);
  const Eigen::VectorXd constant = Eigen::VectorXd::Constant(mesh.num_vertices(), 2.5);
  EXPECT_LT((smooth_vertex_field(mesh, constant, 4) - constant).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::VectorXd spike = Eigen::VectorXd::Zero(mesh.num_vertices());
  spike[0] = 1;
  EXPECT_TRUE(smooth_vertex_field(mesh, spike, 0) == spike);
  const Eigen::VectorXd once = smooth_vertex_field(mesh, spike, 1);
  EXPECT_LT(once[0], 1.0);
  EXPECT_GE(once.minCoeff(), 0.0);
  EXPECT_LE(once.maxCoeff(), 1.0);
  // Every neighbour of vertex 0 got some, vertices two rings away none yet.
  int far = 0;
  std::vector<bool> near(mesh.num_vertices(), false);
  near[0] = true;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) == 0) near[mesh.F(f, (k + 1) % 3)] = near[mesh.F(f, (k + 2) % 3)] = true;
  for (int v = 0; v < mesh.num_vertices(); ++v) far += !near[v] && once[v] != 0;
  EXPECT_EQ(far, 0);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) == 0) {
        EXPECT_GT(once[mesh.F(f, (k + 1) % 3)], 0.0);
      }
}

// With project_onto, the repair judges and keeps positions on that other surface: here the
// parameterized surface is a coarse ellipsoid and the vertices live on a finer one. Every
// vertex ends on the fine surface, the smallest Q it reports is that of the final positions,
// and it went up.
TEST(TriangleRepair, ProjectsItsMovesOntoTheOriginalInput) {
  const TriMesh coarse = ellipsoid(2), fine = ellipsoid(5);
  const Parameterization param = parameterize(coarse);
  const DomainMesh domain(param.domain, param.surface.F);
  const SurfaceLocator on_fine(fine);
  const TriMesh grid = icosphere(3);
  RowMatrixX3d U = grid.V.rowwise().normalized();
  const RowMatrixX3i& F = grid.F;
  for (int f = 0; f < 300; f += 30) {
    const int v = F(f, 0), w = F(f, 1);
    const Eigen::RowVector3d before = U.row(v);
    U.row(v) = (0.2 * U.row(v) + 0.8 * U.row(w)).normalized();
    if (count_flipped(U, F) > 0) U.row(v) = before;
  }
  std::vector<int> hints(U.rows(), 0);
  RowMatrixX3d X = lift_to_surface(domain, param.surface.V, U, hints);
  for (int v = 0; v < X.rows(); ++v) X.row(v) = on_fine.closest(X.row(v).transpose()).point.transpose();
  const double diag = bounding_box_diagonal(fine.V);
  ASSERT_GT(on_fine.distances(lift_to_surface(domain, param.surface.V, U, hints)).maxCoeff(), 1e-3 * diag);
  TriangleRepairOptions options;
  options.project_onto = &on_fine;
  const TriangleRepairStats stats = repair_worst_triangles(DomainKind::sphere, F, domain, param.surface.V, U, X, hints, options);
  EXPECT_GT(stats.moves, 0);
  EXPECT_GT(stats.q_min_after, stats.q_min_before + 0.2);
  EXPECT_NEAR(stats.q_min_after, mesh_quality(TriMesh{X, F}).q_min, 1e-12);
  EXPECT_LT(on_fine.distances(X).maxCoeff(), 1e-9 * diag);
  EXPECT_EQ(count_flipped(U, F), 0);
}

// Tip snapping: on a coarse even layout of the ellipsoid, whose long-axis ends it cuts off,
// vertices snap exactly onto input vertices, the largest input-to-level distance goes down,
// nothing flips, and every snapped vertex's triangles keep the quality and angle bounds.
TEST(FeatureSnap, SnapsVerticesOntoTheTipsTheLevelCutsOff) {
  const TriMesh input = ellipsoid(4);
  const Parameterization param = parameterize(input);
  const DomainMesh domain(param.domain, param.surface.F);
  const TriMesh grid = icosphere(2);
  RowMatrixX3d U = grid.V.rowwise().normalized();
  const RowMatrixX3i& F = grid.F;
  std::vector<int> hints(U.rows(), 0);
  RowMatrixX3d X = lift_to_surface(domain, param.surface.V, U, hints);
  const RowMatrixX3d X0 = X;
  const double before = SurfaceLocator(TriMesh{X, F}).distances(param.surface.V).maxCoeff();
  FeatureSnapOptions options;
  const int snaps = snap_to_input_tips(DomainKind::sphere, F, domain, param.surface.V, U, X, hints, options);
  EXPECT_GT(snaps, 0);
  EXPECT_LE(snaps, options.max_snaps);
  EXPECT_EQ(count_flipped(U, F), 0);
  const double after = SurfaceLocator(TriMesh{X, F}).distances(param.surface.V).maxCoeff();
  EXPECT_LT(after, before);
  std::vector<int> fresh(U.rows(), 0);
  EXPECT_LT((lift_to_surface(domain, param.surface.V, U, fresh) - X).cwiseAbs().maxCoeff(), 1e-9);
  int moved = 0;
  for (int v = 0; v < X.rows(); ++v) {
    if (X.row(v) == X0.row(v)) continue;
    ++moved;
    // Exactly an input vertex.
    double nearest = std::numeric_limits<double>::infinity();
    for (int s = 0; s < param.surface.num_vertices(); ++s) nearest = std::min(nearest, (param.surface.V.row(s) - X.row(v)).norm());
    EXPECT_EQ(nearest, 0.0);
    for (int f = 0; f < F.rows(); ++f) {
      if (F(f, 0) != v && F(f, 1) != v && F(f, 2) != v) continue;
      const QualityReport q = mesh_quality(TriMesh{X, RowMatrixX3i(F.row(f))});
      EXPECT_GE(q.q_min, options.min_quality - 1e-12);
      EXPECT_GE(q.min_angle_deg, options.min_angle_deg - 1e-9);
    }
  }
  EXPECT_EQ(moved, snaps);
}

}  // namespace
}  // namespace mrsnake
