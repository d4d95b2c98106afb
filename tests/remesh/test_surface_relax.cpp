// Tests of the tangential smoothing on the surface (remesh/shape_smoothing.h): the
// area-centroid target (a Lloyd step on the surface, with an optional density) and the rim
// vertices of a disk sliding along the rim.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "mesh/distance.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "remesh/domain.h"
#include "remesh/lift.h"
#include "remesh/parameterization.h"
#include "remesh/remesh.h"
#include "remesh/shape_smoothing.h"
#include "tests/remesh/remesh_shapes.h"

namespace mrsnake {
namespace {

using test::ellipsoid;
using test::EllipsoidLayout;
using test::spherical_cap;

std::vector<double> face_areas(const RowMatrixX3d& X, const RowMatrixX3i& F) {
  std::vector<double> a(F.rows());
  for (int f = 0; f < F.rows(); ++f)
    a[f] = 0.5 * (X.row(F(f, 1)) - X.row(F(f, 0))).cross(X.row(F(f, 2)) - X.row(F(f, 0))).norm();
  return a;
}

double coefficient_of_variation(const std::vector<double>& x) {
  double mean = 0, square = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  for (double v : x) square += (v - mean) * (v - mean);
  return std::sqrt(square / static_cast<double>(x.size())) / mean;
}

// An even triangulation of the sphere D is uneven on the ellipsoid (the parameterization
// stretches the ends); the area-centroid target evens out the 3D areas, flips nothing and
// leaves every vertex the exact lift of its domain position.
TEST(SurfaceRelaxation, EvensOutTriangleAreasOnTheSurfaceWithoutFlips) {
  EllipsoidLayout s;
  const RowMatrixX3i& F = s.grid.F;
  ASSERT_EQ(count_flipped(s.U, F), 0);
  const double cv_before = coefficient_of_variation(face_areas(s.X, F));
  ShapeSmoothingOptions options;
  options.iterations = 30;
  options.step = 1.0;
  options.target = SmoothingTarget::area_centroid;
  const int moves =
      smooth_shapes_in_domain(DomainKind::sphere, F, s.domain, s.param.surface.V, s.U, s.X, s.hints, options);
  EXPECT_GT(moves, 0);
  const double cv_after = coefficient_of_variation(face_areas(s.X, F));
  EXPECT_LT(cv_after, 0.8 * cv_before) << cv_before << " -> " << cv_after;
  EXPECT_EQ(count_flipped(s.U, F), 0);
  for (int v = 0; v < s.U.rows(); ++v) EXPECT_NEAR(s.U.row(v).norm(), 1.0, 1e-12);
  std::vector<int> fresh(s.U.rows(), 0);
  EXPECT_LT((lift_to_surface(s.domain, s.param.surface.V, s.U, fresh) - s.X).cwiseAbs().maxCoeff(), 1e-9);
  const SurfaceLocator locator(s.input);
  EXPECT_LT(locator.distances(s.X).maxCoeff(), 1e-9 * bounding_box_diagonal(s.input.V));
}

// A wanted density twice as high on the x > 0 half gives smaller triangles there: the
// weight area x density² makes the point density follow the density (ideal area ratio 1/2;
// measured 0.62 after 30 steps).
// Without the density both halves end up alike.
TEST(SurfaceRelaxation, DensityMakesTrianglesSmallerWhereItIsHigher) {
  auto area_ratio = [](bool weighted) {
    EllipsoidLayout s;
    const RowMatrixX3i& F = s.grid.F;
    Eigen::VectorXd density(s.param.surface.num_vertices());
    for (int v = 0; v < density.size(); ++v) density[v] = s.param.surface.V(v, 0) > 0 ? 2.0 : 1.0;
    ShapeSmoothingOptions options;
    options.iterations = 30;
    options.step = 1.0;
    options.target = SmoothingTarget::area_centroid;
    if (weighted) options.surface_density = &density;
    smooth_shapes_in_domain(DomainKind::sphere, F, s.domain, s.param.surface.V, s.U, s.X, s.hints, options);
    EXPECT_EQ(count_flipped(s.U, F), 0);
    const std::vector<double> area = face_areas(s.X, F);
    double dense = 0, sparse = 0;
    int n_dense = 0, n_sparse = 0;
    for (int f = 0; f < F.rows(); ++f) {
      const double x = (s.X(F(f, 0), 0) + s.X(F(f, 1), 0) + s.X(F(f, 2), 0)) / 3;
      if (x > 0.5) {
        dense += area[f];
        ++n_dense;
      }
      if (x < -0.5) {
        sparse += area[f];
        ++n_sparse;
      }
    }
    return (dense / n_dense) / (sparse / n_sparse);
  };
  const double even = area_ratio(false), weighted = area_ratio(true);
  EXPECT_NEAR(even, 1.0, 0.1);
  EXPECT_LT(weighted, 0.72);  // a density not squared gives about 0.8
  EXPECT_GT(weighted, 0.35);
}

// The quality floor: every triangle a move changes is in the moved vertex's star, so the
// mesh's smallest Q never ends below min(its value before, floor). Without the floor a
// density jump (3:1 across x = 0) on a layout first smoothed for shapes pulls it lower.
TEST(SurfaceRelaxation, QualityFloorKeepsTheWorstTriangle) {
  auto smallest_q = [](const RowMatrixX3d& X, const RowMatrixX3i& F) {
    double q = 1;
    for (int f = 0; f < F.rows(); ++f)
      q = std::min(q, frey_borouchaki_quality(X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))));
    return q;
  };
  std::vector<double> after;
  double before = 0;
  const double floor = 0.95;
  for (double quality_floor : {floor, 0.0}) {
    EllipsoidLayout s;
    ShapeSmoothingOptions shapes;
    shapes.iterations = 30;
    smooth_shapes_in_domain(DomainKind::sphere, s.grid.F, s.domain, s.param.surface.V, s.U, s.X, s.hints, shapes);
    before = smallest_q(s.X, s.grid.F);
    Eigen::VectorXd density(s.param.surface.num_vertices());
    for (int v = 0; v < density.size(); ++v) density[v] = s.param.surface.V(v, 0) > 0 ? 3.0 : 1.0;
    ShapeSmoothingOptions options;
    options.surface_density = &density;
    options.iterations = 30;
    options.step = 1.0;
    options.target = SmoothingTarget::area_centroid;
    options.quality_floor = quality_floor;
    EXPECT_GT(
        smooth_shapes_in_domain(DomainKind::sphere, s.grid.F, s.domain, s.param.surface.V, s.U, s.X, s.hints, options),
        0);
    EXPECT_EQ(count_flipped(s.U, s.grid.F), 0);
    after.push_back(smallest_q(s.X, s.grid.F));
  }
  EXPECT_GE(after[0], std::min(before, floor) - 1e-12);
  EXPECT_LT(after[1], std::min(before, floor) - 0.01) << before << " " << after[0];
}

