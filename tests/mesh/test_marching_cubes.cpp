#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/label_repair.h"
#include "mesh/label_resample.h"
#include "mesh/marching_cubes.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "tests/test_support.h"

using namespace mrsnake;

namespace {

/// A label volume with `label` on voxels whose physical centre lies within `radius` of
/// `centre`; returns the number of such voxels in `count`.
Volume voxelized_ball(const Volume& grid, const Eigen::Vector3d& centre, double radius, int label, std::size_t& count) {
  Volume v = grid;
  v.data.assign(v.num_voxels(), 0.0f);
  count = 0;
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) {
        const auto p = v.index_to_physical(double(i), double(j), double(k));
        if ((Eigen::Vector3d(p[0], p[1], p[2]) - centre).norm() <= radius) {
          v.at(i, j, k) = static_cast<float>(label);
          ++count;
        }
      }
  return v;
}

Volume grid(std::size_t n, std::array<double, 3> spacing) {
  Volume v;
  v.size = {n, n, n};
  v.spacing = spacing;
  return v;
}

}  // namespace

TEST(MarchingCubes, VoxelBallIsClosedGenusZeroWithTheLabelVolume) {
  std::size_t count = 0;
  const Volume labels = voxelized_ball(grid(48, {1, 1, 1}), {23.5, 23.5, 23.5}, 15.0, 7, count);
  const LabelSurface s = extract_label_surface(labels, 7);
  const auto topo = topology_report(s.mesh);
  EXPECT_TRUE(topo.is_closed_genus0()) << topo.describe();
  EXPECT_EQ(topo.inconsistently_oriented_edges, 0);
  EXPECT_EQ(s.components_found, 1);
  const double voxel_volume = static_cast<double>(count);
  EXPECT_GT(enclosed_volume(s.mesh), 0.0) << "must be oriented outward";
  EXPECT_NEAR(enclosed_volume(s.mesh) / voxel_volume, 1.0, 0.02);
}

TEST(MarchingCubes, SmoothingPreservesVolume) {
  std::size_t count = 0;
  const Volume labels = voxelized_ball(grid(40, {1, 1, 1}), {19.5, 19.5, 19.5}, 12.0, 1, count);
  LabelSurfaceOptions options;
  options.smoothing_iterations = 30;
  const LabelSurface raw = extract_label_surface(labels, 1);
  const LabelSurface smooth = extract_label_surface(labels, 1, options);
  EXPECT_NEAR(enclosed_volume(smooth.mesh) / enclosed_volume(raw.mesh), 1.0, 0.02);
  // Smoothing must actually move the staircase towards the sphere.
  const auto radial_spread = [](const TriMesh& m) {
    const Eigen::ArrayXd r = (m.V.rowwise() - Eigen::RowVector3d(19.5, 19.5, 19.5)).rowwise().norm().array();
    return std::sqrt((r - r.mean()).square().mean());
  };
  EXPECT_LT(radial_spread(smooth.mesh), 0.6 * radial_spread(raw.mesh));
}

TEST(MarchingCubes, ObliqueAnisotropicGridGivesThePhysicalPlace) {
  Volume g = grid(40, {0.7, 1.1, 1.6});
  g.origin = {-12.0, 30.0, 5.5};
  // A rotation of 30° about z then 20° about x: an oblique, proper direction matrix.
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) g.direction[3 * r + c] = R(r, c);
  // The ball's centre: the physical point of the grid's middle.
  const auto mid = g.index_to_physical(19.5, 19.5, 19.5);
  const Eigen::Vector3d centre(mid[0], mid[1], mid[2]);
  std::size_t count = 0;
  const Volume labels = voxelized_ball(g, centre, 11.0, 1, count);
  const LabelSurface s = extract_label_surface(labels, 1);
  const Eigen::Vector3d mesh_centre = s.mesh.V.colwise().mean().transpose();
  EXPECT_LT((mesh_centre - centre).norm(), 0.3);
  const Eigen::ArrayXd r = (s.mesh.V.rowwise() - centre.transpose()).rowwise().norm().array();
  EXPECT_NEAR(r.mean(), 11.0, 0.6);
  EXPECT_NEAR(enclosed_volume(s.mesh) / (count * 0.7 * 1.1 * 1.6), 1.0, 0.03);

  // A mirrored direction (det < 0) must still give an outward mesh at the same place.
  Volume mirrored = labels;
  for (int r = 0; r < 3; ++r) mirrored.direction[3 * r + 2] = -labels.direction[3 * r + 2];
  const LabelSurface m = extract_label_surface(mirrored, 1);
  EXPECT_GT(enclosed_volume(m.mesh), 0.0);
  EXPECT_EQ(topology_report(m.mesh).inconsistently_oriented_edges, 0);
}

