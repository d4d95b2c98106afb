// The mean value parameterization (remesh/mean_value.cpp, remesh/parameterization.cpp):
// whatever the ordering and factorization, the disk map must solve Floater's mean value system
// and equal CGAL's mean value parameterizer; the two-halves sphere map must glue its halves into
// an embedding with a clean cut.
#include <gtest/gtest.h>

#include <CGAL/Eigen_solver_traits.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/Circular_border_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Mean_value_coordinates_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <Eigen/SVD>
#include <Eigen/SparseLU>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "mesh/errors.h"
#include "mesh/topology.h"
#include "remesh/parameterization.h"
#include "tests/remesh/remesh_shapes.h"

using namespace mrsnake;

namespace {

// Mean value weights: w_ij = (tan(a/2) + tan(b/2)) / |x_i - x_j|, a and b the angles at x_i of
// the two triangles beside edge ij (Floater 2003), assembled face by face.
Eigen::SparseMatrix<double> mean_value_weights(const TriMesh& m) {
  std::vector<Eigen::Triplet<double>> w;
  for (int f = 0; f < m.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = m.F(f, k), j = m.F(f, (k + 1) % 3), l = m.F(f, (k + 2) % 3);
      const Eigen::Vector3d a = m.V.row(j) - m.V.row(i), b = m.V.row(l) - m.V.row(i);
      const double t = std::tan(0.5 * std::atan2(a.cross(b).norm(), a.dot(b)));
      w.emplace_back(i, j, t / a.norm());
      w.emplace_back(i, l, t / b.norm());
    }
  Eigen::SparseMatrix<double> W(m.num_vertices(), m.num_vertices());
  W.setFromTriplets(w.begin(), w.end());
  return W;
}

// CGAL's mean value parameterizer with its default arc-length circular border, solved by
// Eigen's SparseLU: the map mean_value_disk_map reproduces.
Eigen::MatrixX2d cgal_mean_value_map(const TriMesh& disk) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
  namespace SMP = CGAL::Surface_mesh_parameterization;
  using Solver = CGAL::Eigen_solver_traits<Eigen::SparseLU<CGAL::Eigen_sparse_matrix<double>::EigenType>>;
  using Parameterizer =
      SMP::Mean_value_coordinates_parameterizer_3<SurfaceMesh,
                                                  SMP::Circular_border_arc_length_parameterizer_3<SurfaceMesh>, Solver>;
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> vertex;
  for (int v = 0; v < disk.num_vertices(); ++v)
    vertex.push_back(sm.add_vertex(Kernel::Point_3(disk.V(v, 0), disk.V(v, 1), disk.V(v, 2))));
  for (int f = 0; f < disk.num_faces(); ++f)
    EXPECT_NE(sm.add_face(vertex[disk.F(f, 0)], vertex[disk.F(f, 1)], vertex[disk.F(f, 2)]), SurfaceMesh::null_face())
        << "face " << f;
  auto uv = sm.add_property_map<SurfaceMesh::Vertex_index, Kernel::Point_2>("v:uv").first;
  const auto border = CGAL::Polygon_mesh_processing::longest_border(sm).first;
  EXPECT_EQ(SMP::parameterize(sm, Parameterizer(), border, uv), SMP::OK);
  Eigen::MatrixX2d out(disk.num_vertices(), 2);
  for (int v = 0; v < disk.num_vertices(); ++v) out.row(v) << uv[vertex[v]].x(), uv[vertex[v]].y();
  return out;
}

}  // namespace

TEST(MeanValueMap, EqualsCGALsMeanValueParameterizerWhateverTheFaceOrder) {
  TriMesh disk = test::spherical_cap(4);
  for (const int seed : {0, 1, 2}) {
    if (seed > 0) {  // the rim's first vertex and direction follow the face order, as in CGAL
      std::vector<int> order(disk.num_faces());
      std::iota(order.begin(), order.end(), 0);
      std::shuffle(order.begin(), order.end(), std::mt19937(seed));
      const RowMatrixX3i F = disk.F;
      for (int f = 0; f < disk.num_faces(); ++f) disk.F.row(f) = F.row(order[f]);
    }
    const Eigen::MatrixX2d uv = mean_value_disk_map(disk);
    EXPECT_LT((uv - cgal_mean_value_map(disk)).cwiseAbs().maxCoeff(), 1e-9) << "face order " << seed;
  }
}

