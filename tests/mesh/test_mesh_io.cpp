#include <gtest/gtest.h>

#include <cstring>
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

TEST(MeshIO, PlyAsciiQuadsAndExtraProperties) {
  const auto dir = test::scratch_dir("ply");
  const std::string path = (dir / "q.ply").string();
  std::ofstream(path) << "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\n"
                         "property float y\nproperty float z\nproperty uchar red\nelement face 1\n"
                         "property list uchar int vertex_indices\nend_header\n"
                         "0 0 0 255\n1 0 0 255\n1 1 0 255\n0 1 0 255\n4 0 1 2 3\n";
  const TriMesh m = read_mesh(path);
  EXPECT_EQ(m.num_vertices(), 4);
  ASSERT_EQ(m.num_faces(), 2);
  EXPECT_EQ(m.V(2, 1), 1.0);
  EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 2, 3));
}

TEST(MeshIO, PlyBigEndianBinary) {
  const auto dir = test::scratch_dir("ply-be");
  const std::string path = (dir / "t.ply").string();
  std::ofstream f(path, std::ios::binary);
  f << "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
       "property double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n";
  const auto put_be = [&](const void* p, int n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (int i = n - 1; i >= 0; --i) f.put(static_cast<char>(b[i]));
  };
  const double coords[9] = {0, 0, 0, 2.5, 0, 0, 0, -1.25, 0};
  for (double c : coords) put_be(&c, 8);
  f.put(3);
  for (std::uint32_t id : {0u, 1u, 2u}) put_be(&id, 4);
  f.close();
  const TriMesh m = read_mesh(path);
  ASSERT_EQ(m.num_faces(), 1);
  EXPECT_EQ(m.V(1, 0), 2.5);
  EXPECT_EQ(m.V(2, 1), -1.25);
}

TEST(MeshIO, MalformedPlyIsRefusedNotCrashed) {
  // The input on which fuzzing found a double free in VTK 9.1's PLY reader: a two-corner
  // face, and more faces declared than present.
  const auto dir = test::scratch_dir("ply-bad");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string(), std::ios::binary) << text;
    return (dir / name).string();
  };
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 5\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  EXPECT_THROW(read_mesh(write("fuzz.ply", header + vertices + "2 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")), InputError);
  EXPECT_THROW(read_mesh(write("short.ply", header + vertices + "3 0 2 1\n3 0 1 3\n")), InputError);
  EXPECT_THROW(read_mesh(write("index.ply", header + vertices + "3 0 2 9\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 1 2 3\n")),
               InputError);
  EXPECT_THROW(read_mesh(write("noheader.ply", "ply\nformat ascii 1.0\n")), InputError);
  EXPECT_THROW(read_mesh(write("binary.ply",
                               "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
                               "property float x\nproperty float y\nproperty float z\nend_header\n\x01\x02")),
               InputError);
}

TEST(MeshIO, StlAsciiMergesCornersAndDamagedBinaryIsRefused) {
  const auto dir = test::scratch_dir("stl");
  const std::string ascii = (dir / "a.stl").string();
  std::ofstream(ascii)
      << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
         "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n"
         "endloop\nendfacet\nendsolid t\n";
  const TriMesh m = read_mesh(ascii);
  EXPECT_EQ(m.num_vertices(), 4);
  EXPECT_EQ(m.num_faces(), 2);
  // A binary header that announces 2^31 triangles in a 200-byte file: fuzzing made VTK's
  // reader allocate gigabytes on such a file.
  std::string binary(200, '\0');
  const std::uint32_t huge = 0x80000000u;
  std::memcpy(&binary[80], &huge, 4);
  const std::string path = (dir / "b.stl").string();
  std::ofstream(path, std::ios::binary) << binary;
  EXPECT_THROW(read_mesh(path), InputError);
}

TEST(MeshIO, LegacyVtkWithStrayBytesIsRefused) {
  // Fuzzing found that VTK 9.1's legacy reader dereferences null on a NUL in an ASCII file.
  const auto dir = test::scratch_dir("vtk-bad");
  const std::string path = (dir / "nul.vtk").string();
  const std::string text =
      "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n"
      "0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0";
  std::ofstream(path, std::ios::binary) << text << '\0' << " 1 2\n";
  EXPECT_THROW(read_mesh(path), InputError);
  const std::string star = (dir / "star.vtk").string();  // printable but malformed
  std::ofstream(star) << text << "*0 1 2\n";
  EXPECT_THROW(read_mesh(star), InputError);
  std::ofstream((dir / "hdr.vtk").string()) << "not a vtk file\n";
  EXPECT_THROW(read_mesh((dir / "hdr.vtk").string()), InputError);
  // The classic ASCII layout (VTK before 5.1) is read too.
  const std::string classic = (dir / "classic.vtk").string();
  std::ofstream(classic) << "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
                            "0 0 0 1 0 0 1 1 0 0 1 0\nPOLYGONS 1 5\n4 0 1 2 3\nPOINT_DATA 4\n";
  const TriMesh quad = read_mesh(classic);
  EXPECT_EQ(quad.num_faces(), 2);
  EXPECT_EQ(quad.V(2, 0), 1.0);
}

TEST(MeshIO, ObjCornerFormsAndMissingReferences) {
  const auto dir = test::scratch_dir("obj");
  const std::string good = (dir / "g.obj").string();
  std::ofstream(good) << "# quad\nv 0 0 0\nv 1 0 0\nvt 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2//1 -2/1 4\n";
  const TriMesh m = read_mesh(good);
  ASSERT_EQ(m.num_faces(), 2);
  EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(0, 1, 2));
  // The input on which fuzzing found a null dereference in VTK 9.1's OBJ reader.
  const std::string bad = (dir / "b.obj").string();
  std::ofstream(bad) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 4\nf 1 4 3\nf 2 4/4\n";
  EXPECT_THROW(read_mesh(bad), InputError);
  std::ofstream((dir / "c.obj").string()) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
  EXPECT_THROW(read_mesh((dir / "c.obj").string()), InputError);
}
