#include <gtest/gtest.h>

#include <fstream>

#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "tests/test_support.h"

using namespace mrsnake;

class MeshRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(MeshRoundTrip, WritesAndReadsBackTheSameMesh) {
  const auto dir = test::scratch_dir("io");
  const TriMesh sphere = icosphere(2, 3.0);
  const std::string path = (dir / ("sphere" + GetParam())).string();
  write_mesh(path, sphere);
  const TriMesh back = read_mesh(path);
  ASSERT_EQ(back.num_vertices(), sphere.num_vertices());
  ASSERT_EQ(back.num_faces(), sphere.num_faces());
  if (GetParam() == ".stl") {
    // STL stores unindexed float triangles: the reader re-merges corners in its own order.
    EXPECT_LT((back.V.rowwise().norm().array() - 3.0).abs().maxCoeff(), 1e-5);
  } else {
    EXPECT_LT((back.V - sphere.V).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_EQ(back.F, sphere.F);
  }
  EXPECT_TRUE(topology_report(back).is_closed_genus0());
  // No temporary file is left beside the output.
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1);
}

INSTANTIATE_TEST_SUITE_P(Formats, MeshRoundTrip, ::testing::Values(".vtp", ".vtk", ".stl", ".ply", ".obj", ".off"),
                         [](const auto& info) { return info.param.substr(1); });

TEST(MeshIO, BadInputsGiveInputErrors) {
  const auto dir = test::scratch_dir("io-bad");
  EXPECT_THROW(read_mesh((dir / "missing.off").string()), InputError);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  EXPECT_THROW(read_mesh(write("a.xyz", "1 2 3")), InputError);
  EXPECT_THROW(read_mesh(write("trunc.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n")), InputError);
  EXPECT_THROW(read_mesh(write("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n")), InputError);
  EXPECT_THROW(read_mesh(write("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")), InputError);
  EXPECT_THROW(read_mesh(write("garbage.vtp", "<VTKFile garbage")), InputError);
  EXPECT_THROW(read_mesh(write("empty.stl", "")), InputError);
  EXPECT_THROW(write_mesh((dir / "out.xyz").string(), icosahedron()), OutputError);
}

TEST(MeshIO, QuadsAreTriangulated) {
  const auto dir = test::scratch_dir("io-quad");
  const std::string path = (dir / "quad.off").string();
  std::ofstream(path) << "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  EXPECT_EQ(read_mesh(path).num_faces(), 2);
}

TEST(MeshIO, FileExtensionHandlesCompoundGz) {
  EXPECT_EQ(file_extension("/a/b/Labels.NII.GZ"), ".nii.gz");
  EXPECT_EQ(file_extension("x.vtp"), ".vtp");
  EXPECT_EQ(file_extension("noext"), "");
}