// Degenerate corners follow CGAL's tangent weight too: an angle of π gives a tangent of about
// 1.6e16, and an edge of zero length a weight of 0 (its corners' angles are then taken as π/2).
TEST(MeanValueMap, EqualsCGALsMeanValueParameterizerWithDegenerateCorners) {
  const int v = 2 * 7 + 2, right = v + 1, up_right = v + 8;  // vertex (2, 2) of a 6 x 6 grid, face (v, right, up_right)
  TriMesh straight = test::flat_grid(6);
  straight.V.row(v) = 0.5 * (straight.V.row(right) + straight.V.row(up_right));  // the corner at v is π
  EXPECT_LT((mean_value_disk_map(straight) - cgal_mean_value_map(straight)).cwiseAbs().maxCoeff(), 1e-9);
  TriMesh collapsed = test::flat_grid(6);
  collapsed.V.row(v) = collapsed.V.row(right);  // the edge v -> right has zero length
  EXPECT_LT((mean_value_disk_map(collapsed) - cgal_mean_value_map(collapsed)).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(MeanValueMap, RefusesARimOfTwoLoops) {
  const TriMesh grid = test::flat_grid(6);
  std::vector<int> kept;  // all but the two faces of cell (2, 2), an inner hole
  for (int f = 0; f < grid.num_faces(); ++f)
    if (f / 2 != 2 * 6 + 2) kept.push_back(f);
  EXPECT_THROW(mean_value_disk_map(extract_faces(grid, kept)), AlgorithmError);
}

TEST(Parameterize, RefusesFacesOrientedInconsistently) {
  TriMesh disk = test::flat_grid(6);
  std::swap(disk.F(30, 1), disk.F(30, 2));
  EXPECT_THROW(parameterize(disk), TopologyError);
}

TEST(MeanValueMap, SolvesTheMeanValueSystemAsAPlainSparseLUDoesWithoutFlips) {
  const TriMesh disk = test::spherical_cap(5);
  const int n = disk.num_vertices();
  ASSERT_GT(n, 5000);
  ASSERT_TRUE(topology_report(disk).is_disk());
  const Eigen::MatrixX2d uv = mean_value_disk_map(disk);
  ASSERT_EQ(uv.rows(), n);

  const std::vector<bool> boundary = [&] {
    std::vector<bool> b(n, false);
    // A boundary edge is used by one face only.
    std::vector<std::pair<int, int>> edges;
    for (int f = 0; f < disk.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int u = disk.F(f, k), v = disk.F(f, (k + 1) % 3);
        edges.emplace_back(std::min(u, v), std::max(u, v));
      }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const bool single = (i == 0 || edges[i - 1] != edges[i]) && (i + 1 == edges.size() || edges[i + 1] != edges[i]);
      if (single) b[edges[i].first] = b[edges[i].second] = true;
    }
    return b;
  }();
  int rim = 0;
  for (int v = 0; v < n; ++v)
    if (boundary[v]) {
      ++rim;
      EXPECT_NEAR((uv.row(v) - Eigen::RowVector2d(0.5, 0.5)).norm(), 0.5, 1e-12)
          << v;  // on CGAL's unit-diameter circle
    }
  ASSERT_GT(rim, 50);

  // Interior rows: sum_j w_ij (u_j - u_i) = 0; boundary rows: u_i fixed at the map's value.
  const Eigen::SparseMatrix<double> W = mean_value_weights(disk);
  std::vector<Eigen::Triplet<double>> a;
  Eigen::MatrixX2d rhs = Eigen::MatrixX2d::Zero(n, 2);
  for (int i = 0; i < n; ++i)
    if (boundary[i]) {
      a.emplace_back(i, i, 1.0);
      rhs.row(i) = uv.row(i);
    }
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Wr = W;
  double worst_residual = 0;
  for (int i = 0; i < n; ++i) {
    if (boundary[i]) continue;
    double sum = 0;
    Eigen::RowVector2d r = Eigen::RowVector2d::Zero();
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Wr, i); it; ++it) {
      a.emplace_back(i, static_cast<int>(it.col()), it.value());
      sum += it.value();
      r += it.value() * (uv.row(it.col()) - uv.row(i));
    }
    a.emplace_back(i, i, -sum);
    worst_residual = std::max(worst_residual, r.norm() / sum);
  }
  EXPECT_LT(worst_residual, 1e-10);

  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(a.begin(), a.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu(A);
  ASSERT_EQ(lu.info(), Eigen::Success);
  const Eigen::MatrixX2d reference = lu.solve(rhs);
  EXPECT_LT((reference - uv).cwiseAbs().maxCoeff(), 1e-8);

  // Floater: a convex boundary and positive weights give an embedding, no flipped triangle.
  int positive = 0, negative = 0;
  for (int f = 0; f < disk.num_faces(); ++f) {
    const Eigen::Vector2d p = uv.row(disk.F(f, 0)), q = uv.row(disk.F(f, 1)), r = uv.row(disk.F(f, 2));
    const double orientation = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
    (orientation > 0 ? positive : negative)++;
  }
  EXPECT_TRUE(positive == 0 || negative == 0) << positive << " vs " << negative;
}

