#include <gtest/gtest.h>

#include <set>

#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "mesh/subdivision.h"
#include "mesh/topology.h"

using namespace mrsnake;

TEST(Subdivision, CountsFollowEulerOnTheIcosahedron) {
  const TriMesh ico = icosahedron();
  const auto conn = subdivide_connectivity(ico.F, 12, 3);
  ASSERT_EQ(conn.levels(), 3);
  // Level j of a closed mesh: F_j = 20*4^j, E_j = 30*4^j, V_{j+1} = V_j + E_j.
  EXPECT_EQ(conn.vertex_counts, (std::vector<int>{12, 42, 162, 642}));
  EXPECT_EQ(conn.faces[3].rows(), 1280);
  EXPECT_EQ(conn.parent_edges.rows(), 642 - 12);
}

TEST(Subdivision, LevelsArePrefixesAndParentsAreEdgesOfTheCoarserLevel) {
  const TriMesh ico = icosahedron();
  const auto conn = subdivide_connectivity(ico.F, 12, 2);
  for (int j = 0; j < conn.levels(); ++j) {
    std::set<std::pair<int, int>> edges;
    for (int f = 0; f < conn.faces[j].rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        int a = conn.faces[j](f, k), b = conn.faces[j](f, (k + 1) % 3);
        edges.insert({std::min(a, b), std::max(a, b)});
      }
    for (int v = conn.vertex_counts[j]; v < conn.vertex_counts[j + 1]; ++v) {
      const auto p = conn.parents(v);
      EXPECT_LT(p.maxCoeff(), conn.vertex_counts[j]);
      EXPECT_TRUE(edges.count({std::min(p[0], p[1]), std::max(p[0], p[1])})) << "vertex " << v;
      EXPECT_EQ(conn.level_of_vertex(v), j + 1);
    }
    // Each child face's corners are either the parent's corners or its edge midpoints.
    for (int f = 0; f < conn.faces[j].rows(); ++f) EXPECT_EQ(conn.faces[j + 1](4 * f, 0), conn.faces[j](f, 0));
  }
  EXPECT_EQ(conn.level_of_vertex(0), 0);
  EXPECT_EQ(conn.level_of_vertex(11), 0);
}

TEST(Subdivision, IcosphereIsClosedGenusZeroWithTwelveIrregularVertices) {
  const TriMesh sphere = icosphere(3, 2.0);
  const auto r = topology_report(sphere);
  EXPECT_TRUE(r.is_closed_genus0());
  EXPECT_EQ(r.inconsistently_oriented_edges, 0);
  std::vector<int> valence(sphere.num_vertices(), 0);
  for (int f = 0; f < sphere.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) ++valence[sphere.F(f, k)];
  int v5 = 0, v6 = 0;
  for (int d : valence) (d == 5 ? v5 : d == 6 ? v6 : d) += 1;
  EXPECT_EQ(v5, 12);
  EXPECT_EQ(v6, sphere.num_vertices() - 12);
  EXPECT_NEAR(sphere.V.rowwise().norm().minCoeff(), 2.0, 1e-12);
}

TEST(Subdivision, MidpointRefineKeepsCoarseVerticesAndSplitsEdges) {
  const TriMesh ico = icosahedron();
  const auto conn = subdivide_connectivity(ico.F, 12, 1);
  const RowMatrixX3d V1 = midpoint_refine(conn, 0, ico.V);
  ASSERT_EQ(V1.rows(), 42);
  EXPECT_EQ((V1.topRows(12) - ico.V).norm(), 0.0);
  const auto p = conn.parents(20);
  EXPECT_NEAR((V1.row(20) - 0.5 * (ico.V.row(p[0]) + ico.V.row(p[1]))).norm(), 0.0, 1e-15);
}

TEST(Subdivision, RejectsNonManifoldEdges) {
  RowMatrixX3i F(3, 3);
  F << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  EXPECT_THROW(subdivide_connectivity(F, 5, 1), TopologyError);
}
