#include <gtest/gtest.h>

#include "mesh/errors.h"
#include "mesh/merge.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "tests/test_support.h"

using namespace mrsnake;

TEST(Topology, IcosahedronCounts) {
  const auto r = topology_report(icosahedron());
  EXPECT_EQ(r.vertices, 12);
  EXPECT_EQ(r.faces, 20);
  EXPECT_EQ(r.edges, 30);
  EXPECT_EQ(r.euler_characteristic, 2);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.boundary_loops, 0);
  EXPECT_EQ(r.components, 1);
  EXPECT_TRUE(r.is_closed_genus0());
  EXPECT_NO_THROW(require_disk_or_sphere(r, "icosahedron"));
}

TEST(Topology, OpenedIcosahedronIsADisk) {
  TriMesh m = icosahedron();
  m.F.conservativeResize(19, 3);  // drop one face: one boundary loop of 3 edges
  const auto r = topology_report(m);
  EXPECT_TRUE(r.is_disk());
  EXPECT_EQ(r.boundary_edges, 3);
  EXPECT_EQ(r.boundary_loops, 1);
}

TEST(Topology, TwoComponentsAndDefects) {
  TriMesh a = icosahedron(), b = icosahedron();
  TriMesh both;
  both.V.resize(24, 3);
  both.V << a.V, b.V.array() + 5.0;
  both.F.resize(40, 3);
  both.F << a.F, b.F.array() + 12;
  auto r = topology_report(both);
  EXPECT_EQ(r.components, 2);
  EXPECT_EQ(r.genus, 0);
  EXPECT_THROW(require_disk_or_sphere(r, "two balls"), TopologyError);
  EXPECT_EQ(connected_components(both).size(), 2u);
  EXPECT_EQ(extract_faces(both, connected_components(both)[0]).num_vertices(), 12);

  // A third face on an edge makes it non-manifold; a repeated corner is degenerate.
  TriMesh bad = icosahedron();
  bad.V.conservativeResize(13, 3);
  bad.V.row(12) << 3, 3, 3;
  bad.F.conservativeResize(22, 3);
  bad.F.row(20) << 0, 11, 12;
  bad.F.row(21) << 1, 1, 2;
  r = topology_report(bad);
  EXPECT_EQ(r.non_manifold_edges, 1);
  EXPECT_EQ(r.degenerate_faces, 1);
  EXPECT_FALSE(r.is_manifold());
}

TEST(Topology, FlippedFacesMakeInconsistentlyOrientedEdges) {
  TriMesh m = icosphere(4);  // 5120 faces, 7680 edges
  EXPECT_EQ(topology_report(m).inconsistently_oriented_edges, 0);
  m.F.col(1).swap(m.F.col(2));  // every face flipped: consistent again
  EXPECT_EQ(topology_report(m).inconsistently_oriented_edges, 0);
  // One face flipped: its 3 edges; two neighbours flipped: 4 (their shared edge agrees again).
  TriMesh one = icosahedron();
  std::swap(one.F(0, 1), one.F(0, 2));
  const auto r = topology_report(one);
  EXPECT_EQ(r.inconsistently_oriented_edges, 3);
  EXPECT_THROW(require_disk_or_sphere(r, "the icosahedron"), TopologyError);
  EXPECT_EQ(r.edges, 30);
  EXPECT_EQ(r.non_manifold_edges, 0);
  int neighbour = -1;
  for (int f = 1; f < one.num_faces() && neighbour < 0; ++f) {
    int shared = 0;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) shared += one.F(0, i) == one.F(f, k);
    if (shared == 2) neighbour = f;
  }
  ASSERT_GE(neighbour, 0);
  std::swap(one.F(neighbour, 1), one.F(neighbour, 2));
  EXPECT_EQ(topology_report(one).inconsistently_oriented_edges, 4);
}

TEST(Topology, BowtieVertexIsNonManifold) {
  TriMesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 3, 4;
  EXPECT_EQ(topology_report(m).non_manifold_vertices, 1);
}

struct SharedMeshCase {
  const char* file;
  int vertices, faces, genus, boundary_loops;
};

class SharedMeshes : public ::testing::TestWithParam<SharedMeshCase> {};

TEST_P(SharedMeshes, TopologyMatchesTheDataReadme) {
  const auto c = GetParam();
  MRSNAKE_REQUIRE_DATA(path, std::string("meshes/") + c.file);
  const auto r = topology_report(read_mesh(path));
  EXPECT_EQ(r.vertices, c.vertices);
  EXPECT_EQ(r.faces, c.faces);
  EXPECT_EQ(r.genus, c.genus);
  EXPECT_EQ(r.boundary_loops, c.boundary_loops);
  EXPECT_EQ(r.components, 1);
  EXPECT_TRUE(r.is_manifold());
}

INSTANTIATE_TEST_SUITE_P(
    Data, SharedMeshes,
    ::testing::Values(SharedMeshCase{"mushroom.off", 2337, 4608, 0, 1}, SharedMeshCase{"heart.off", 8896, 17788, 0, 0},
                      SharedMeshCase{"bear.off", 13826, 27648, 0, 0}, SharedMeshCase{"blobby.off", 2027, 4050, 0, 0},
                      SharedMeshCase{"retinal.off", 3643, 7282, 0, 0}, SharedMeshCase{"elephant.off", 2775, 5558, 3, 0},
                      SharedMeshCase{"lion.off", 7529, 14859, 0, 5}),
    [](const auto& info) {
      std::string n = info.param.file;
      return n.substr(0, n.find('.'));
    });

TEST(InfoCommand, ReportsGenusAndLoopsAsJson) {
  MRSNAKE_REQUIRE_DATA(elephant, "meshes/elephant.off");
  auto r = test::run_mrsnake("info --json " + elephant);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"genus\": 3"), std::string::npos) << r.output;
  r = test::run_mrsnake("info /nonexistent/mesh.off");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.output.find("does not exist"), std::string::npos) << r.output;
  r = test::run_mrsnake("info");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(Topology, MergedMeshesAreSideBySideComponents) {
  const TriMesh a = icosahedron();
  TriMesh b = icosahedron();
  b.V.col(0).array() += 5.0;
  const TriMesh m = merged_meshes({&a, &b});
  ASSERT_EQ(m.V.rows(), 24);
  ASSERT_EQ(m.F.rows(), 40);
  EXPECT_TRUE(m.V.bottomRows(12).isApprox(b.V));
  EXPECT_TRUE((m.F.bottomRows(20).array() == b.F.array() + 12).all());
  const auto r = topology_report(m);
  EXPECT_EQ(r.components, 2);
  EXPECT_EQ(r.boundary_edges, 0);
}