// The two-halves map of a closed surface: each half's disk map lifted onto one hemisphere, the
// two glued along the cut. Whatever the Möbius balancing does after, the map must be an
// embedding in the sphere (no flipped triangle, every point on it), and the cut, where the two
// solves meet, must lie on one circle of the sphere: a Möbius transformation maps the equator
// to a circle, a plane section.
TEST(SphereMap, TwoHalvesGlueAlongOneCircleOfTheSphereWithoutFlips) {
  const TriMesh input = test::ellipsoid(5);
  ParameterizationOptions options;
  options.sphere_map = SphereMap::two_halves;
  const Parameterization p = parameterize(input, options);
  ASSERT_EQ(p.kind, DomainKind::sphere);
  ASSERT_EQ(p.sphere_map, SphereMap::two_halves);
  EXPECT_EQ(p.summary.at("cut_axis").get<int>(), 0);  // across the longest axis: the shortest cut
  ASSERT_GT(p.cut.size(), 30u);
  EXPECT_EQ(count_flipped(p.domain, p.surface.F), 0);
  EXPECT_LT(((p.domain.rowwise().norm().array() - 1.0).abs()).maxCoeff(), 1e-9);

  RowMatrixX3d on_cut(static_cast<Eigen::Index>(p.cut.size()), 3);
  for (std::size_t i = 0; i < p.cut.size(); ++i) on_cut.row(static_cast<Eigen::Index>(i)) = p.domain.row(p.cut[i]);
  const Eigen::RowVector3d centre = on_cut.colwise().mean();
  const RowMatrixX3d centred = on_cut.rowwise() - centre;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinV);
  const Eigen::Vector3d normal = svd.matrixV().col(2);
  EXPECT_LT((centred * normal).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT(svd.singularValues()[1], 0.1 * svd.singularValues()[0]);  // a circle, not a few points on a line

  // The cut's plane splits the surface into the two halves: no face has corners strictly on
  // both sides of it, and each side holds half the area (the cut is at the median).
  const Eigen::VectorXd side = (p.domain.rowwise() - centre) * normal;
  double area_above = 0, area_total = 0;
  for (int f = 0; f < p.surface.num_faces(); ++f) {
    const Eigen::Vector3d a = p.surface.V.row(p.surface.F(f, 0)), b = p.surface.V.row(p.surface.F(f, 1)),
                          c = p.surface.V.row(p.surface.F(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    double highest = -1, lowest = 1;
    for (int k = 0; k < 3; ++k) {
      highest = std::max(highest, side[p.surface.F(f, k)]);
      lowest = std::min(lowest, side[p.surface.F(f, k)]);
    }
    EXPECT_FALSE(highest > 1e-9 && lowest < -1e-9) << "face " << f << " straddles the cut";
    area_total += area;
    if (highest > 1e-9) area_above += area;
  }
  EXPECT_NEAR(area_above / area_total, 0.5, 0.02);
}

namespace {

// Vertices on the cut where one side's 3D angle is below 0.6π (the disk maps open it to π).
int count_spikes(const TriMesh& mesh, const std::vector<int>& side) {
  std::vector<std::array<double, 2>> angle(mesh.num_vertices(), {0.0, 0.0});
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = mesh.V.row(mesh.F(f, k)), a = mesh.V.row(mesh.F(f, (k + 1) % 3)),
                            b = mesh.V.row(mesh.F(f, (k + 2) % 3));
      angle[mesh.F(f, k)][side[f]] += std::atan2((a - v).cross(b - v).norm(), (a - v).dot(b - v));
    }
  int spikes = 0;
  for (const auto& a : angle)
    if (a[0] > 0 && a[1] > 0 && std::min(a[0], a[1]) < 0.6 * M_PI) ++spikes;
  return spikes;
}

}  // namespace

// A plane cut along the edges of an uneven mesh (a sphere's, its vertices jittered like a
// marching-cubes surface's) zigzags: spikes of one or two triangles. The cleanup must remove
// almost all of them (moving the ears alone leaves 16 of 78), and leave no face with three corners on the cut (flat on
// the equator).
TEST(SphereMap, CutCleanupRemovesMostSpikesOfAPlaneCut) {
  TriMesh mesh = icosphere(4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.012, 0.012);  // about 0.3 edge lengths
  for (int v = 0; v < mesh.num_vertices(); ++v)
    mesh.V.row(v) = (mesh.V.row(v) + Eigen::RowVector3d(jitter(rng), jitter(rng), jitter(rng))).normalized();
  std::vector<int> side(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f)
    side[f] = mesh.V(mesh.F(f, 0), 0) + mesh.V(mesh.F(f, 1), 0) + mesh.V(mesh.F(f, 2), 0) > 0.1;
  const int before = count_spikes(mesh, side);
  ASSERT_GT(before, 10);
  EXPECT_GT(detail::smooth_cut(mesh, side), 0);
  const int after = count_spikes(mesh, side);
  EXPECT_LE(8 * after, before) << before << " -> " << after;  // 78 -> 4 (ears alone: 16)
  std::vector<std::array<int, 2>> touches(mesh.num_vertices(), {0, 0});
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) touches[mesh.F(f, k)][side[f]] = 1;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    int on_cut = 0;
    for (int k = 0; k < 3; ++k) on_cut += touches[mesh.F(f, k)][0] && touches[mesh.F(f, k)][1];
    EXPECT_LT(on_cut, 3) << f;
  }
}