TEST(MarchingCubes, ResampledOccupancyGivesTheBallWithFewerFaces) {
  // Thick slices and an oblique, mirrored direction: the resampled surface must still be the
  // ball, at its physical place, with the voxels' volume, closed, outward, and much smaller.
  Volume g;
  g.size = {56, 56, 28};
  g.spacing = {0.6, 0.6, 1.3};
  g.origin = {4.0, -20.0, 7.0};
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) g.direction[3 * r + c] = (c == 2 ? -1.0 : 1.0) * R(r, c);
  const auto mid = g.index_to_physical(27.5, 27.5, 13.5);
  const Eigen::Vector3d centre(mid[0], mid[1], mid[2]);
  std::size_t count = 0;
  const Volume labels = voxelized_ball(g, centre, 12.0, 4, count);
  const double voxel_volume = count * 0.6 * 0.6 * 1.3;

  LabelSurfaceOptions options;
  options.resample_spacing_mm = 1.5;
  const LabelSurface s = extract_label_surface(labels, 4, options);
  const auto topo = topology_report(s.mesh);
  EXPECT_TRUE(topo.is_closed_genus0()) << topo.describe();
  EXPECT_EQ(topo.inconsistently_oriented_edges, 0);
  EXPECT_GT(enclosed_volume(s.mesh), 0.0) << "must be oriented outward";
  EXPECT_NEAR(enclosed_volume(s.mesh) / voxel_volume, 1.0, 0.03);
  const Eigen::Vector3d mesh_centre = s.mesh.V.colwise().mean().transpose();
  EXPECT_LT((mesh_centre - centre).norm(), 0.3);
  const Eigen::ArrayXd r = (s.mesh.V.rowwise() - centre.transpose()).rowwise().norm().array();
  // The voxel ball's surface lies within half a voxel of the sphere; the resampled one with it.
  EXPECT_NEAR(r.mean(), 12.0, 0.4);
  EXPECT_LT((r - 12.0).abs().maxCoeff(), 1.0);

  const LabelSurface voxels = extract_label_surface(labels, 4);
  EXPECT_LT(s.mesh.num_faces() * 3, voxels.mesh.num_faces()) << "a 1.5 mm grid must give a much smaller surface";
  // Halving the spacing gives about four times as many faces (the size follows the spacing).
  options.resample_spacing_mm = 0.75;
  const LabelSurface fine = extract_label_surface(labels, 4, options);
  const double ratio = static_cast<double>(fine.mesh.num_faces()) / s.mesh.num_faces();
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 5.0);
  EXPECT_NEAR(enclosed_volume(fine.mesh) / voxel_volume, 1.0, 0.03);
}

TEST(MarchingCubes, OccupancyIsInZeroOneAndClosesAtTheBorder) {
  Volume labels = grid(12, {1, 1, 1});
  labels.data.assign(labels.num_voxels(), 2.0f);  // the whole volume is the object
  OccupancyOptions o;
  o.spacing_mm = 1.25;
  const Volume field = label_occupancy(labels, 2, o);
  for (float v : field.data) {
    ASSERT_GE(v, 0.0f);
    ASSERT_LE(v, 1.0f);
  }
  EXPECT_EQ(field.spacing[0], 1.25);
  // The margin is ~0 all around (so the 0.5 isosurface closes), the middle is inside.
  EXPECT_LT(field.at(0, 0, 0), 1e-3f);
  EXPECT_LT(field.at(field.size[0] - 1, field.size[1] - 1, field.size[2] - 1), 1e-3f);
  EXPECT_GT(field.at(field.size[0] / 2, field.size[1] / 2, field.size[2] / 2), 0.99f);
  LabelSurfaceOptions options;
  options.resample_spacing_mm = 1.25;
  const LabelSurface s = extract_label_surface(labels, 2, options);
  EXPECT_TRUE(topology_report(s.mesh).is_closed_genus0());
  EXPECT_NEAR(enclosed_volume(s.mesh) / 1728.0, 1.0, 0.08);  // a rounded cube of 12 mm
  EXPECT_THROW(label_occupancy(labels, 3, o), InputError);
  o.spacing_mm = 0;
  EXPECT_THROW(label_occupancy(labels, 2, o), std::invalid_argument);
  // Spacings far from the voxels' would need grids of billions of voxels: refused up front.
  o.spacing_mm = 1e-4;  // 12 mm / 1e-4 mm = 120,000 cells per axis
  EXPECT_THROW(label_occupancy(labels, 2, o), InputError);
  o.spacing_mm = 500;  // a margin of about 1,300 voxels per side
  EXPECT_THROW(label_occupancy(labels, 2, o), InputError);
}