// Disk rim: with move_rim the rim vertices slide along the rim (they stay on the unit circle
// in D, on the input's boundary in 3D) and even out the rim's edge lengths; without it they
// do not move at all.
TEST(SurfaceRelaxation, RimVerticesSlideAlongTheRimAndStayOnTheCircle) {
  const TriMesh input = spherical_cap(4);
  const Parameterization param = parameterize(input);
  const DomainMesh domain(param.domain, param.surface.F);
  RemeshOptions plain;
  plain.levels = 2;
  plain.base_vertices = 24;
  plain.relax = RelaxMode::none;
  plain.compute_stats = false;
  const RemeshResult r = remesh(input, plain);
  const RowMatrixX3i& F = r.connectivity.faces.back();
  RowMatrixX3d U0 = r.levels.back().domain_positions;
  const int n = static_cast<int>(U0.rows());
  const std::vector<bool> rim = boundary_vertices(F, n);
  // Turn every other rim vertex by a small angle along the circle (skipping turns that flip).
  int turned = 0;
  for (int v = 0, k = 0; v < n; ++v) {
    if (!rim[v] || (k++ % 2)) continue;
    const Eigen::RowVector3d before = U0.row(v);
    const double angle = std::atan2(U0(v, 1), U0(v, 0)) + 0.03;
    U0.row(v) << std::cos(angle), std::sin(angle), 1.0;
    if (count_flipped(U0, F) > 0)
      U0.row(v) = before;
    else
      ++turned;
  }
  ASSERT_GT(turned, 4);
  auto rim_cv = [&](const RowMatrixX3d& X) {
    std::vector<double> lengths;
    for (int f = 0; f < F.rows(); ++f)
      for (int e = 0; e < 3; ++e) {
        const int a = F(f, e), b = F(f, (e + 1) % 3);
        bool twin = false;
        for (int g = 0; g < F.rows() && !twin; ++g)
          for (int k = 0; k < 3; ++k) twin = twin || (F(g, k) == b && F(g, (k + 1) % 3) == a);
        if (!twin) lengths.push_back((X.row(a) - X.row(b)).norm());
      }
    return coefficient_of_variation(lengths);
  };
  for (bool move_rim : {false, true}) {
    SCOPED_TRACE(move_rim);
    RowMatrixX3d U = U0;
    std::vector<int> hints(n, 0);
    RowMatrixX3d X = lift_to_surface(domain, param.surface.V, U, hints);
    const double before = rim_cv(X);
    ShapeSmoothingOptions options;
    options.iterations = 10;
    options.move_rim = move_rim;
    smooth_shapes_in_domain(DomainKind::disk, F, domain, param.surface.V, U, X, hints, options);
    EXPECT_EQ(count_flipped(U, F), 0);
    for (int v = 0; v < n; ++v) {
      if (!rim[v]) continue;
      EXPECT_NEAR(std::hypot(U(v, 0), U(v, 1)), 1.0, 1e-12);
      if (!move_rim) {
        EXPECT_TRUE(U.row(v) == U0.row(v));
      }
    }
    if (move_rim) {
      EXPECT_LT(rim_cv(X), 0.7 * before) << before << " -> " << rim_cv(X);
    }
    // Still on the input (the rim lifts onto the input's boundary polygon).
    const SurfaceLocator locator(input);
    EXPECT_LT(locator.distances(X).maxCoeff(), 1e-9 * bounding_box_diagonal(input.V));
  }
}

// The surface relaxation runs whenever all vertices relax, also without shape rounds: with
// relaxation.shape_iterations = 0 it still moves vertices (shape_moves counts them, and the positions
// differ from those without it).
TEST(SurfaceRelaxation, RunsWithoutShapeIterations) {
  const TriMesh input = ellipsoid(4);
  RemeshOptions o;
  o.levels = 1;
  o.base_vertices = 20;
  o.compute_stats = false;
  o.relaxation.shape_iterations = 0;
  o.snap.max_snaps = 0;
  o.repair.sweeps = 0;
  o.relaxation.surface_iterations = 0;
  const RemeshResult without = remesh(input, o);
  o.relaxation.surface_iterations = 3;
  const RemeshResult with = remesh(input, o);
  for (int j = 0; j <= 1; ++j) {
    SCOPED_TRACE(j);
    EXPECT_EQ(without.levels[j].stats["shape_moves"].get<int>(), 0);
    EXPECT_GT(with.levels[j].stats["shape_moves"].get<int>(), 0);
    EXPECT_GT((with.levels[j].positions - without.levels[j].positions).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_EQ(count_flipped(with.levels[j].domain_positions, with.connectivity.faces[j]), 0);
  }
}

}  // namespace
}  // namespace mrsnake