TEST(SphereMap, AutomaticTakesTheTwoHalvesFromTheFaceCountOnAndThePuncturedMapBelow) {
  const TriMesh input = test::ellipsoid(4);  // 5120 faces
  ParameterizationOptions options;
  options.halves_from_faces = 5120;
  EXPECT_EQ(parameterize(input, options).sphere_map, SphereMap::two_halves);
  options.halves_from_faces = 5121;
  const Parameterization punctured = parameterize(input, options);
  EXPECT_EQ(punctured.sphere_map, SphereMap::punctured);
  EXPECT_TRUE(punctured.cut.empty());
  EXPECT_EQ(count_flipped(punctured.domain, punctured.surface.F), 0);
  EXPECT_EQ(ParameterizationOptions{}.sphere_map, SphereMap::automatic);
}

// A tetrahedron has no cut into two disks without faces whose three corners all lie on the
// cut (degenerate on the equator): the two-halves map must fall back to the punctured one.
TEST(SphereMap, FallsBackToThePuncturedMapWhenNoPlaneCutsTwoDisks) {
  TriMesh tetrahedron;
  tetrahedron.V.resize(4, 3);
  tetrahedron.V << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  tetrahedron.F.resize(4, 3);
  tetrahedron.F << 0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2;
  ASSERT_TRUE(topology_report(tetrahedron).is_closed_genus0());
  ParameterizationOptions options;
  options.sphere_map = SphereMap::two_halves;
  const Parameterization p = parameterize(tetrahedron, options);
  EXPECT_EQ(p.sphere_map, SphereMap::punctured);
  EXPECT_TRUE(p.cut.empty());
  EXPECT_EQ(p.summary.value("sphere_map", ""), "punctured");
  EXPECT_EQ(p.summary.value("sphere_map_fallback", ""), "no principal plane cuts the surface into two disks");
  EXPECT_EQ(count_flipped(p.domain, p.surface.F), 0);
}

TEST(DomainOrientation, ResolvesTinyTrianglesOnTheSphere) {
  // A long shape's sphere map squeezes its far end into triangles far smaller than the
  // rounding of a coordinate (1e-16) allows a determinant of three corners to see: the
  // orientation must come from the edges. For corners a, a + ε·t1, a + ε·t2 (projected onto
  // the sphere) with t1 × t2 = a, it is ε² to first order, and −ε² the other way round.
  const Eigen::Vector3d a = Eigen::Vector3d(0.3, -0.5, 0.81).normalized();
  const Eigen::Vector3d t1 = a.unitOrthogonal(), t2 = a.cross(t1);
  for (const double eps : {1e-3, 1e-6, 1e-9, 1e-11, 1e-13}) {
    const Eigen::Vector3d b = (a + eps * t1).normalized(), c = (a + eps * t2).normalized();
    const double o = domain_orientation(a, b, c);
    EXPECT_NEAR(o / (eps * eps), 1.0, 1e-2) << "edge " << eps;
    EXPECT_LT(domain_orientation(a, c, b), 0.0) << "edge " << eps;
    RowMatrixX3d D(3, 3);
    D << a.transpose(), b.transpose(), c.transpose();
    RowMatrixX3i F(2, 3);
    F << 0, 1, 2, 0, 2, 1;
    EXPECT_EQ(count_flipped(D, F), 1) << "edge " << eps;
  }
}
