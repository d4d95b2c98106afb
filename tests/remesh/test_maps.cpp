// Tests of the MAPS simplification: the base mesh K is a valid, outward-oriented surface of
// the input's topology, every input vertex has a valid point of K, and the map is local (an
// input vertex lands near itself, an input triangle's corners land in faces around one vertex).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "remesh/base_flips.h"
#include "remesh/maps.h"
#include "tests/remesh/remesh_shapes.h"

namespace mrsnake {
namespace {

MapsParameterization simplify(const TriMesh& input, int base_vertices) {
  MapsOptions options;
  options.base_vertices = base_vertices;
  return maps_parameterize(input, options);
}

// Every directed edge of K once; inside, its reverse too (two faces, opposite directions).
void expect_oriented_manifold(const TriMesh& K, bool closed) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < K.num_faces(); ++f)
    for (int j = 0; j < 3; ++j) ++directed[{K.F(f, j), K.F(f, (j + 1) % 3)}];
  int boundary = 0;
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << edge.first << " -> " << edge.second;
    if (directed.count({edge.second, edge.first}) == 0) ++boundary;
  }
  const TopologyReport report = topology_report(K);
  EXPECT_TRUE(closed ? report.is_closed_genus0() : report.is_disk()) << report.describe();
  if (closed) {
    EXPECT_EQ(boundary, 0);
    EXPECT_EQ(K.num_vertices() - static_cast<int>(directed.size()) / 2 + K.num_faces(), 2);
  }
}

Eigen::Vector3d on_base(const MapsParameterization& maps, int v) {
  const BasePoint& p = maps.location[v];
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) x += p.bary[j] * maps.base.V.row(maps.base.F(p.face, j)).transpose();
  return x;
}

// Faces in range, barycentric coordinates >= 0 summing to 1, and each base vertex at its own
// corner (a unit vector).
void expect_valid_locations(const TriMesh& input, const MapsParameterization& maps) {
  ASSERT_EQ(static_cast<int>(maps.location.size()), input.num_vertices());
  ASSERT_EQ(static_cast<int>(maps.base_vertex.size()), maps.base.num_vertices());
  for (const BasePoint& p : maps.location) {
    ASSERT_GE(p.face, 0);
    ASSERT_LT(p.face, maps.base.num_faces());
    EXPECT_GE(p.bary.minCoeff(), -1e-9);
    EXPECT_NEAR(p.bary.sum(), 1.0, 1e-9);
  }
  for (int i = 0; i < maps.base.num_vertices(); ++i) {
    const int v = maps.base_vertex[i];
    EXPECT_EQ(maps.base.V.row(i), input.V.row(v));
    const BasePoint& p = maps.location[v];
    int corner = -1;
    for (int j = 0; j < 3; ++j)
      if (maps.base.F(p.face, j) == i) corner = j;
    ASSERT_GE(corner, 0) << "base vertex " << i << " is not a corner of its face";
    EXPECT_EQ(p.bary, Eigen::Vector3d::Unit(corner));
  }
}

// The vertices of K within reach of an input vertex's point: those of every face of K that
// holds its carrier (the corners with a non-zero coordinate), as a point on an edge or at a
// corner may be named by any face around it.
std::set<int> reach(const MapsParameterization& maps, const std::vector<std::vector<int>>& vertex_faces, int v) {
  const TriMesh& K = maps.base;
  const BasePoint& p = maps.location[v];
  std::vector<int> carrier;
  for (int j = 0; j < 3; ++j)
    if (p.bary[j] > 1e-12) carrier.push_back(K.F(p.face, j));
  std::set<int> near;
  for (int f : vertex_faces[carrier[0]]) {
    bool holds = true;
    for (int c : carrier) holds &= K.F(f, 0) == c || K.F(f, 1) == c || K.F(f, 2) == c;
    if (holds) near.insert({K.F(f, 0), K.F(f, 1), K.F(f, 2)});
  }
  return near;
}

// Whether some vertex within reach of a is b or a neighbour of b's.
bool within_a_ring(const std::set<int>& a, const std::set<int>& b, const std::set<std::pair<int, int>>& edges) {
  for (int x : a)
    for (int y : b)
      if (x == y || edges.count({x, y})) return true;
  return false;
}

