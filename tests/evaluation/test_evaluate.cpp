// Segmentation scores: overlap, volume difference and boundary-voxel surface distances.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "evaluation/evaluate.h"
#include "mesh/image_filters_itk.h"
#include "tests/test_support.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

Volume grid(std::array<std::size_t, 3> size, std::array<double, 3> spacing, std::array<double, 3> origin = {0, 0, 0}) {
  Volume v;
  v.size = size;
  v.spacing = spacing;
  v.origin = origin;
  v.data.assign(v.num_voxels(), 0.0f);
  return v;
}

/// 1 on the voxels whose centre is within radius of the physical point c.
Volume ball(Volume v, const std::array<double, 3>& c, double radius) {
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) {
        const auto p = v.index_to_physical(i, j, k);
        v.at(i, j, k) = std::hypot(p[0] - c[0], p[1] - c[1], p[2] - c[2]) <= radius ? 1.0f : 0.0f;
      }
  return v;
}

/// A box of voxels [lo, hi) (index space).
Volume box(Volume v, std::array<int, 3> lo, std::array<int, 3> hi, float value = 1.0f) {
  for (int k = lo[2]; k < hi[2]; ++k)
    for (int j = lo[1]; j < hi[1]; ++j)
      for (int i = lo[0]; i < hi[0]; ++i) v.at(i, j, k) = value;
  return v;
}

/// Reference surface distances by brute force: boundary voxels (6-neighbourhood), every
/// pair, both directions pooled.
std::vector<double> brute_force_distances(const Volume& a, const Volume& b) {
  auto boundary = [](const Volume& v) {
    std::vector<std::array<double, 3>> points;
    auto in = [&](long i, long j, long k) {
      return i >= 0 && j >= 0 && k >= 0 && i < long(v.size[0]) && j < long(v.size[1]) && k < long(v.size[2]) &&
             v.at(i, j, k) != 0;
    };
    for (long k = 0; k < long(v.size[2]); ++k)
      for (long j = 0; j < long(v.size[1]); ++j)
        for (long i = 0; i < long(v.size[0]); ++i)
          if (in(i, j, k) && !(in(i - 1, j, k) && in(i + 1, j, k) && in(i, j - 1, k) && in(i, j + 1, k) &&
                               in(i, j, k - 1) && in(i, j, k + 1)))
            points.push_back(v.index_to_physical(i, j, k));
    return points;
  };
  const auto pa = boundary(a), pb = boundary(b);
  std::vector<double> d;
  auto directed = [&](const auto& from, const auto& to) {
    for (const auto& p : from) {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& q : to) best = std::min(best, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]));
      d.push_back(best);
    }
  };
  directed(pa, pb);
  directed(pb, pa);
  return d;
}

TEST(Evaluate, IdenticalInputsScorePerfectly) {
  const Volume t = ball(grid({40, 36, 30}, {0.8, 1.0, 1.3}), {16, 17, 19}, 9.0);
  const SegmentationScores s = evaluate_segmentation(t, t);
  EXPECT_EQ(s.dice, 1.0);
  EXPECT_EQ(s.jaccard, 1.0);
  EXPECT_EQ(s.volume_difference_pct, 0.0);
  EXPECT_EQ(s.assd_mm, 0.0);
  EXPECT_EQ(s.hd95_mm, 0.0);
  EXPECT_EQ(s.hausdorff_mm, 0.0);
  EXPECT_GT(s.truth_boundary_voxels, 100u);
  EXPECT_EQ(s.seg_boundary_voxels, s.truth_boundary_voxels);
}

TEST(Evaluate, DistanceMapIsEuclideanInMillimetres) {
  Volume m = grid({9, 7, 5}, {0.5, 1.5, 2.0}, {3, -2, 1});
  m.direction = {0, 1, 0, -1, 0, 0, 0, 0, 1};  // a rotation: distances must not change
  m.at(4, 3, 2) = 1;
  m.at(0, 0, 0) = 1;
  const Volume d = distance_to_voxels(m);
  for (std::size_t k = 0; k < m.size[2]; ++k)
    for (std::size_t j = 0; j < m.size[1]; ++j)
      for (std::size_t i = 0; i < m.size[0]; ++i) {
        auto dist = [&](double a, double b, double c) {
          return std::hypot((i - a) * 0.5, (j - b) * 1.5, (k - c) * 2.0);
        };
        EXPECT_NEAR(d.at(i, j, k), std::min(dist(4, 3, 2), dist(0, 0, 0)), 1e-4) << i << "," << j << "," << k;
      }
}

