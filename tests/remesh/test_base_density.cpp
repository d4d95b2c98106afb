// Tests of the base mesh's density-scaled farthest-point sampling and its flips on a one-chart
// map, the 1-ring smoothing of a vertex field, and the triangle repair that projects its moves
// onto another surface (the original input of a simplified one).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "mesh/distance.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "remesh/base_mesh.h"
#include "remesh/domain.h"
#include "remesh/feature_snap.h"
#include "remesh/lift.h"
#include "remesh/parameterization.h"
#include "remesh/remesh.h"
#include "remesh/sizing.h"
#include "remesh/triangle_repair.h"
#include "tests/remesh/remesh_shapes.h"

namespace mrsnake {
namespace {

using test::ellipsoid;
using test::EllipsoidLayout;

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

// On a sphere of radius r (κ = 1/r), spacing at most b·r asks for its area over an
// equilateral vertex's share, 4πr² / (√3/2 (b r)²) = 8π / (√3 b²) points, at any r.
TEST(Sizing, TheBendBoundOnASphereAsksForItsAreaOverTheSpacingSquared) {
  for (const double r : {0.01, 1.0, 300.0}) {
    TriMesh sphere = icosphere(4);
    sphere.V *= r;
    const Eigen::VectorXd kappa = Eigen::VectorXd::Constant(sphere.num_vertices(), 1.0 / r);
    EXPECT_NEAR(vertex_areas(sphere).sum(), 4 * 3.14159265358979 * r * r, 0.01 * 4 * 3.14159265358979 * r * r);
    EXPECT_NEAR(bend_bound_points(sphere, kappa, 2.0), 8 * 3.14159265358979 / (std::sqrt(3.0) * 4), 0.05) << r;
  }
}

// Curvature φ on the cap x > 0.5 only (a quarter of the area), density 1 everywhere. Where the bound is slack the
// density comes back unchanged. Where it is not, the bent half gets the bound's own density,
// with the scale t of the rest set so that Σ area·max(t·1, floor) is the points asked for.
// Where the bound alone would take more than half of the points, it is scaled to half.
TEST(Sizing, TheBendBoundRaisesTheDensityOnlyWhereItIsTight) {
  const TriMesh sphere = icosphere(3);
  const int n = sphere.num_vertices();
  const Eigen::VectorXd area = vertex_areas(sphere);
  Eigen::VectorXd kappa = Eigen::VectorXd::Zero(n);
  for (int v = 0; v < n; ++v)
    if (sphere.V(v, 0) > 0.5) kappa[v] = 3.0;
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  const double bound = bend_bound_points(sphere, kappa, 1.0);
  EXPECT_TRUE(bend_bounded_density(sphere, ones, kappa, 100 * bound, 1.0) == ones);

  const double bent_area = area.dot((kappa.array() > 0).cast<double>().matrix());
  for (const double points : {3.0 * bound, 1.0 * bound}) {
    const Eigen::VectorXd raised = bend_bounded_density(sphere, ones, kappa, points, 1.0);
    const double floor = 2.0 / std::sqrt(3.0) * 9.0 * std::min(1.0, 0.5 * points / bound);
    const double t = (points - bent_area * floor) / (area.sum() - bent_area);
    for (int v = 0; v < n; ++v)
      EXPECT_NEAR(raised[v], kappa[v] > 0 ? floor / t : 1.0, 1e-6 * floor / t) << points << " " << v;
  }
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
  const RowMatrixX3i& F = grid.F;
  RowMatrixX3d U = test::sheared_layout(grid.V.rowwise().normalized(), F);
  std::vector<int> hints(U.rows(), 0);
  RowMatrixX3d X = lift_to_surface(domain, param.surface.V, U, hints);
  for (int v = 0; v < X.rows(); ++v) X.row(v) = on_fine.closest(X.row(v).transpose()).point.transpose();
  const double diag = bounding_box_diagonal(fine.V);
  ASSERT_GT(on_fine.distances(lift_to_surface(domain, param.surface.V, U, hints)).maxCoeff(), 1e-3 * diag);
  TriangleRepairOptions options;
  options.project_onto = &on_fine;
  const TriangleRepairStats stats =
      repair_worst_triangles(DomainKind::sphere, F, domain, param.surface.V, U, X, hints, options);
  EXPECT_GT(stats.moves, 0);
  EXPECT_GT(stats.q_min_after, stats.q_min_before + 0.2);
  EXPECT_NEAR(stats.q_min_after, mesh_quality(TriMesh{X, F}).q_min, 1e-12);
  EXPECT_LT(on_fine.distances(X).maxCoeff(), 1e-9 * diag);
  EXPECT_EQ(count_flipped(U, F), 0);
}

// Tip snapping: on a coarse even layout of the ellipsoid, whose long-axis ends it cuts off,
// vertices snap onto input vertices (or part of the way, on the input), the largest
// input-to-level distance goes down, nothing flips, and every snapped vertex's triangles keep
// the quality and angle bounds.
TEST(FeatureSnap, SnapsVerticesOntoTheTipsTheLevelCutsOff) {
  EllipsoidLayout layout(2);
  const Parameterization& param = layout.param;
  const DomainMesh& domain = layout.domain;
  const RowMatrixX3i& F = layout.grid.F;
  RowMatrixX3d &U = layout.U, &X = layout.X;
  std::vector<int>& hints = layout.hints;
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
  int moved = 0, whole_way = 0;
  for (int v = 0; v < X.rows(); ++v) {
    if (X.row(v) == X0.row(v)) continue;
    ++moved;
    // Exactly an input vertex, or part of the way there on the input (X is U's lift, above).
    double nearest = std::numeric_limits<double>::infinity();
    for (int s = 0; s < param.surface.num_vertices(); ++s)
      nearest = std::min(nearest, (param.surface.V.row(s) - X.row(v)).norm());
    if (nearest == 0.0) ++whole_way;
    for (int f = 0; f < F.rows(); ++f) {
      if (F(f, 0) != v && F(f, 1) != v && F(f, 2) != v) continue;
      const QualityReport q = mesh_quality(TriMesh{X, RowMatrixX3i(F.row(f))});
      EXPECT_GE(q.q_min, options.min_quality - 1e-12);
      EXPECT_GE(q.min_angle_deg, options.min_angle_deg - 1e-9);
    }
  }
  EXPECT_EQ(moved, snaps);
  std::printf("%d snaps, %d the whole way\n", snaps, whole_way);
}

// A flat triangle grid (the level, 7 x 7 vertices, unit edges) and an input that is the same
// grid with a spike: the face (nearest, next, third) replaced by three faces to a tip above it.
// D is the plane the grid lies in.
struct SpikedGrid {
  static constexpr int n = 7;
  static int at(int i, int j) { return j * n + i; }
  const int nearest = at(3, 3), next = at(4, 3), third = at(3, 4), tip_vertex = n * n;
  RowMatrixX3d X, input_V;
  RowMatrixX3i F, input_F;