// The map is local: an input triangle's corners land in faces of K around one common vertex
// (a corner near a sliver of K may land one face further: at most 1 triangle in 500), and
// each input edge's ends at most one ring of K apart. Returns the largest distance between an
// input vertex and its point evaluated on K, over the longest edge of that K face.
double expect_local_map(const TriMesh& input, const MapsParameterization& maps) {
  const TriMesh& K = maps.base;
  std::vector<std::vector<int>> vertex_faces(K.num_vertices());
  std::set<std::pair<int, int>> edges;
  for (int f = 0; f < K.num_faces(); ++f)
    for (int j = 0; j < 3; ++j) {
      vertex_faces[K.F(f, j)].push_back(f);
      edges.insert({K.F(f, j), K.F(f, (j + 1) % 3)});
      edges.insert({K.F(f, (j + 1) % 3), K.F(f, j)});
    }
  int far_apart = 0, over_a_ring = 0;
  for (int f = 0; f < input.num_faces(); ++f) {
    std::array<std::set<int>, 3> near;
    for (int j = 0; j < 3; ++j) near[j] = reach(maps, vertex_faces, input.F(f, j));
    std::set<int> common = near[0];
    for (int j = 1; j < 3; ++j) {
      std::set<int> both;
      for (int c : common)
        if (near[j].count(c)) both.insert(c);
      common = both;
    }
    far_apart += common.empty();
    for (int j = 0; j < 3; ++j) over_a_ring += !within_a_ring(near[j], near[(j + 1) % 3], edges);
  }
  EXPECT_LE(far_apart, input.num_faces() / 500)
      << "input triangles whose corners land in faces of K without a common vertex";
  EXPECT_EQ(over_a_ring, 0) << "input edges whose ends land more than one ring of K apart";
  double worst = 0;
  for (int v = 0; v < input.num_vertices(); ++v) {
    const int g = maps.location[v].face;
    double longest = 0;
    for (int j = 0; j < 3; ++j) longest = std::max(longest, (K.V.row(K.F(g, j)) - K.V.row(K.F(g, (j + 1) % 3))).norm());
    worst = std::max(worst, (on_base(maps, v) - input.V.row(v).transpose()).norm() / longest);
  }
  return worst;
}

TEST(Maps, SimplifiesAnIcosphereToAnOutwardSphereWithEveryVertexLocatedNearItself) {
  const TriMesh input = icosphere(4);
  ASSERT_EQ(input.num_vertices(), 2562);
  const MapsParameterization maps = simplify(input, 100);
  EXPECT_LE(maps.base.num_vertices(), 100);
  EXPECT_GE(maps.base.num_vertices(), 90);
  EXPECT_EQ(maps.removed_vertices, input.num_vertices() - maps.base.num_vertices());
  expect_oriented_manifold(maps.base, true);
  for (int f = 0; f < maps.base.num_faces(); ++f) {
    const Eigen::Vector3d a = maps.base.V.row(maps.base.F(f, 0)), b = maps.base.V.row(maps.base.F(f, 1)),
                          c = maps.base.V.row(maps.base.F(f, 2));
    EXPECT_GT((b - a).cross(c - a).dot(a + b + c), 0) << "face " << f << " points inward";
  }
  expect_valid_locations(input, maps);
  expect_local_map(input, maps);
  double farthest = 0;
  for (int v = 0; v < input.num_vertices(); ++v)
    farthest = std::max(farthest, (on_base(maps, v) - input.V.row(v).transpose()).norm());
  EXPECT_LT(farthest, 0.1);  // radius 1
}

// K no larger than `target`, a closed oriented manifold, every location valid, and the map local
// (each vertex within half its face's longest edge of its point on K).
void expect_sound_closed_map(const TriMesh& input, const MapsParameterization& maps, int target) {
  EXPECT_LE(maps.base.num_vertices(), target);
  expect_oriented_manifold(maps.base, true);
  expect_valid_locations(input, maps);
  EXPECT_LT(expect_local_map(input, maps), 0.5);
}

TEST(Maps, SimplifiesAnEllipsoid) {
  const TriMesh input = test::ellipsoid(4);
  const MapsParameterization maps = simplify(input, 80);
  expect_sound_closed_map(input, maps, 80);
}