TEST(Evaluate, ConcentricSpheresMatchTheAnalyticValues) {
  // Radii 12 and 9 mm on an anisotropic grid: Dice 2·r2³/(r1³+r2³), ASSD |r1 − r2|.
  const std::array<double, 3> spacing{1.0, 0.8, 1.2};
  const Volume g = grid({40, 50, 34}, spacing);
  const std::array<double, 3> c{19.7, 19.9, 19.6};
  const double r1 = 12, r2 = 9;
  const Volume big = ball(g, c, r1), small = ball(g, c, r2);
  const SegmentationScores s = evaluate_segmentation(small, big);
  const double dice = 2 * r2 * r2 * r2 / (r1 * r1 * r1 + r2 * r2 * r2);
  const double jaccard = r2 * r2 * r2 / (r1 * r1 * r1);
  const double half_voxel = 0.5 * 1.2;
  std::cout << "concentric spheres r1=12 r2=9 mm, spacing 1x0.8x1.2: dice " << s.dice << " (analytic " << dice
            << "), jaccard " << s.jaccard << " (" << jaccard << "), volume difference " << s.volume_difference_pct
            << " % (" << (jaccard - 1) * 100 << "), assd " << s.assd_mm << " mm (3), hd95 " << s.hd95_mm
            << " mm, hausdorff " << s.hausdorff_mm << " mm\n";
  EXPECT_NEAR(s.dice, dice, 0.01);
  EXPECT_NEAR(s.jaccard, jaccard, 0.01);
  EXPECT_NEAR(s.volume_difference_pct, (jaccard - 1) * 100, 1.5);
  EXPECT_NEAR(s.assd_mm, r1 - r2, half_voxel);
  EXPECT_NEAR(s.hd95_mm, r1 - r2, 2 * half_voxel);
  EXPECT_GE(s.hausdorff_mm, s.hd95_mm);
  EXPECT_LE(s.hausdorff_mm, r1 - r2 + 2 * half_voxel);
  // Symmetric in its distances.
  const SegmentationScores swapped = evaluate_segmentation(big, small);
  EXPECT_NEAR(swapped.assd_mm, s.assd_mm, 1e-9);
  EXPECT_NEAR(swapped.hausdorff_mm, s.hausdorff_mm, 1e-9);
  EXPECT_NEAR(swapped.dice, s.dice, 1e-12);
  // And the pooled distances are the brute-force ones.
  auto d = brute_force_distances(small, big);
  double sum = 0;
  for (double x : d) sum += x;
  EXPECT_NEAR(s.assd_mm, sum / d.size(), 1e-4);
  EXPECT_NEAR(s.hd95_mm, nearest_rank_percentile(d, 0.95), 1e-4);
}

TEST(Evaluate, OneVoxelShiftGivesTheExpectedValues) {
  // A 10×8×6 box and the same box one voxel further along each axis in turn.
  const std::array<double, 3> spacing{1.5, 1.0, 0.7};
  const Volume g = grid({16, 14, 12}, spacing);
  const Volume t = box(g, {3, 3, 3}, {13, 11, 9});
  const int extent[3] = {10, 8, 6};
  for (int axis = 0; axis < 3; ++axis) {
    std::array<int, 3> lo{3, 3, 3}, hi{13, 11, 9};
    ++lo[axis];
    ++hi[axis];
    const Volume s = box(g, lo, hi);
    const SegmentationScores r = evaluate_segmentation(s, t);
    const double n = extent[axis];
    EXPECT_DOUBLE_EQ(r.dice, (n - 1) / n) << "axis " << axis;
    EXPECT_DOUBLE_EQ(r.jaccard, (n - 1) / (n + 1)) << "axis " << axis;
    EXPECT_DOUBLE_EQ(r.volume_difference_pct, 0.0);
    EXPECT_NEAR(r.hausdorff_mm, spacing[axis], 1e-5) << "axis " << axis;
    const auto d = brute_force_distances(s, t);
    double sum = 0;
    for (double x : d) sum += x;
    EXPECT_NEAR(r.assd_mm, sum / d.size(), 1e-5) << "axis " << axis;
    EXPECT_NEAR(r.hd95_mm, nearest_rank_percentile(d, 0.95), 1e-5) << "axis " << axis;
    // Only the two faces across the shift are off, by exactly one spacing.
    EXPECT_GT(r.assd_mm, 0.0);
    EXPECT_LT(r.assd_mm, spacing[axis]);
  }
}

TEST(Evaluate, NearestRankPercentile) {
  std::vector<double> v;
  for (int i = 1; i <= 20; ++i) v.push_back(21 - i);
  EXPECT_EQ(nearest_rank_percentile(v, 0.95), 19);
  EXPECT_EQ(nearest_rank_percentile(v, 1.0), 20);
  EXPECT_EQ(nearest_rank_percentile({7}, 0.95), 7);
  std::vector<double> w;
  for (int i = 1; i <= 100; ++i) w.push_back(i);
  EXPECT_EQ(nearest_rank_percentile(w, 0.95), 95);
}

TEST(Evaluate, EmptySegmentationAndMissingLabel) {
  const Volume t = box(grid({10, 10, 10}, {1, 1, 1}), {2, 2, 2}, {8, 8, 8});
  const Volume empty = grid({10, 10, 10}, {1, 1, 1});
  const SegmentationScores s = evaluate_segmentation(empty, t);
  EXPECT_EQ(s.dice, 0.0);
  EXPECT_EQ(s.volume_difference_pct, -100.0);
  EXPECT_TRUE(std::isinf(s.assd_mm));
  const nlohmann::json j = s;
  EXPECT_TRUE(j.at("assd_mm").is_null());
  EXPECT_THROW(evaluate_segmentation(t, t, 1, 7), InputError);
  try {
    evaluate_segmentation(t, t, 1, 7);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("labels present: 0, 1"), std::string::npos) << e.what();
  }
}