TEST(MarchingCubes, OccupancyIsTheMaskSmoothedBySigmaAndCrossesOneHalfAtTheVoxelBoundary) {
  // A box of voxels of 0.6 x 0.6 x 1.3 mm (the liver's shape of voxel), origin 0, identity
  // direction, sampled on a 1.3 mm grid: along z the samples are the voxel centres. There the
  // field is the mask convolved with the sampled Gaussian of sigma = 1.3/3 mm (taps at 0 and
  // ±1.3 mm: weights 1 and exp(-4.5), normalized), so the last voxel inside has exactly
  // 1 - w and the first outside w; the 0.5 crossing is halfway between them, on the voxels'
  // boundary. Along x (samples every 1.3 mm over 0.6 mm voxels) the crossing is within the
  // linear interpolation's error of the boundary.
  Volume labels = grid(40, {0.6, 0.6, 1.3});
  labels.data.assign(labels.num_voxels(), 0.0f);
  for (std::size_t k = 10; k <= 25; ++k)
    for (std::size_t j = 8; j <= 30; ++j)
      for (std::size_t i = 12; i <= 27; ++i) labels.at(i, j, k) = 3.0f;
  OccupancyOptions o;
  o.spacing_mm = 1.3;
  const Volume field = label_occupancy(labels, 3, o);
  ASSERT_EQ(field.spacing[2], 1.3);
  const double w = std::exp(-4.5) / (1 + 2 * std::exp(-4.5));
  // The sample nearest the box's middle, and the 0.5 crossings along axis d through it (mm).
  std::size_t middle[3];
  const double middle_mm[3] = {0.6 * 19.5, 0.6 * 19, 1.3 * 17.5};
  for (int e = 0; e < 3; ++e) middle[e] = static_cast<std::size_t>(std::lround((middle_mm[e] - field.origin[e]) / 1.3));
  const auto value = [&](int d, std::size_t i) {
    std::size_t p[3] = {middle[0], middle[1], middle[2]};
    p[d] = i;
    return static_cast<double>(field.at(p[0], p[1], p[2]));
  };
  const auto crossings = [&](int d) {
    std::vector<double> found;
    for (std::size_t i = 0; i + 1 < field.size[d]; ++i) {
      const double a = value(d, i), b = value(d, i + 1);
      if ((a - 0.5) * (b - 0.5) < 0)
        found.push_back(field.origin[d] + 1.3 * (static_cast<double>(i) + (0.5 - a) / (b - a)));
    }
    return found;
  };
  const std::vector<double> x = crossings(0), z = crossings(2);
  ASSERT_EQ(z.size(), 2u);
  EXPECT_NEAR(z[0], 1.3 * 9.5, 1e-4);
  EXPECT_NEAR(z[1], 1.3 * 25.5, 1e-4);
  const auto z_index = [&](double k) {
    return static_cast<std::size_t>(std::lround((1.3 * k - field.origin[2]) / 1.3));
  };
  EXPECT_NEAR(value(2, z_index(10)), 1 - w, 1e-5);
  EXPECT_NEAR(value(2, z_index(9)), w, 1e-5);
  EXPECT_NEAR(value(2, z_index(17)), 1.0, 1e-5);
  ASSERT_EQ(x.size(), 2u);
  EXPECT_NEAR(x[0], 0.6 * 11.5, 0.3);
  EXPECT_NEAR(x[1], 0.6 * 27.5, 0.3);
  EXPECT_NEAR(x[0] + x[1], 0.6 * 39, 0.6);
  EXPECT_LT(field.at(0, 0, 0), 1e-6f);
}

TEST(MarchingCubes, KeepsTheLargestComponentAndReportsTheOthers) {
  std::size_t count = 0;
  Volume labels = voxelized_ball(grid(40, {1, 1, 1}), {12, 12, 12}, 8.0, 1, count);
  std::size_t small = 0;
  const Volume second = voxelized_ball(labels, {30, 30, 30}, 4.0, 1, small);
  for (std::size_t i = 0; i < labels.data.size(); ++i) labels.data[i] = std::max(labels.data[i], second.data[i]);
  const LabelSurface s = extract_label_surface(labels, 1);
  EXPECT_EQ(s.components_found, 2);
  ASSERT_EQ(s.dropped_component_faces.size(), 1u);
  EXPECT_TRUE(topology_report(s.mesh).is_closed_genus0());
  EXPECT_LT((s.mesh.V.colwise().mean() - Eigen::RowVector3d(12, 12, 12)).norm(), 0.3);
}