  // `pulled` moves a neighbour of `nearest` (only) toward the tip's side first.
  SpikedGrid(const Eigen::RowVector3d& tip, bool pulled) : X(n * n, 3), input_V(n * n + 1, 3) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) X.row(at(i, j)) << i + 0.5 * j, j * std::sqrt(3.0) / 2, 0;
    if (pulled) X.row(at(3, 2)) << 4.45, 1.376, 0;
    std::vector<Eigen::RowVector3i> faces;
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        faces.emplace_back(at(i, j), at(i + 1, j), at(i, j + 1));
        faces.emplace_back(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
    F.resize(static_cast<Eigen::Index>(faces.size()), 3);
    input_F.resize(F.rows() + 2, 3);
    int rows = 0;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      F.row(static_cast<Eigen::Index>(f)) = faces[f];
      if (faces[f] != Eigen::RowVector3i(nearest, next, third)) input_F.row(rows++) = faces[f];
    }
    input_F.row(rows++) << nearest, next, tip_vertex;
    input_F.row(rows++) << next, third, tip_vertex;
    input_F.row(rows++) << third, nearest, tip_vertex;
    input_V << X, tip;
  }

  // Whether v's triangles, v at x, keep the snap's bounds.
  bool bounds_hold(int v, const Eigen::RowVector3d& x, const FeatureSnapOptions& options) const {
    const VertexStars stars(F, n * n);
    RowMatrixX3d moved = X;
    moved.row(v) = x;
    for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
      const QualityReport q = mesh_quality(TriMesh{moved, RowMatrixX3i(F.row(stars.faces[i]))});
      if (q.q_min < options.min_quality || q.min_angle_deg < options.min_angle_deg) return false;
    }
    return true;
  }

  // Puts a second tip at `height` above the face (at(1, 1), at(2, 1), at(1, 2)), far from the first.
  void add_tip(double height) {
    const int a = at(1, 1), b = at(2, 1), c = at(1, 2), tip = static_cast<int>(input_V.rows());
    input_V.conservativeResize(tip + 1, 3);
    input_V.row(tip) = (X.row(a) + X.row(b) + X.row(c)) / 3 + Eigen::RowVector3d(0, 0, height);
    RowMatrixX3i faces(input_F.rows() + 2, 3);
    int rows = 0;
    for (int f = 0; f < input_F.rows(); ++f)
      if (input_F.row(f) != Eigen::RowVector3i(a, b, c)) faces.row(rows++) = input_F.row(f);
    faces.row(rows++) << a, b, tip;
    faces.row(rows++) << b, c, tip;
    faces.row(rows++) << c, a, tip;
    input_F = faces;
  }

  // The snap, with v moved the fraction t of the way in the plane; the snapped mask. With
  // `input_faces`, the domain gives each input vertex's level face.
  std::pair<int, std::vector<bool>> snap(const FeatureSnapOptions& options,
                                         std::function<std::vector<int>()> input_faces = {}) {
    const SnapInDomain flat{[&](int v, int s, double t) -> std::optional<Eigen::Vector3d> {
                              return Eigen::Vector3d(((1 - t) * X.row(v) + t * input_V.row(s)).transpose());
                            },
                            [](int, int, double) {}, [] {}, std::move(input_faces)};
    std::vector<bool> snapped;
    const int snaps =
        snap_level_to_input_tips(F, X, input_V, input_F, boundary_vertices(F, n * n),
                                 boundary_vertices(input_F, static_cast<int>(input_V.rows())), flat, options, &snapped);
    return {snaps, snapped};
  }
};