TEST(Evaluate, DifferentGridsAreRefusedWithTheReason) {
  const Volume a = box(grid({10, 10, 10}, {1, 1, 1}), {2, 2, 2}, {8, 8, 8});
  auto message = [&](const Volume& b) {
    try {
      evaluate_segmentation(a, b);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(box(grid({10, 10, 11}, {1, 1, 1}), {2, 2, 2}, {8, 8, 8})).find("sizes 10x10x10 and 10x10x11"),
            std::string::npos);
  EXPECT_NE(message(box(grid({10, 10, 10}, {1, 1, 2}), {2, 2, 2}, {8, 8, 8})).find("spacings"), std::string::npos);
  EXPECT_NE(message(box(grid({10, 10, 10}, {1, 1, 1}, {0, 0.5, 0}), {2, 2, 2}, {8, 8, 8})).find("origins"),
            std::string::npos);
  Volume rotated = a;
  rotated.direction = {0, 1, 0, 1, 0, 0, 0, 0, -1};
  EXPECT_NE(message(rotated).find("direction"), std::string::npos);
}

TEST(EvaluateCli, ScoresFilesAndRefusesBadInput) {
  const auto dir = test::scratch_dir("evaluate-cli");
  const Volume g = grid({24, 24, 24}, {1, 1, 1}, {-12, -12, -12});
  const std::string t = (dir / "t.nii.gz").string(), s = (dir / "s.nii.gz").string(),
                    other = (dir / "o.nii.gz").string();
  write_volume(t, ball(g, {0, 0, 0}, 8), VoxelType::uint8);
  write_volume(s, ball(g, {1, 0, 0}, 8), VoxelType::uint8);
  write_volume(other, ball(grid({20, 24, 24}, {1, 1, 1}), {10, 12, 12}, 8), VoxelType::uint8);

  auto same = test::run_mrsnake("evaluate --seg " + t + " --truth " + t + " --json");
  ASSERT_EQ(same.exit_code, 0) << same.output;
  const auto j = nlohmann::json::parse(same.output);
  EXPECT_EQ(j.at("dice").get<double>(), 1.0);
  EXPECT_EQ(j.at("hausdorff_mm").get<double>(), 0.0);
  EXPECT_EQ(j.at("label").get<int>(), 1);

  auto shifted = test::run_mrsnake("evaluate --seg " + s + " --truth " + t);
  EXPECT_EQ(shifted.exit_code, 0) << shifted.output;
  EXPECT_NE(shifted.output.find("dice"), std::string::npos);
  EXPECT_NE(shifted.output.find("hausdorff            1.000 mm"), std::string::npos) << shifted.output;

  auto missing = test::run_mrsnake("evaluate --seg " + (dir / "nothing.nii.gz").string() + " --truth " + t);
  EXPECT_EQ(missing.exit_code, 3) << missing.output;
  EXPECT_NE(missing.output.find("does not exist"), std::string::npos) << missing.output;

  auto grids = test::run_mrsnake("evaluate --seg " + other + " --truth " + t);
  EXPECT_EQ(grids.exit_code, 3) << grids.output;
  EXPECT_NE(grids.output.find("different grids: sizes 20x24x24 and 24x24x24"), std::string::npos) << grids.output;

  auto label = test::run_mrsnake("evaluate --seg " + s + " --truth " + t + " --label 5");
  EXPECT_EQ(label.exit_code, 3) << label.output;

  // Surfaces: concentric spheres 1 mm apart.
  const std::string m1 = (dir / "r10.vtp").string(), m2 = (dir / "r11.vtp").string();
  write_mesh(m1, icosphere(4, 10.0));
  write_mesh(m2, icosphere(4, 11.0));
  auto meshes = test::run_mrsnake("evaluate --seg-mesh " + m1 + " --truth-mesh " + m2 + " --json");
  ASSERT_EQ(meshes.exit_code, 0) << meshes.output;
  const auto jm = nlohmann::json::parse(meshes.output).at("surface_distance");
  EXPECT_NEAR(jm.at("mean_mm").get<double>(), 1.0, 0.05);
  EXPECT_NEAR(jm.at("hausdorff_mm").get<double>(), 1.0, 0.1);
  auto both = test::run_mrsnake("evaluate --seg " + s + " --truth " + t + " --seg-mesh " + m1 + " --truth-mesh " + m1 +
                                " --json");
  ASSERT_EQ(both.exit_code, 0) << both.output;
  const auto jb = nlohmann::json::parse(both.output);
  EXPECT_TRUE(jb.contains("dice"));
  EXPECT_NEAR(jb.at("surface_distance").at("hausdorff_mm").get<double>(), 0.0, 1e-9);

  auto nothing = test::run_mrsnake("evaluate");
  EXPECT_EQ(nothing.exit_code, 2) << nothing.output;
  auto half = test::run_mrsnake("evaluate --seg " + s);
  EXPECT_EQ(half.exit_code, 2) << half.output;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mrsnake