TEST(MarchingCubes, ObjectTouchingTheBorderIsClosed) {
  Volume labels = grid(10, {1, 1, 1});
  labels.data.assign(labels.num_voxels(), 1.0f);  // the whole volume is the object
  const LabelSurface s = extract_label_surface(labels, 1);
  EXPECT_TRUE(topology_report(s.mesh).is_closed_genus0());
}

TEST(MarchingCubes, MissingLabelListsThePresentOnes) {
  std::size_t count = 0;
  const Volume labels = voxelized_ball(grid(16, {1, 1, 1}), {8, 8, 8}, 4.0, 3, count);
  try {
    extract_label_surface(labels, 5);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("labels present: 0, 3"), std::string::npos) << e.what();
  }
}

TEST(MarchingCubes, IsosurfaceOfADistanceFieldIsTheSphere) {
  Volume field = grid(32, {1, 1, 1});
  field.data.resize(field.num_voxels());
  for (std::size_t k = 0; k < 32; ++k)
    for (std::size_t j = 0; j < 32; ++j)
      for (std::size_t i = 0; i < 32; ++i)
        field.at(i, j, k) = static_cast<float>(10.0 - Eigen::Vector3d(i - 15.5, j - 15.5, k - 15.5).norm());
  const TriMesh s = extract_isosurface(field, 0.0);
  const Eigen::ArrayXd r = (s.V.rowwise() - Eigen::RowVector3d(15.5, 15.5, 15.5)).rowwise().norm().array();
  EXPECT_NEAR(r.minCoeff(), 10.0, 0.05);
  EXPECT_NEAR(r.maxCoeff(), 10.0, 0.05);
  EXPECT_NEAR(enclosed_volume(s) / (4.0 / 3.0 * M_PI * 1000.0), 1.0, 0.01);
}