// A tip whose nearest level vertex cannot take it (a neighbour pulled in makes that vertex's
// triangles too thin there) is snapped by the next corner of its face that can.
TEST(FeatureSnap, ATipTheNearestCornerCannotTakeGoesToTheNextCorner) {
  const Eigen::RowVector3d tip(4.937, 2.726, 0.454);  // above the face (nearest, next, third)
  SpikedGrid g(tip, true);
  const FeatureSnapOptions options;
  ASSERT_LT((g.X.row(g.nearest) - tip).head<2>().norm(), (g.X.row(g.next) - tip).head<2>().norm());
  ASSERT_FALSE(g.bounds_hold(g.nearest, tip, options));
  ASSERT_TRUE(g.bounds_hold(g.next, tip, options));
  const RowMatrixX3d X0 = g.X;
  const auto [snaps, snapped] = g.snap(options);
  ASSERT_EQ(snaps, 1);
  EXPECT_TRUE(snapped[g.next]);
  EXPECT_TRUE(g.X.row(g.next) == tip);
  for (int v = 0; v < g.X.rows(); ++v) {
    if (v != g.next) {
      EXPECT_TRUE(g.X.row(v) == X0.row(v)) << v;
    }
  }
}

// A tip too high for any corner to take it the whole way is taken part of the way, as far as
// the bounds allow (to the bisection's 1/40), by the nearest corner: the tip comes closer.
TEST(FeatureSnap, ATipNoCornerCanTakeIsTakenPartOfTheWay) {
  const Eigen::RowVector3d tip(4.9, 2.748, 1.3);
  SpikedGrid g(tip, false);
  const FeatureSnapOptions options;
  for (int v : {g.nearest, g.next, g.third}) ASSERT_FALSE(g.bounds_hold(v, tip, options)) << v;
  const Eigen::RowVector3d start = g.X.row(g.nearest);
  const auto part_of_the_way = [&](double t) { return Eigen::RowVector3d((1 - t) * start + t * tip); };
  ASSERT_TRUE(g.bounds_hold(g.nearest, part_of_the_way(0.5), options));
  const double before = SurfaceLocator(TriMesh{g.X, g.F}).closest(tip.transpose()).distance;
  const auto [snaps, snapped] = g.snap(options);
  ASSERT_EQ(snaps, 1);
  EXPECT_TRUE(snapped[g.nearest]);
  const double t = g.X(g.nearest, 2) / tip.z();  // the grid is flat: the height tells the fraction
  EXPECT_GE(t, 0.5);
  EXPECT_LT((g.X.row(g.nearest) - part_of_the_way(t)).norm(), 1e-12);
  EXPECT_TRUE(g.bounds_hold(g.nearest, part_of_the_way(t), options));
  EXPECT_FALSE(g.bounds_hold(g.nearest, part_of_the_way(t + 0.025), options));
  EXPECT_LT(SurfaceLocator(TriMesh{g.X, g.F}).closest(tip.transpose()).distance, 0.5 * before);
}