// A long protrusion, where one map onto the sphere fails: K keeps a tube of its own.
TEST(Maps, SimplifiesALongCapsule) {
  const TriMesh input = test::capsule(15.0);
  const MapsParameterization maps = simplify(input, 60);
  expect_sound_closed_map(input, maps, 60);
  double top = -1e9, bottom = 1e9;
  for (int i = 0; i < maps.base.num_vertices(); ++i) {
    top = std::max(top, maps.base.V(i, 2));
    bottom = std::min(bottom, maps.base.V(i, 2));
  }
  EXPECT_GT(top - bottom, 15.0);  // the tube's length, tips included
}

// A disk keeps one boundary loop made of input rim vertices, and rim points stay on the rim.
TEST(Maps, SimplifiesADiskAlongItsRim) {
  const TriMesh input = test::spherical_cap(4);
  const MapsParameterization maps = simplify(input, 60);
  EXPECT_LE(maps.base.num_vertices(), 60);
  expect_oriented_manifold(maps.base, false);
  expect_valid_locations(input, maps);
  EXPECT_LT(expect_local_map(input, maps), 0.5);
  auto boundary_edges = [](const TriMesh& m) {
    std::set<std::pair<int, int>> directed, boundary;
    for (int f = 0; f < m.num_faces(); ++f)
      for (int j = 0; j < 3; ++j) directed.insert({m.F(f, j), m.F(f, (j + 1) % 3)});
    for (const auto& [a, b] : directed)
      if (!directed.count({b, a})) boundary.insert({a, b});
    return boundary;
  };
  std::set<int> input_rim, base_rim;
  double rim_spacing = 0;
  for (const auto& [a, b] : boundary_edges(input)) {
    input_rim.insert(a);
    rim_spacing += (input.V.row(a) - input.V.row(b)).norm();
  }
  rim_spacing /= static_cast<double>(input_rim.size());
  const std::set<std::pair<int, int>> base_boundary = boundary_edges(maps.base);
  for (const auto& [a, b] : base_boundary) base_rim.insert(a);
  for (int i : base_rim) EXPECT_TRUE(input_rim.count(maps.base_vertex[i])) << "base rim vertex " << i;
  EXPECT_GE(base_rim.size(), 6u);
  for (int v : input_rim) {
    const BasePoint& p = maps.location[v];
    bool on_rim = false;  // on a rim edge of its face, or at a rim corner
    for (int j = 0; j < 3; ++j) {
      const int a = maps.base.F(p.face, j), b = maps.base.F(p.face, (j + 1) % 3);
      on_rim |= base_rim.count(a) && p.bary[j] == 1.0;
      if (!base_boundary.count({a, b}) || p.bary[(j + 2) % 3] >= 1e-9) continue;
      on_rim = true;
      // The rim keeps its shape: the input rim stays as near K's rim edge as max_rim_turn allows.
      const Eigen::Vector3d x = input.V.row(v), ka = maps.base.V.row(a), kb = maps.base.V.row(b);
      const double t = std::clamp((x - ka).dot(kb - ka) / (kb - ka).squaredNorm(), 0.0, 1.0);
      const double allowed = 0.5 * std::tan(15 * M_PI / 180) * (kb - ka).norm() + 0.6 * rim_spacing;
      EXPECT_LE((x - ka - t * (kb - ka)).norm(), allowed + 1e-9) << "input rim vertex " << v;
    }
    EXPECT_TRUE(on_rim) << "input rim vertex " << v << " is located off the rim of K";
  }
}

// Down to a few vertices K stays a simplicial sphere: a removal whose fill would repeat an
// edge of K (the link condition) is filled otherwise or refused; a thin tube needs that most.
TEST(Maps, SimplifiesToAFewVerticesWithoutRepeatingAnEdge) {
  for (const auto& [input, target] : {std::pair{test::ellipsoid(4), 6}, std::pair{test::capsule(15.0), 20}}) {
    const MapsParameterization maps = simplify(input, target);
    EXPECT_LE(maps.base.num_vertices(), 2 * target);
    expect_oriented_manifold(maps.base, true);
    expect_valid_locations(input, maps);
  }
}

