// The remesher is deterministic: the same input and options give bit-identical levels, in
// one process (no state kept between calls) and across processes (the CLI's level files).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "remesh/convex_hull.h"
#include "remesh/remesh.h"
#include "remesh/simplify.h"
#include "tests/remesh/remesh_shapes.h"
#include "tests/test_support.h"

namespace mrsnake {
namespace {

using test::ellipsoid;
using test::spherical_cap;

// Every level's 3D and domain positions and its statistics (timings aside) are identical.
void expect_identical(const RemeshResult& a, const RemeshResult& b) {
  ASSERT_EQ(a.levels.size(), b.levels.size());
  for (std::size_t j = 0; j < a.levels.size(); ++j) {
    SCOPED_TRACE("level " + std::to_string(j));
    ASSERT_EQ(a.levels[j].positions.rows(), b.levels[j].positions.rows());
    EXPECT_TRUE(a.levels[j].positions == b.levels[j].positions)
        << "largest difference " << (a.levels[j].positions - b.levels[j].positions).cwiseAbs().maxCoeff();
    EXPECT_TRUE(a.levels[j].domain_positions == b.levels[j].domain_positions);
    nlohmann::json sa = a.levels[j].stats, sb = b.levels[j].stats;
    for (const char* timing : {"seconds", "stage_seconds"}) {
      sa.erase(timing);
      sb.erase(timing);
    }
    EXPECT_EQ(sa, sb);
  }
}

void expect_repeatable(const TriMesh& input, RemeshOptions options) {
  options.compute_stats = true;
  const RemeshResult first = remesh(input, options);
  for (int run = 0; run < 3; ++run) {
    SCOPED_TRACE("run " + std::to_string(run + 2));
    expect_identical(first, remesh(input, options));
  }
}

TEST(RemeshDeterminism, SameInputTwiceInOneProcessGivesIdenticalLevels) {
  RemeshOptions o;
  o.levels = 3;
  o.base_vertices = 24;
  {
    SCOPED_TRACE("sphere");
    expect_repeatable(ellipsoid(4), o);
  }
  {
    SCOPED_TRACE("disk");
    expect_repeatable(spherical_cap(4), o);
  }
}

TEST(RemeshDeterminism, RealSurfaceTwiceInOneProcessGivesIdenticalLevels) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/blobby.off");
  RemeshOptions o;
  o.levels = 2;
  expect_repeatable(read_mesh(path), o);
}

// CGAL's hull lists faces in an order that follows its internal bookkeeping (it changed from
// call to call in one process, and with it the base mesh and every level): the adapter
// returns them sorted, each with its smallest index first.
TEST(RemeshDeterminism, ConvexHullFacesComeInCanonicalOrder) {
  const TriMesh sphere = icosphere(2);  // many cospherical points
  const RowMatrixX3i first = convex_hull_faces(sphere.V);
  ASSERT_EQ(first.rows(), sphere.num_faces());
  for (int f = 0; f < first.rows(); ++f) {
    EXPECT_LT(first(f, 0), first(f, 1));
    EXPECT_LT(first(f, 0), first(f, 2));
    if (f > 0) {
      const auto& a = first.row(f - 1);
      const auto& b = first.row(f);
      EXPECT_TRUE(std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3)) << "face " << f;
    }
  }
  std::vector<std::vector<double>> churn;  // other heap addresses for CGAL's second run
  for (int i = 0; i < 50; ++i) {
    churn.emplace_back(37 * i + 1, 1.0);
    EXPECT_TRUE(convex_hull_faces(sphere.V) == first) << "call " << i + 2;
  }
}

TEST(RemeshDeterminism, SimplificationIsRepeatable) {
  const TriMesh input = ellipsoid(4);
  const TriMesh first = simplify_to_faces(input, 1000);
  for (int run = 0; run < 3; ++run) {
    const TriMesh again = simplify_to_faces(input, 1000);
    EXPECT_TRUE(again.V == first.V && again.F == first.F) << "run " << run + 2;
  }
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(RemeshDeterminism, TwoCliRunsWriteIdenticalLevelFiles) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/blobby.off");
  const auto dir = test::scratch_dir("remesh-determinism");
  for (const char* run : {"a", "b"}) {
    const auto r = test::run_mrsnake("remesh " + path + " -o " + (dir / run).string() + " --levels 2");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  for (int j = 0; j <= 2; ++j) {
    const std::string name = "level_" + std::to_string(j) + ".vtp";
    const std::string a = file_bytes(dir / "a" / name), b = file_bytes(dir / "b" / name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == b) << name << " differs between the two runs";
  }
  nlohmann::json ja = nlohmann::json::parse(file_bytes(dir / "a" / "report.json"));
  nlohmann::json jb = nlohmann::json::parse(file_bytes(dir / "b" / "report.json"));
  ASSERT_EQ(ja["per_level"].size(), 3u);
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_EQ(ja["per_level"][j]["quality"], jb["per_level"][j]["quality"]) << "level " << j;
    EXPECT_EQ(ja["per_level"][j]["distance"], jb["per_level"][j]["distance"]) << "level " << j;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mrsnake
