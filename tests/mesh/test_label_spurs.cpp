#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include <nlohmann/json.hpp>

#include "mesh/image_io.h"
#include "mesh/label_spurs.h"
#include "mesh/marching_cubes.h"
#include "mesh/topology.h"
#include "tests/test_support.h"

using namespace mrsnake;

namespace {

Volume empty_grid(std::size_t n) {
  Volume v;
  v.size = {n, n, n};
  v.data.assign(v.num_voxels(), 0.0f);
  return v;
}

// `label` on the voxels [lo, hi) along each axis.
void fill_box(Volume& v, std::array<std::size_t, 3> lo, std::array<std::size_t, 3> hi, float label) {
  for (std::size_t k = lo[2]; k < hi[2]; ++k)
    for (std::size_t j = lo[1]; j < hi[1]; ++j)
      for (std::size_t i = lo[0]; i < hi[0]; ++i) v.at(i, j, k) = label;
}

long count_of(const Volume& v, float label) { return std::count(v.data.begin(), v.data.end(), label); }

}  // namespace

TEST(LabelSpurs, ALineHangingFromABoxGoesBackToTheBoxAndOtherLabelsStay) {
  Volume v = empty_grid(16);
  fill_box(v, {4, 4, 4}, {8, 8, 8}, 3);
  fill_box(v, {8, 5, 5}, {11, 6, 6}, 3);   // three voxels in a line off the box's +x face
  fill_box(v, {1, 12, 1}, {6, 13, 2}, 9);  // a line of another label
  EXPECT_EQ(remove_label_spurs(v, 3), 3);
  EXPECT_EQ(count_of(v, 3), 64);
  EXPECT_EQ(v.at(8, 5, 5), 0.0f);
  EXPECT_EQ(count_of(v, 9), 5);
}

TEST(LabelSpurs, AVoxelOnABoxFaceOrEdgeGoesButALineJoiningTwoBoxesStays) {
  Volume v = empty_grid(20);
  fill_box(v, {2, 2, 2}, {6, 6, 6}, 1);
  fill_box(v, {10, 2, 2}, {14, 6, 6}, 1);
  fill_box(v, {6, 3, 3}, {10, 4, 4}, 1);  // four voxels from one box to the other
  v.at(3, 6, 3) = 1;                      // on the first box's +y face: one face neighbour
  v.at(6, 6, 5) = 1;                      // on its (+x, +y) edge: no face neighbour
  EXPECT_EQ(remove_label_spurs(v, 1), 2);
  EXPECT_EQ(count_of(v, 1), 2 * 64 + 4);
}

TEST(LabelSpurs, ALabelMadeOfSpursOnlyIsKeptWhole) {
  Volume v = empty_grid(8);
  fill_box(v, {1, 3, 3}, {6, 4, 4}, 2);
  EXPECT_EQ(remove_label_spurs(v, 2), 0);
  EXPECT_EQ(count_of(v, 2), 5);
}

TEST(MarchingCubes, WithoutSpursABoxWithALineHasTheSurfaceOfTheBox) {
  Volume box = empty_grid(16);
  fill_box(box, {4, 4, 4}, {8, 8, 8}, 3);
  Volume with_line = box;
  fill_box(with_line, {8, 5, 5}, {11, 6, 6}, 3);
  LabelSurfaceOptions options;
  const LabelSurface kept = extract_label_surface(with_line, 3, options);
  options.remove_spurs = true;
  const LabelSurface removed = extract_label_surface(with_line, 3, options);
  const LabelSurface plain = extract_label_surface(box, 3, options);
  EXPECT_EQ(kept.spur_voxels_removed, 0);
  EXPECT_GT(kept.mesh.num_faces(), plain.mesh.num_faces());
  EXPECT_EQ(removed.spur_voxels_removed, 3);
  EXPECT_EQ(removed.mesh.num_faces(), plain.mesh.num_faces());
  EXPECT_EQ(removed.mesh.V, plain.mesh.V);
  EXPECT_TRUE(topology_report(removed.mesh).is_closed_genus0());
}

TEST(McCommand, RemoveSpursReportsTheVoxelsItRemoved) {
  const auto dir = test::scratch_dir("mc-spurs");
  Volume v = empty_grid(16);
  fill_box(v, {4, 4, 4}, {8, 8, 8}, 3);
  fill_box(v, {8, 5, 5}, {11, 6, 6}, 3);
  const std::string img = (dir / "labels.nii.gz").string();
  write_volume(img, v, VoxelType::uint8);
  const auto faces_and_spurs = [&](const std::string& flags) {
    const auto r =
        test::run_mrsnake("-q mc --labels " + img + " --label 3 -o " + (dir / "s.vtp").string() + " --json" + flags);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json j = nlohmann::json::parse(r.output);
    return std::make_pair(j["faces"].get<int>(), j["spur_voxels_removed"].get<int>());
  };
  const auto [faces_kept, none] = faces_and_spurs("");
  const auto [faces_without, removed] = faces_and_spurs(" --remove-spurs");
  EXPECT_EQ(none, 0);
  EXPECT_EQ(removed, 3);
  LabelSurfaceOptions options;
  options.remove_spurs = true;
  EXPECT_EQ(faces_without, extract_label_surface(v, 3, options).mesh.num_faces());
  EXPECT_LT(faces_without, faces_kept);
}