// Faces in D that overstate the distances change neither which tips are far enough to try nor
// the decision to keep the snaps: both are made on the exact largest distance. The faces are
// the nearest ones; or a rim corner of the input is given the face at the level's far corner,
// 21 times the largest distance away; or every input vertex but the two tips is, so that
// measuring the exact largest distance takes more than the 32 scans of the whole level after
// which it builds a closest-point tree (that face's corners are on the level's rim, so no snap
// is tried from them). The first tip's snap is undone when a second tip, out of the snap
// budget, stays above 3/4 of the first tip's height, and kept when it is below.
TEST(FeatureSnap, KeepsSnapsOnTheExactLargestDistanceWhenTheFacesInDOverstateIt) {
  enum class Faces { nearest, one_overstated, all_but_the_tips_overstated };
  const Eigen::RowVector3d tip(4.937, 2.726, 0.454);  // the snap takes it with the corner `next`
  for (const double second_height : {0.40, 0.20})
    for (const Faces given : {Faces::nearest, Faces::one_overstated, Faces::all_but_the_tips_overstated}) {
      SCOPED_TRACE(std::to_string(second_height) + " faces " + std::to_string(static_cast<int>(given)));
      SpikedGrid g(tip, true);
      g.add_tip(second_height);
      const SurfaceLocator level(TriMesh{g.X, g.F});
      const int far_corner_face = static_cast<int>(g.F.rows()) - 1;
      std::vector<int> faces(g.input_V.rows());
      for (int s = 0; s < g.input_V.rows(); ++s) faces[s] = level.closest(g.input_V.row(s).transpose()).face;
      if (given == Faces::one_overstated) faces[SpikedGrid::at(0, 0)] = far_corner_face;
      if (given == Faces::all_but_the_tips_overstated)
        for (int s = 0; s < g.tip_vertex; ++s) faces[s] = far_corner_face;
      FeatureSnapOptions options;
      options.max_snaps = 1;
      const RowMatrixX3d X0 = g.X;
      const double largest = level.distances(g.input_V).maxCoeff();
      ASSERT_DOUBLE_EQ(largest, tip.z());
      const auto [snaps, snapped] = g.snap(options, [&] { return faces; });
      if (second_height > (1 - options.min_gain) * largest) {
        EXPECT_EQ(snaps, 0);
        EXPECT_TRUE(g.X == X0);
      } else {
        EXPECT_EQ(snaps, 1);
        EXPECT_TRUE(snapped[g.next]);
        EXPECT_LE(SurfaceLocator(TriMesh{g.X, g.F}).distances(g.input_V).maxCoeff(), (1 - options.min_gain) * largest);
      }
    }
}