// The drift guard holds to the end: a point's last move passed it, and its face stayed.
TEST(Maps, KeepsEveryPointWithinTheDriftItIsAllowed) {
  const TriMesh input = test::capsule(15.0);
  MapsOptions options;
  options.base_vertices = 60;
  options.max_drift = 0.2;
  const MapsParameterization maps = maps_parameterize(input, options);
  EXPECT_LE(maps.base.num_vertices(), 2 * 60);  // the guard may stall it above the target
  EXPECT_GT(maps.refused_drift, 0);
  expect_oriented_manifold(maps.base, true);
  EXPECT_LE(expect_local_map(input, maps), 0.2 + 1e-9);
}

TEST(Maps, IsDeterministic) {
  const TriMesh input = test::ellipsoid(3);
  const MapsParameterization a = simplify(input, 40), b = simplify(input, 40);
  EXPECT_EQ(a.base.F, b.base.F);
  EXPECT_EQ(a.base_vertex, b.base_vertex);
  for (int v = 0; v < input.num_vertices(); ++v) {
    EXPECT_EQ(a.location[v].face, b.location[v].face);
    EXPECT_EQ(a.location[v].bary, b.location[v].bary);
  }
}

TEST(Maps, KeepsFeatureVertices) {
  const TriMesh input = icosphere(3);
  MapsOptions options;
  options.base_vertices = 50;
  options.feature_vertices = {0, 7, 100, 400};
  const MapsParameterization maps = maps_parameterize(input, options);
  for (int v : options.feature_vertices)
    EXPECT_NE(std::find(maps.base_vertex.begin(), maps.base_vertex.end(), v), maps.base_vertex.end()) << v;
}

// sum (valence - 6)² over K's vertices (a closed K).
int valence_deviation(const TriMesh& K) {
  std::vector<int> valence(K.num_vertices(), 0);
  for (int f = 0; f < K.num_faces(); ++f)
    for (int j = 0; j < 3; ++j) ++valence[K.F(f, j)];
  int sum = 0;
  for (int v : valence) sum += (v - 6) * (v - 6);
  return sum;
}

// On a flat K the unfolding of a flip's quad is exact, so every point of K stays where it was:
// the flips locate the points of the two faces again without moving them.
TEST(BaseFlips, LocateThePointsOfAFlatBaseAgainWithoutMovingThem) {
  const TriMesh input = test::flat_grid(24, 0.25);
  MapsParameterization maps = simplify(input, 60);
  std::vector<Eigen::Vector3d> before(input.num_vertices());
  for (int v = 0; v < input.num_vertices(); ++v) before[v] = on_base(maps, v);
  const BaseFlipStats stats = flip_base_edges(maps);
  EXPECT_GT(stats.delaunay_flips + stats.valence_flips, 0);
  expect_oriented_manifold(maps.base, false);
  expect_valid_locations(input, maps);
  for (int v = 0; v < input.num_vertices(); ++v) EXPECT_LT((on_base(maps, v) - before[v]).norm(), 1e-9) << v;
}

// On a long capsule the flips make K more regular and leave the map sound and local.
TEST(BaseFlips, MakeACapsulesBaseMoreRegularAndKeepTheMapSound) {
  const TriMesh input = test::capsule(15.0);
  MapsParameterization maps = simplify(input, 60);
  const int deviation_before = valence_deviation(maps.base);
  const BaseFlipStats stats = flip_base_edges(maps);
  EXPECT_GT(stats.valence_flips, 0);
  EXPECT_LT(valence_deviation(maps.base), deviation_before);
  expect_sound_closed_map(input, maps, 60);
}

TEST(Maps, RefusesMeshesThatAreNeitherADiskNorASphere) {
  TriMesh two = icosphere(1);
  const int n = two.num_vertices(), m = two.num_faces();
  two.V.conservativeResize(2 * n, 3);
  two.V.bottomRows(n) = two.V.topRows(n).rowwise() + Eigen::RowVector3d(5, 0, 0);
  two.F.conservativeResize(2 * m, 3);
  two.F.bottomRows(m) = two.F.topRows(m).array() + n;
  EXPECT_THROW(maps_parameterize(two), TopologyError);
}

}  // namespace
}  // namespace mrsnake