TEST(McCommand, WritesAMeshAndRefusesAnAbsentLabel) {
  const auto dir = test::scratch_dir("mc-cli");
  std::size_t count = 0;
  const Volume labels = voxelized_ball(grid(24, {1, 1, 2}), {11.5, 11.5, 23}, 7.0, 2, count);
  const std::string img = (dir / "labels.nii.gz").string();
  write_volume(img, labels, VoxelType::uint8);
  auto r = test::run_mrsnake("mc --labels " + img + " --label 2 -o " + (dir / "s.vtp").string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(topology_report(read_mesh((dir / "s.vtp").string())).is_closed_genus0());
  r = test::run_mrsnake("mc --labels " + img + " --label 9 -o " + (dir / "t.vtp").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("not present"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "t.vtp"));
  r = test::run_mrsnake("mc --labels " + (dir / "nope.nii.gz").string() + " --label 1 -o " + (dir / "u.vtp").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
}

TEST(McCommand, ComponentExtractsOnePartOfTheLabel) {
  // Label 4 on two balls of radius 6 and 4: --component picks one, the rest is background.
  const auto dir = test::scratch_dir("mc-cli-parts");
  std::size_t big = 0, small = 0;
  Volume labels = voxelized_ball(grid(32, {1, 1, 1}), {8, 16, 16}, 6.0, 4, big);
  const Volume other = voxelized_ball(grid(32, {1, 1, 1}), {24, 16, 16}, 4.0, 4, small);
  for (std::size_t i = 0; i < labels.num_voxels(); ++i) labels.data[i] += other.data[i];
  const std::string img = (dir / "labels.nii.gz").string();
  write_volume(img, labels, VoxelType::uint8);
  const auto centre_x = [](const TriMesh& m) { return m.V.col(0).mean(); };
  for (const int part : {1, 2}) {
    const std::string out = (dir / ("part" + std::to_string(part) + ".vtp")).string();
    const auto r =
        test::run_mrsnake("mc --labels " + img + " --label 4 --component " + std::to_string(part) + " -o " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("connected surfaces"), std::string::npos) << r.output;  // nothing dropped
    EXPECT_NEAR(centre_x(read_mesh(out)), part == 1 ? 8.0 : 24.0, 0.5);
  }
  const auto r = test::run_mrsnake("mc --labels " + img + " --label 4 --component 3 -o " + (dir / "p3.vtp").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("label 4 has 2 connected parts, so there is no part 3"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "p3.vtp"));
}

TEST(McCommand, LiverIsOneClosedGenusZeroSurface) {
  MRSNAKE_REQUIRE_DATA(liver, "volumes/liver-labels.nii.gz");
  const Volume labels = read_volume(liver);
  const LabelSurface s = extract_label_surface(labels, 255);
  const auto topo = topology_report(s.mesh);
  EXPECT_TRUE(topo.is_closed_genus0()) << topo.describe();
  EXPECT_GT(s.mesh.num_faces(), 10000);
}

TEST(MarchingCubes, ClosingRepairsATunnelOnlyWhenAsked) {
  // A torus (major radius 9, minor 5.5): its hole has radius 3.5 voxels.
  Volume labels = grid(40, {1, 1, 1});
  labels.data.assign(labels.num_voxels(), 0.f);
  for (std::size_t k = 0; k < 40; ++k)
    for (std::size_t j = 0; j < 40; ++j)
      for (std::size_t i = 0; i < 40; ++i) {
        const double x = i - 19.5, y = j - 19.5, z = k - 19.5;
        const double ring = std::hypot(x, y) - 9.0;
        if (ring * ring + z * z <= 5.5 * 5.5) labels.at(i, j, k) = 4.f;
      }
  const LabelSurface plain = extract_label_surface(labels, 4);
  EXPECT_EQ(topology_report(plain.mesh).genus, 1);
  EXPECT_EQ(plain.closing_radius, 0);

  LabelSurfaceOptions options;
  options.max_closing_radius = 6;
  const LabelSurface repaired = extract_label_surface(labels, 4, options);
  EXPECT_TRUE(topology_report(repaired.mesh).is_closed_genus0());
  EXPECT_EQ(repaired.genus_before_repair, 1);
  EXPECT_GE(repaired.closing_radius, 1);
  EXPECT_LE(repaired.closing_radius, 6);
  // The repair fills the hole but keeps the outside: the volume only grows, and not by much.
  EXPECT_GT(enclosed_volume(repaired.mesh), enclosed_volume(plain.mesh));
  EXPECT_LT(enclosed_volume(repaired.mesh), 1.3 * enclosed_volume(plain.mesh));
}

TEST(LabelParts, KeepsThePartOfTheRankAskedAndLeavesOtherLabels) {
  // Label 7 on two balls (radius 5 and 3.5) and on a voxel touching the smaller one only
  // along an edge (a part of its own: parts are face-connected); label 2 on a third ball.
  std::size_t big = 0, small = 0, other = 0;
  Volume labels = voxelized_ball(grid(40, {1, 1, 1}), {10, 10, 10}, 5.0, 7, big);
  const Volume b = voxelized_ball(grid(40, {1, 1, 1}), {28, 28, 10}, 3.5, 7, small);
  const Volume c = voxelized_ball(grid(40, {1, 1, 1}), {10, 30, 30}, 4.0, 2, other);
  for (std::size_t i = 0; i < labels.num_voxels(); ++i) labels.data[i] += b.data[i] + c.data[i];
  ASSERT_EQ(labels.at(29, 28, 13), 7.f);  // on the top layer of the smaller ball
  labels.at(30, 28, 14) = 7.f;            // meets (29, 28, 13) along an edge only
  const auto count = [](const Volume& v, float value) {
    return static_cast<std::size_t>(std::count(v.data.begin(), v.data.end(), value));
  };
  const Volume first = keep_label_part(labels, 7, 1), second = keep_label_part(labels, 7, 2),
               third = keep_label_part(labels, 7, 3);
  EXPECT_EQ(count(first, 7.f), big);
  EXPECT_EQ(first.at(10, 10, 10), 7.f);
  EXPECT_EQ(count(second, 7.f), small);
  EXPECT_EQ(second.at(28, 28, 10), 7.f);
  EXPECT_EQ(count(third, 7.f), 1u);
  EXPECT_EQ(third.at(30, 28, 14), 7.f);
  for (const Volume* v : {&first, &second, &third}) {
    EXPECT_EQ(count(*v, 2.f), other);  // other labels untouched
    EXPECT_EQ(v->size, labels.size);
  }
  try {
    keep_label_part(labels, 7, 4);
    ADD_FAILURE() << "a fourth part of three was accepted";
  } catch (const InputError& e) {
    // The library says what is wrong; the command words the remedy (apps/hints.h).
    EXPECT_EQ(std::string(e.what()), "label 7 has 3 connected parts, so there is no part 4");
    EXPECT_EQ(e.remedy(), Remedy::choose_component);
    EXPECT_EQ(e.remedy_limit(), 3);
  }
  EXPECT_THROW(keep_label_part(labels, 9, 1), InputError);
}