// A snap must bring the input around the vertex really closer to the level: asking for the
// largest distance there to drop to zero refuses every snap (the input between the level's
// vertices stays off its flat triangles), and leaves U, X and hints as they were; a zero
// budget snaps nothing either.
TEST(FeatureSnap, RefusesSnapsThatDoNotBringTheInputCloser) {
  for (const bool zero_budget : {false, true}) {
    SCOPED_TRACE(zero_budget);
    EllipsoidLayout s(2);
    const EllipsoidLayout before(2);
    FeatureSnapOptions options;
    if (zero_budget)
      options.max_snaps = 0;
    else
      options.min_gain = 1.0;
    std::vector<bool> snapped(3, true);
    EXPECT_EQ(snap_to_input_tips(DomainKind::sphere, s.grid.F, s.domain, s.param.surface.V, s.U, s.X, s.hints, options,
                                 &snapped),
              0);
    EXPECT_TRUE(s.U == before.U);
    EXPECT_TRUE(s.X == before.X);
    EXPECT_TRUE(s.hints == before.hints);
    EXPECT_EQ(snapped, std::vector<bool>(s.U.rows(), false));
  }
}

// The repair keeps the vertices of its fixed mask exactly where they are (U, X and hints),
// and still repairs the others.
TEST(TriangleRepair, KeepsFixedVerticesInPlace) {
  EllipsoidLayout s(3, true);
  const RowMatrixX3i& F = s.grid.F;
  RowMatrixX3d &U = s.U, &X = s.X;
  std::vector<int>& hints = s.hints;
  // Fix one corner of each of the 5 worst triangles: those the repair would move first.
  std::vector<std::pair<double, int>> worst;
  for (int f = 0; f < F.rows(); ++f) worst.emplace_back(mesh_quality(TriMesh{X, RowMatrixX3i(F.row(f))}).q_min, f);
  std::sort(worst.begin(), worst.end());
  std::vector<bool> fixed(U.rows(), false);
  for (int i = 0; i < 5; ++i)
    for (int k = 0; k < 3; ++k) fixed[F(worst[i].second, k)] = true;
  const RowMatrixX3d U0 = U, X0 = X;
  const std::vector<int> hints0 = hints;
  TriangleRepairOptions options;
  options.fixed = &fixed;
  const TriangleRepairStats stats =
      repair_worst_triangles(DomainKind::sphere, F, s.domain, s.param.surface.V, U, X, hints, options);
  EXPECT_GT(stats.moves, 0);
  int moved = 0;
  for (int v = 0; v < U.rows(); ++v) {
    if (fixed[v]) {
      EXPECT_TRUE(U.row(v) == U0.row(v)) << v;
      EXPECT_TRUE(X.row(v) == X0.row(v)) << v;
      EXPECT_EQ(hints[v], hints0[v]) << v;
    } else if (!(X.row(v) == X0.row(v))) {
      ++moved;
    }
  }
  EXPECT_GT(moved, 0);
  EXPECT_EQ(count_flipped(U, F), 0);
  // Without the mask the repair does move some of those vertices.
  RowMatrixX3d U1 = U0, X1 = X0;
  std::vector<int> hints1 = hints0;
  repair_worst_triangles(DomainKind::sphere, F, s.domain, s.param.surface.V, U1, X1, hints1, TriangleRepairOptions{});
  int fixed_would_move = 0;
  for (int v = 0; v < U.rows(); ++v)
    if (fixed[v] && !(X1.row(v) == X0.row(v))) ++fixed_would_move;
  EXPECT_GT(fixed_would_move, 0);
}

// Whatever the options, snaps are kept only if together they lower the largest input-to-level
// distance by min_gain; otherwise nothing moves.
TEST(FeatureSnap, KeepsSnapsOnlyIfTheLargestDistanceDrops) {
  int kept = 0;
  for (const double share : {0.0, 0.5, 0.9})
    for (const double gain : {0.05, 0.25, 0.6}) {
      SCOPED_TRACE(std::to_string(share) + " " + std::to_string(gain));
      EllipsoidLayout s(2);
      const EllipsoidLayout before(2);
      FeatureSnapOptions options;
      options.min_share_of_largest = share;
      options.min_gain = gain;
      const double largest = SurfaceLocator(TriMesh{s.X, s.grid.F}).distances(s.param.surface.V).maxCoeff();
      const int snaps =
          snap_to_input_tips(DomainKind::sphere, s.grid.F, s.domain, s.param.surface.V, s.U, s.X, s.hints, options);
      if (snaps == 0) {
        EXPECT_TRUE(s.U == before.U && s.X == before.X && s.hints == before.hints);
        continue;
      }
      ++kept;
      EXPECT_LE(SurfaceLocator(TriMesh{s.X, s.grid.F}).distances(s.param.surface.V).maxCoeff(),
                (1 - gain) * largest + 1e-12);
    }
  EXPECT_GT(kept, 0);
}
// snap.max_snaps = 0 in the remesher: no vertex snaps (snapped_vertices 0 on every level).
TEST(FeatureSnap, RemeshWithZeroSnapTipsSnapsNothing) {
  RemeshOptions o;
  o.levels = 1;
  o.base_vertices = 20;
  o.compute_stats = false;
  o.snap.max_snaps = 0;
  const RemeshResult r = remesh(ellipsoid(3), o);
  for (const RemeshLevel& level : r.levels) EXPECT_EQ(level.stats["snapped_vertices"].get<int>(), 0);
}

// The base's mean Q on the surface: its faces over the samples' 3D points.
double mean_base_quality(const BaseMesh& base, const TriMesh& surface) {
  TriMesh on_surface;
  on_surface.V.resize(static_cast<Eigen::Index>(base.samples.size()), 3);
  for (std::size_t i = 0; i < base.samples.size(); ++i)
    on_surface.V.row(static_cast<Eigen::Index>(i)) = surface.V.row(base.samples[i]);
  on_surface.F = base.faces;
  return mesh_quality(on_surface).q_mean;
}

// A capsule 5 radii long under the one-chart map: the sphere's Delaunay triangulation of the
// samples has edges well past Delaunay on the surface, where the map squeezes the tube. The
// margin's flips raise the base triangles' mean quality on the surface (measured: 0.733 ->
// 0.764 with 40 base vertices, 0.753 -> 0.771 with 127); with a margin of 180° none is made.
TEST(BaseMeshDensity, OneChartBaseEdgesFarPastDelaunayOnTheSurfaceAreFlipped) {
  const TriMesh input = test::capsule(5.0, 24);
  const Parameterization param = parameterize(input);
  ASSERT_NE(param.sphere_map, SphereMap::hierarchical);
  for (int n0 : {40, 127}) {
    SCOPED_TRACE(n0);
    const BaseMesh flipped = build_base_mesh(param, n0, 3, nullptr, kOneChartFlipMarginDeg);
    const BaseMesh sphere_delaunay = build_base_mesh(param, n0, 3, nullptr, 180.0);
    EXPECT_GT(flipped.surface_flips, 0);
    EXPECT_EQ(sphere_delaunay.surface_flips, 0);
    EXPECT_EQ(count_flipped(flipped.domain, flipped.faces), 0);
    EXPECT_GT(mean_base_quality(flipped, param.surface), mean_base_quality(sphere_delaunay, param.surface) + 0.01);
  }
}

}  // namespace
}  // namespace mrsnake
