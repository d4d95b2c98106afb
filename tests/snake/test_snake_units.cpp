// Unit tests of the snake module: sampler, pyramid, rasterization, internal forces,
// initialization, the stand-in model's synthesis, the searches and appearance I/O.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "model/sections.h"
#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/marching_cubes.h"
#include "mesh/primitives.h"
#include "mesh/subdivision.h"
#include "snake/appearance.h"
#include "snake/deformable_surface.h"
#include "snake/forces.h"
#include "snake/image_pyramid.h"
#include "snake/initialize.h"
#include "snake/rasterize.h"
#include "snake/sampler.h"
#include "snake/segment.h"
#include "tests/support/midpoint_frame_model.h"
#include "snake/surface_geometry.h"
#include "tests/test_support.h"

using namespace mrsnake;

namespace {

Eigen::Matrix3d rotation(double deg, Eigen::Vector3d axis) {
  return Eigen::AngleAxisd(deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
}

Volume make_grid(std::array<std::size_t, 3> size, std::array<double, 3> spacing, std::array<double, 3> origin,
                 const Eigen::Matrix3d& D) {
  Volume v;
  v.size = size;
  v.spacing = spacing;
  v.origin = origin;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) v.direction[3 * r + c] = D(r, c);
  v.data.assign(v.num_voxels(), 0.0f);
  return v;
}

Eigen::Vector3d physical(const Volume& v, std::size_t i, std::size_t j, std::size_t k) {
  const auto p = v.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
  return {p[0], p[1], p[2]};
}

// Fills a volume with an implicit object: value `in` where phi < 0, `out` elsewhere,
// supersampled (n³ per voxel) for partial volume.
template <class Phi>
void fill_object(Volume& v, Phi phi, float in, float out, int n = 3) {
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) {
        int inside = 0;
        for (int a = 0; a < n; ++a)
          for (int b = 0; b < n; ++b)
            for (int c = 0; c < n; ++c) {
              const auto p =
                  v.index_to_physical(i + (a + 0.5) / n - 0.5, j + (b + 0.5) / n - 0.5, k + (c + 0.5) / n - 0.5);
              inside += phi(Eigen::Vector3d(p[0], p[1], p[2])) < 0;
            }
        const double f = inside / double(n * n * n);
        v.at(i, j, k) = static_cast<float>(out + f * (in - out));
      }
}

// Adds Gaussian noise of the given sigma to every voxel, reproducibly (seeded).
void add_noise(Volume& v, float sigma, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma);
  for (float& x : v.data) x += noise(rng);
}

// The faces of an n × n grid of vertices (vertex y·n + x), each square split along the same
// diagonal: valence 6 inside.
RowMatrixX3i grid_faces(int n) {
  RowMatrixX3i F(2 * (n - 1) * (n - 1), 3);
  int f = 0;
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      const int a = y * n + x;
      F.row(f++) << a, a + 1, a + n;
      F.row(f++) << a + 1, a + n + 1, a + n;
    }
  return F;
}

// Icospheres of radius r subdivided 1..count times: the levels and faces of a small hierarchy
// (vertex positions only; not nested) for learning appearances.
std::pair<std::vector<RowMatrixX3d>, std::vector<RowMatrixX3i>> icosphere_levels(int count, double radius) {
  std::vector<RowMatrixX3d> levels;
  std::vector<RowMatrixX3i> faces;
  for (int j = 0; j < count; ++j) {
    const TriMesh sphere = icosphere(j + 1, radius);
    levels.push_back(sphere.V);
    faces.push_back(sphere.F);
  }
  return {levels, faces};
}

}  // namespace

TEST(Sampler, ExactOnALinearImageWithObliqueDirection) {
  const Eigen::Matrix3d D = rotation(30, {1, 2, 3});
  Volume v = make_grid({9, 8, 7}, {0.7, 1.1, 1.9}, {3, -2, 5}, D);
  const Eigen::Vector3d a(0.3, -1.2, 2.1);
  const double c = 4.0;
  for (std::size_t k = 0; k < 7; ++k)
    for (std::size_t j = 0; j < 8; ++j)
      for (std::size_t i = 0; i < 9; ++i) v.at(i, j, k) = static_cast<float>(a.dot(physical(v, i, j, k)) + c);
  const VolumeSampler s(v);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ui(0.2, 7.8), uj(0.2, 6.8), uk(0.2, 5.8);
  for (int t = 0; t < 200; ++t) {
    const auto p = v.index_to_physical(ui(rng), uj(rng), uk(rng));
    const Eigen::Vector3d x(p[0], p[1], p[2]);
    Eigen::Vector3d g;
    const float val = s.value_and_gradient(x, g);
    EXPECT_NEAR(val, a.dot(x) + c, 1e-3);
    EXPECT_NEAR(s.value(x), a.dot(x) + c, 1e-3);
    EXPECT_NEAR((g - a).norm(), 0.0, 1e-4);
    EXPECT_TRUE(s.inside(x));
  }
  // Outside: the nearest border value, and inside() says so.
  const auto far = v.index_to_physical(-5, 3, 3);
  const auto edge = v.index_to_physical(0, 3, 3);
  EXPECT_FALSE(s.inside({far[0], far[1], far[2]}));
  EXPECT_NEAR(s.value({far[0], far[1], far[2]}), s.value({edge[0], edge[1], edge[2]}), 1e-4);
}

// The line sampler of the searches must give value() at every point: inside the image (the
// fast path without clamps: forwards, backwards, one point, an end just below the last voxel
// plane), and across the border or along the last plane (the clamped path), on a random
// image with an oblique direction and anisotropic spacing.
TEST(Sampler, ValuesAlongALineMatchValueAtEachPoint) {
  Volume v = make_grid({9, 8, 7}, {0.7, 1.1, 1.9}, {3, -2, 5}, rotation(30, {1, 2, 3}));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(-3.0f, 7.0f);
  for (float& x : v.data) x = noise(rng);
  const VolumeSampler s(v, 0.5, 2.0);
  const auto at = [&](double i, double j, double k) {
    const auto p = v.index_to_physical(i, j, k);
    return Eigen::Vector3d(p[0], p[1], p[2]);
  };
  struct Line {
    Eigen::Vector3d from, to;
    double t0, dt;
    int count;
  };
  const std::vector<Line> lines{
      {at(1.2, 1.7, 1.1), at(6.9, 5.3, 4.8), 0.1, 0.8 / 22, 23},         // inside
      {at(1.2, 1.7, 1.1), at(6.9, 5.3, 4.8), 0.9, -0.8 / 22, 23},        // inside, backwards
      {at(1.2, 1.7, 1.1), at(6.9, 5.3, 4.8), 0.5, 0.1, 1},               // one point
      {at(2.2, 3.1, 1.5), at(8.0 - 1e-9, 3.1, 1.5), 0.0, 1.0 / 22, 23},  // up to just below x = n − 1
      {at(-2.0, 3.5, 2.5), at(10.5, 3.5, 2.5), -0.25, 1.5 / 22, 23},     // through two faces
      {at(8.0, 2.2, 3.3), at(8.0, 6.1, 5.2), -0.25, 1.5 / 22, 23},       // on the last x plane
      {at(4.4, 3.3, 2.2), at(4.4, 3.3, 2.2), -0.25, 1.5 / 22, 23}};      // zero direction
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const Line& line = lines[l];
    const Eigen::Vector3d dir = line.to - line.from;
    std::vector<double> out(line.count, -99.0);
    s.values_along(line.from, dir, line.t0, line.dt, line.count, out.data());
    for (int k = 0; k < line.count; ++k)
      EXPECT_NEAR(out[k], s.value(line.from + (line.t0 + k * line.dt) * dir), 1e-5) << "line " << l << ", point " << k;
  }
  std::vector<double> none(1, -99.0);
  s.values_along(lines[0].from, lines[0].to, 0.0, 1.0, 0, none.data());
  EXPECT_EQ(none[0], -99.0);
  // A NaN point is clamped like any other outside point (to the first voxel), not read wildly.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isfinite(s.value(Eigen::Vector3d(nan, 0.0, 0.0))));
}

TEST(Pyramid, DownsamplingKeepsPhysicalPositions) {
  const Eigen::Matrix3d D = rotation(20, {0, 1, 1});
  Volume v = make_grid({16, 12, 9}, {1.0, 0.5, 2.0}, {1, 2, 3}, D);
  const Eigen::Vector3d a(1.0, -2.0, 0.5);
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) v.at(i, j, k) = static_cast<float>(a.dot(physical(v, i, j, k)));
  const Volume h = downsample_by_two(v);
  EXPECT_EQ(h.size[0], 8u);
  EXPECT_EQ(h.size[1], 6u);
  EXPECT_EQ(h.size[2], 5u);  // odd axis: the last block is a single slice
  EXPECT_DOUBLE_EQ(h.spacing[1], 1.0);
  // The mean of a linear function over a full block is its value at the block centre.
  for (std::size_t k = 0; k < 4; ++k)
    for (std::size_t j = 0; j < h.size[1]; ++j)
      for (std::size_t i = 0; i < h.size[0]; ++i) EXPECT_NEAR(h.at(i, j, k), a.dot(physical(h, i, j, k)), 1e-3);
  const auto pyr = build_pyramid(v, 5, 4);
  EXPECT_EQ(pyr.size(), 2u);  // 9 → 5 → 3 (< 4) stops
}

TEST(Pyramid, NormalizationMapsPercentiles) {
  Volume v = make_grid({10, 10, 10}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  for (std::size_t i = 0; i < v.data.size(); ++i) v.data[i] = static_cast<float>(i);  // 0..999
  const IntensityWindow w = normalize_intensities(v, 10, 90);
  EXPECT_NEAR(w.low, 100, 1.0);
  EXPECT_NEAR(w.high, 899, 1.0);
  EXPECT_NEAR(v.data[100], 0.0, 0.01);
  EXPECT_NEAR(v.data[899], 1.0, 0.01);
  Volume flat = make_grid({4, 4, 4}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  EXPECT_THROW(normalize_intensities(flat), InputError);
}

TEST(Pyramid, TheSegmentsIntensitySubsampleGivesTheFullImagesWindow) {
  // A noisy sphere on a dark background (2^20 voxels): the window segment estimates from
  // SegmentOptions::intensity_samples voxels on a regular stride is the one of every voxel,
  // to within 1% of its width.
  Volume v = make_grid({128, 128, 64}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.25f);
  for (std::size_t k = 0; k < 64; ++k)
    for (std::size_t j = 0; j < 128; ++j)
      for (std::size_t i = 0; i < 128; ++i) {
        const double r2 = (i - 64.0) * (i - 64.0) + (j - 64.0) * (j - 64.0) + 4.0 * (k - 32.0) * (k - 32.0);
        v.at(i, j, k) = (r2 < 40.0 * 40.0 ? 1.0f : 0.0f) + noise(rng);
      }
  const IntensityWindow all = robust_intensity_window(v, 1.0, 99.0, v.data.size());
  const SegmentOptions options;
  ASSERT_LT(options.intensity_samples, v.data.size() / 3);  // a true subsample
  const IntensityWindow sub = robust_intensity_window(v, 1.0, 99.0, options.intensity_samples);
  const double width = all.high - all.low;
  EXPECT_GT(width, 1.0);
  EXPECT_NEAR(sub.low, all.low, 0.01 * width);
  EXPECT_NEAR(sub.high, all.high, 0.01 * width);
}

TEST(Pyramid, TheIntensitySubsampleSeesEveryPartOfARow) {
  // A bright slab of 8 x planes (12.5 % of the voxels) in a 64-voxel row: a stride of 16 along
  // the flat index would only ever read x = 0, 16, 32, 48 and miss it; the 3D lattice must not.
  Volume v = make_grid({64, 32, 32}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  for (std::size_t k = 0; k < 32; ++k)
    for (std::size_t j = 0; j < 32; ++j)
      for (std::size_t i = 0; i < 64; ++i) v.at(i, j, k) = (i >= 1 && i <= 8) ? 10.0f : static_cast<float>(i % 3);
  const std::size_t max_samples = v.data.size() / 16;
  const IntensityWindow all = robust_intensity_window(v, 1.0, 99.0, v.data.size());
  const IntensityWindow sub = robust_intensity_window(v, 1.0, 99.0, max_samples);
  EXPECT_EQ(all.high, 10.0);
  EXPECT_EQ(sub.high, 10.0);
  EXPECT_EQ(sub.low, all.low);
}

TEST(Rasterize, SphereMatchesTheLatticeWithObliqueDirection) {
  const Eigen::Matrix3d D = rotation(35, {1, -1, 2});
  const Volume grid = make_grid({40, 36, 30}, {0.8, 0.9, 1.1}, {-12, -14, -11}, D);
  const Eigen::Vector3d centre = physical(grid, 20, 18, 15) + Eigen::Vector3d(0.13, -0.21, 0.17);
  const double r = 10.0;
  TriMesh sphere = icosphere(5, r);
  sphere.V.rowwise() += centre.transpose();
  // The icosphere lies between its inradius (distance to the flattest face) and r.
  double r_in = r;
  for (int f = 0; f < sphere.num_faces(); ++f) {
    const Eigen::Vector3d a = sphere.V.row(sphere.F(f, 0)), b = sphere.V.row(sphere.F(f, 1)),
                          c = sphere.V.row(sphere.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    r_in = std::min(r_in, std::abs(n.dot(a - centre)));
  }
  const Volume labels = rasterize_mesh(sphere, grid, 1.0f);
  long count = 0, wrong = 0, ambiguous = 0;
  for (std::size_t k = 0; k < grid.size[2]; ++k)
    for (std::size_t j = 0; j < grid.size[1]; ++j)
      for (std::size_t i = 0; i < grid.size[0]; ++i) {
        const double d = (physical(grid, i, j, k) - centre).norm();
        const bool in = labels.at(i, j, k) > 0.5f;
        count += in;
        if (d < r_in)
          wrong += !in;
        else if (d > r)
          wrong += in;
        else
          ++ambiguous;
      }
  EXPECT_EQ(wrong, 0);
  EXPECT_LT(ambiguous, 40);
  const double voxel = 0.8 * 0.9 * 1.1;
  EXPECT_NEAR(count * voxel, 4.0 / 3.0 * M_PI * r * r * r, 0.01 * 4.0 / 3.0 * M_PI * r * r * r);
  EXPECT_EQ(labels.direction, grid.direction);
  EXPECT_EQ(labels.origin, grid.origin);
}

TEST(Internal, UmbrellaOfARegularPlanarPatchIsZero) {
  // A regular triangulated plane (valence 6 inside), with an arbitrary rigid motion.
  const int n = 7;
  RowMatrixX3d V(n * n, 3);
  const Eigen::Matrix3d R = rotation(40, {1, 1, 0});
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      V.row(y * n + x) =
          (R * Eigen::Vector3d(x + 0.5 * y, y * std::sqrt(3.0) / 2, 0) + Eigen::Vector3d(1, 2, 3)).transpose();
  const VertexRings rings = build_vertex_rings(grid_faces(n), n * n);
  RowMatrixX3d U;
  umbrella(rings, V, U);
  for (int y = 1; y + 1 < n; ++y)
    for (int x = 1; x + 1 < n; ++x) {
      EXPECT_EQ(rings.valence(y * n + x), 6);
      EXPECT_NEAR(U.row(y * n + x).norm(), 0.0, 1e-12);
    }
}

TEST(Internal, PriorTermIsZeroAtTheModelsShapeInAnyPose) {
  // A non-uniform model: an ellipsoid-like bumpy icosphere.
  TriMesh m = icosphere(3, 10.0);
  for (int v = 0; v < m.num_vertices(); ++v) {
    Eigen::Vector3d x = m.V.row(v);
    x = x.cwiseProduct(Eigen::Vector3d(1.4, 1.0, 0.7)) * (1.0 + 0.1 * std::sin(x.x() / 3));
    m.V.row(v) = x.transpose();
  }
  SnakeOptions o;
  o.tangential_weight = 0.5;  // relative to the model's tangential umbrella: zero there too
  o.membrane_weight = 0;
  o.prior_weight = 0.5;
  o.thin_plate_weight = 0.2;
  const DeformableSurface snake(m.F, m.V, o);
  EXPECT_LT(snake.internal_forces(m.V).rowwise().norm().maxCoeff(), 1e-10);
  Similarity s;
  s.rotation = rotation(50, {1, 2, -1});
  s.scale = 1.7;
  s.translation = {5, -3, 2};
  const RowMatrixX3d moved = s.apply(m.V);
  EXPECT_LT(snake.internal_forces(moved).rowwise().norm().maxCoeff(), 1e-9);
  // A plain membrane is not zero there (it shrinks the surface), and the prior pulls back a bump.
  SnakeOptions plain = o;
  plain.prior_weight = 0;
  plain.thin_plate_weight = 0;
  plain.membrane_weight = 0.5;
  const DeformableSurface membrane(m.F, m.V, plain);
  EXPECT_GT(membrane.internal_forces(m.V).rowwise().norm().maxCoeff(), 1e-2);
  RowMatrixX3d bumped = m.V;
  RowMatrixX3d N;
  vertex_normals(m.V, m.F, N);
  bumped.row(100) += 2.0 * N.row(100);
  EXPECT_LT(snake.internal_forces(bumped).row(100).dot(N.row(100)), -0.1);
}

TEST(Internal, TangentialTermKeepsTheModelsSamplingNotAUniformOne) {
  // A non-uniformly sampled sphere: vertices crowd towards +z. The tangential term measured
  // against the model is zero there in any pose, and pulls a vertex slid along the surface
  // back; a plain uniform tangential pull (the model's own umbrella not subtracted) is not
  // zero on it, which moved coarse real meshes away from the model before any image force.
  TriMesh m = icosphere(3, 10.0);
  for (int v = 0; v < m.num_vertices(); ++v) {
    Eigen::Vector3d x = m.V.row(v);
    x.z() = 10.0 * std::sin(0.5 * M_PI * (0.6 * x.z() / 10.0 + 0.4 * std::pow(x.z() / 10.0, 3)));
    m.V.row(v) = (10.0 * x.normalized()).transpose();
  }
  SnakeOptions o;
  o.membrane_weight = 0;
  o.prior_weight = 0;
  o.thin_plate_weight = 0;
  o.tangential_weight = 1.0;
  const DeformableSurface snake(m.F, m.V, o);
  EXPECT_LT(snake.internal_forces(m.V).rowwise().norm().maxCoeff(), 1e-10);
  Similarity s;
  s.rotation = rotation(120, {-1, 0.5, 2});
  s.scale = 0.4;
  s.translation = {-7, 3, 1};
  EXPECT_LT(snake.internal_forces(s.apply(m.V)).rowwise().norm().maxCoeff(), 1e-9);
  // A vertex slid tangentially by 0.3 mm is pulled back along the slide.
  RowMatrixX3d N;
  vertex_normals(m.V, m.F, N);
  const int v = 200;
  const Eigen::Vector3d slide = N.row(v).transpose().unitOrthogonal() * 0.3;
  RowMatrixX3d slid = m.V;
  slid.row(v) += slide.transpose();
  EXPECT_LT(snake.internal_forces(slid).row(v).dot(slide), -0.1 * slide.squaredNorm());
  // What the old uniform pull gives on the model itself: the umbrella's tangential part.
  RowMatrixX3d U;
  umbrella(snake.rings(), m.V, U);
  double uniform_max = 0;
  for (int k = 0; k < m.num_vertices(); ++k)
    uniform_max = std::max(uniform_max, (U.row(k) - U.row(k).dot(N.row(k)) * N.row(k)).norm());
  EXPECT_GT(uniform_max, 0.05);
}

TEST(Internal, RingMedianRemovesAnIsolatedOutlierThatTheMeanSpreads) {
  const TriMesh m = icosphere(2, 10.0);
  const VertexRings rings = build_vertex_rings(m.F, m.num_vertices());
  Eigen::VectorXd values = Eigen::VectorXd::Constant(m.num_vertices(), 1.0);
  values[17] = 12.0;  // a false match
  Eigen::VectorXd mean = values, median = values;
  smooth_on_rings(rings, mean, 1);
  median_on_rings(rings, median, 1);
  EXPECT_NEAR(median.maxCoeff(), 1.0, 1e-15);
  EXPECT_NEAR(median.minCoeff(), 1.0, 1e-15);
  EXPECT_GT(mean.maxCoeff(), 2.0);  // the mean spreads it over the ring
  // An even window takes the mean of its two middle values; a monotone field stays monotone.
  Eigen::VectorXd ramp(m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) ramp[v] = m.V(v, 2);
  Eigen::VectorXd filtered = ramp;
  median_on_rings(rings, filtered, 1);
  EXPECT_LE(filtered.maxCoeff(), ramp.maxCoeff() + 1e-12);
  EXPECT_GE(filtered.minCoeff(), ramp.minCoeff() - 1e-12);
}

// Rings and ring medians against plain references: the sorted set of each vertex's edge
// neighbours, and the median of a sorted copy of the closed ring, on an icosphere (valence
// 5 and 6: even and odd windows) and an open grid (boundary rings), with many ties.
TEST(Internal, RingsAndRingMediansMatchPlainReferences) {
  const int n = 7;
  const std::vector<TriMesh> meshes{icosphere(2, 10.0), TriMesh{RowMatrixX3d::Zero(n * n, 3), grid_faces(n)}};
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> level(0, 3);  // four values: ties in every ring
  for (const TriMesh& m : meshes) {
    const int nv = m.num_vertices();
    std::vector<std::set<int>> expected(static_cast<std::size_t>(nv));
    for (int f = 0; f < m.num_faces(); ++f)
      for (int c = 0; c < 3; ++c) {
        expected[m.F(f, c)].insert(m.F(f, (c + 1) % 3));
        expected[m.F(f, (c + 1) % 3)].insert(m.F(f, c));
      }
    const VertexRings rings = build_vertex_rings(m.F, nv);
    ASSERT_EQ(rings.num_vertices(), nv);
    Eigen::VectorXd values(nv);
    for (int v = 0; v < nv; ++v) values[v] = 0.5 * level(rng);
    Eigen::VectorXd median = values;
    median_on_rings(rings, median, 1);
    for (int v = 0; v < nv; ++v) {
      const std::vector<int> ring(rings.neighbors.begin() + rings.offsets[v],
                                  rings.neighbors.begin() + rings.offsets[v + 1]);
      EXPECT_EQ(ring, std::vector<int>(expected[v].begin(), expected[v].end())) << v;
      std::vector<double> window{values[v]};
      for (int u : ring) window.push_back(values[u]);
      std::sort(window.begin(), window.end());
      const std::size_t mid = window.size() / 2;
      EXPECT_EQ(median[v], window.size() % 2 ? window[mid] : 0.5 * (window[mid - 1] + window[mid])) << v;
    }
  }
}

TEST(Snake, UndoSelfIntersectionsRestoresAnIntersectionFreeSurface) {
  const TriMesh m = icosphere(3, 10.0);
  const VertexRings rings = build_vertex_rings(m.F, m.num_vertices());
  // Push one vertex through the sphere and out of the far side: its faces cross others.
  RowMatrixX3d V = m.V;
  const int v = 5;
  V.row(v) = -1.3 * m.V.row(v);
  // A harmless displacement elsewhere, which must be kept.
  const int far = 100;
  ASSERT_GT((m.V.row(far) - m.V.row(v)).norm(), 8.0);
  V.row(far) *= 1.02;
  ASSERT_GT(count_self_intersections(TriMesh{V, m.F}), 0);
  const UndoOutcome undo = undo_self_intersections(V, m.V, m.F, rings);
  EXPECT_EQ(count_self_intersections(TriMesh{V, m.F}), 0);
  EXPECT_EQ(undo.remaining_pairs, 0);
  EXPECT_GT(undo.moved_vertices, 0);
  EXPECT_LT(undo.moved_vertices, m.num_vertices() / 4);
  EXPECT_EQ(V.row(far), (1.02 * m.V.row(far)).eval());
  // Nothing to undo on a clean surface.
  RowMatrixX3d clean = 1.1 * m.V;
  EXPECT_EQ(undo_self_intersections(clean, m.V, m.F, rings).moved_vertices, 0);
  EXPECT_EQ(clean, (1.1 * m.V).eval());
  // An intersection already in the safe positions stays, and is counted.
  RowMatrixX3d stuck = V;
  stuck.row(v) = -1.3 * m.V.row(v);
  const RowMatrixX3d unsafe = stuck;
  const UndoOutcome left = undo_self_intersections(stuck, unsafe, m.F, rings);
  EXPECT_EQ(left.remaining_pairs, count_self_intersections(TriMesh{unsafe, m.F}));
  EXPECT_GT(left.remaining_pairs, 0);
}

TEST(Model, MidpointFrameSynthesisFollowsASimilarity) {
  const TriMesh base = icosahedron(10.0);
  const SubdivisionConnectivity conn = subdivide_connectivity(base.F, base.num_vertices(), 3);
  RowMatrixX3d finest = icosphere(3, 10.0).V;
  for (int v = 0; v < finest.rows(); ++v) finest.row(v) *= 1.0 + 0.05 * std::cos(finest(v, 0));
  const SnakeModel model = midpoint_frame_model(conn, finest);
  for (int j = 0; j < 3; ++j) {
    EXPECT_LT((model.synthesize(j, model.levels[j]) - model.levels[j + 1]).cwiseAbs().maxCoeff(), 1e-10);
    Similarity s;
    s.rotation = rotation(70, {0, 1, 1});
    s.scale = 0.6;
    s.translation = {1, 2, 3};
    EXPECT_LT((model.synthesize(j, s.apply(model.levels[j])) - s.apply(model.levels[j + 1])).cwiseAbs().maxCoeff(),
              1e-9);
  }
}

TEST(Initialize, ThresholdClassesMediansFromALatticeSampleMatchTheWholeBox) {
  // A bright ball (2) on a dark background (-1) with noise of sigma 0.5: the two classes'
  // medians are the two intensities, from every voxel of the box or from a lattice sample.
  Volume image = make_grid({48, 48, 48}, {1, 1, 1}, {-23.5, -23.5, -23.5}, Eigen::Matrix3d::Identity());
  fill_object(
      image, [](const Eigen::Vector3d& p) { return p.norm() - 12.0; }, 2.0f, -1.0f, 1);
  add_noise(image, 0.5f, 5);
  const Volume smooth = downsample_by_two(image);
  const std::array<long, 3> lo{2, 2, 2}, hi{45, 45, 45};
  const ThresholdClasses all = threshold_classes(image, smooth, lo, hi, std::size_t{1} << 30);
  const ThresholdClasses some = threshold_classes(image, smooth, lo, hi, 4000);  // stride 6
  EXPECT_NEAR(all.upper_median, 2.0, 0.05);
  EXPECT_NEAR(all.lower_median, -1.0, 0.05);
  EXPECT_NEAR(some.upper_median, all.upper_median, 0.08);
  EXPECT_NEAR(some.lower_median, all.lower_median, 0.05);
  EXPECT_EQ(some.threshold, all.threshold);  // Otsu on the coarse image is not sampled
}

TEST(Initialize, MomentsRecoverAKnownSimilarity) {
  // Model: an ellipsoid with distinct axes. Image: the same ellipsoid under a known similarity.
  const Eigen::Vector3d axes(12, 8, 5);
  TriMesh model = icosphere(4, 1.0);
  for (int v = 0; v < model.num_vertices(); ++v) model.V.row(v) = model.V.row(v).cwiseProduct(axes.transpose());
  model.V.rowwise() += Eigen::Vector3d(32, 32, 32).transpose();
  Similarity truth;
  truth.rotation = rotation(12, {1, 2, 0.5});
  truth.scale = 1.08;
  truth.translation = Eigen::Vector3d(32, 32, 32) + Eigen::Vector3d(2.5, -1.5, 3.0) -
                      truth.scale * (truth.rotation * Eigen::Vector3d(32, 32, 32));
  Volume image = make_grid({64, 64, 64}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d inv = truth.rotation.transpose() / truth.scale;
  fill_object(
      image,
      [&](const Eigen::Vector3d& p) {
        const Eigen::Vector3d q = inv * (p - truth.translation) - Eigen::Vector3d(32, 32, 32);
        return q.cwiseQuotient(axes).squaredNorm() - 1.0;
      },
      1.0f, 0.0f, 2);
  const Similarity s = moments_alignment(image, model);
  EXPECT_NEAR(s.scale, truth.scale, 0.02);
  EXPECT_LT(Eigen::AngleAxisd(s.rotation * truth.rotation.transpose()).angle() * 180 / M_PI, 2.0);
  const Eigen::Vector3d c(32, 32, 32);
  EXPECT_LT((s.apply(c) - truth.apply(c)).norm(), 0.3);
}

TEST(Initialize, TargetFitRecoversASimilarity) {
  // The search reports the exact offset along the normal to a sphere of radius 10 at (1,2,3).
  const Eigen::Vector3d centre(1, 2, 3);
  const ExternalSearch search = [&](const RowMatrixX3d& V, const RowMatrixX3d& N) {
    SearchResult r;
    r.offsets.resize(V.rows());
    r.costs.setZero(V.rows());
    for (int v = 0; v < V.rows(); ++v) {
      // Solve |x + t n − c| = 10 for the root closest to 0.
      const Eigen::Vector3d d = V.row(v).transpose() - centre, n = N.row(v).transpose();
      const double b = d.dot(n), cc = d.squaredNorm() - 100.0, disc = std::max(0.0, b * b - cc);
      const double t1 = -b + std::sqrt(disc), t2 = -b - std::sqrt(disc);
      r.offsets[v] = std::abs(t1) < std::abs(t2) ? t1 : t2;
    }
    return r;
  };
  TriMesh m = icosphere(2, 7.0);
  RowMatrixX3d V = m.V;
  V.rowwise() += Eigen::Vector3d(2.0, 1.0, 4.0).transpose();
  TargetFitOptions o;
  o.iterations = 50;
  o.trim_fraction = 0;
  fit_similarity_to_targets(V, m.F, search, o);
  EXPECT_LT((V.colwise().mean() - centre.transpose()).norm(), 0.05);
  const Eigen::VectorXd radii = (V.rowwise() - centre.transpose()).rowwise().norm();
  EXPECT_NEAR(radii.mean(), 10.0, 0.05);
}

TEST(Forces, StepEdgeAndProfileFindAPlaneBoundary) {
  // Bright half-space x < 10.3 (blurred by partial volume); vertices on x = 8 with normal +x.
  Volume image = make_grid({32, 16, 16}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  fill_object(
      image, [](const Eigen::Vector3d& p) { return p.x() - 10.3; }, 1.0f, 0.0f, 5);
  const VolumeSampler s(image);
  RowMatrixX3d V(3, 3), N(3, 3);
  for (int v = 0; v < 3; ++v) {
    V.row(v) = Eigen::RowVector3d(8.0, 6.0 + v, 7.0 + 0.5 * v);
    N.row(v) = Eigen::RowVector3d(1, 0, 0);
  }
  NormalSearchOptions o;
  o.range_mm = 4;
  o.step_mm = 0.5;
  o.window_mm = 2;
  const SearchResult r = search_step_edges(s, V, N, RegionStats{1.0, 0.0}, o);
  for (int v = 0; v < 3; ++v) EXPECT_NEAR(r.offsets[v], 2.3, 0.15);
  // Profiles learned on the true boundary find it from 2.3 mm away.
  RowMatrixX3d on = V;
  on.col(0).setConstant(10.3);
  const Eigen::MatrixXf learned = sample_profiles(s, on, N, 5, 1.0);
  const SearchResult p = search_profiles(s, V, N, learned, 1.0, o);
  for (int v = 0; v < 3; ++v) EXPECT_NEAR(p.offsets[v], 2.3, 0.3);
  const RegionStats st = estimate_region_stats(s, on, N, 2.0, 0.5);
  EXPECT_NEAR(st.inside, 1.0, 0.2);
  EXPECT_NEAR(st.outside, 0.0, 0.2);
}

namespace {

/// A clean step along x (1 below the boundary, 0 above, 32 x 16 x 16 voxels of 1 mm) and two
/// vertices at x0 and x1 with normals +x, searched over +-range_mm in 0.5 mm steps.
struct PlaneStepCase {
  Volume image;
  RowMatrixX3d V{2, 3}, N{2, 3};
  NormalSearchOptions options;
};

PlaneStepCase plane_step_case(double boundary, double x0, double x1, double range_mm) {
  PlaneStepCase c;
  c.image = make_grid({32, 16, 16}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  fill_object(
      c.image, [boundary](const Eigen::Vector3d& p) { return p.x() - boundary; }, 1.0f, 0.0f, 5);
  c.V.row(0) = Eigen::RowVector3d(x0, 6.0, 7.0);
  c.V.row(1) = Eigen::RowVector3d(x1, 8.0, 8.0);
  c.N.row(0) = c.N.row(1) = Eigen::RowVector3d(1, 0, 0);
  c.options.range_mm = range_mm;
  c.options.step_mm = 0.5;
  c.options.window_mm = 2;
  return c;
}

}  // namespace

TEST(Forces, EachVertexFindsItsOwnBoundaryWhateverTheVertexBeforeIt) {
  // Vertex 0 sits on the boundary (its best candidate is the centre, cost ~0); vertex 1 sits
  // 2 mm outside it, so its boundary is inward. Its answer must not depend on vertex 0's
  // costs (the minimum was once taken against the previous vertex's centre cost, which hid
  // every inward candidate of vertex 1 behind vertex 0's near-perfect match).
  const PlaneStepCase c = plane_step_case(10.3, 10.3, 12.3, 4);
  const VolumeSampler s(c.image);
  const RowMatrixX3d &V = c.V, &N = c.N;
  const NormalSearchOptions o = c.options;
  const SearchResult r = search_step_edges(s, V, N, RegionStats{1.0, 0.0}, o);
  EXPECT_NEAR(r.offsets[0], 0.0, 0.15);
  EXPECT_NEAR(r.offsets[1], -2.0, 0.15);
  RowMatrixX3d on = V;
  on.col(0).setConstant(10.3);
  const Eigen::MatrixXf learned = sample_profiles(s, on, N, 5, 1.0);
  const SearchResult p = search_profiles(s, V, N, learned, 1.0, o);
  EXPECT_NEAR(p.offsets[0], 0.0, 0.3);
  EXPECT_NEAR(p.offsets[1], -2.0, 0.3);
  // The same vertex alone gives the same answer.
  const SearchResult alone = search_profiles(s, V.bottomRows(1), N.bottomRows(1), learned.bottomRows(1), 1.0, o);
  EXPECT_DOUBLE_EQ(alone.offsets[0], p.offsets[1]);
}

TEST(Forces, MinGainKeepsAVertexInPlaceUnlessAMoveIsClearlyBetterOnEitherSide) {
  // A clean step at x = 10.5 (between voxels, so the image is antisymmetric about it);
  // vertex 0 sits 1 mm outside it, vertex 1 sits 1 mm inside it. By symmetry their best moves gain the
  // same, so any min_gain moves both or neither.
  const PlaneStepCase c = plane_step_case(10.5, 11.5, 9.5, 3);
  const VolumeSampler s(c.image);
  const RowMatrixX3d &V = c.V, &N = c.N;
  NormalSearchOptions o = c.options;
  o.distance_penalty = 0;
  const SearchResult free_move = search_step_edges(s, V, N, RegionStats{1.0, 0.0}, o);
  EXPECT_NEAR(free_move.offsets[0], -1.0, 0.15);
  EXPECT_NEAR(free_move.offsets[1], 1.0, 0.15);
  // The gain of the move: the centre's cost (seen from a vertex there) minus the best cost.
  RowMatrixX3d centre_only = V;
  NormalSearchOptions stay = o;
  stay.range_mm = 0;  // a single candidate: the centre
  const SearchResult at_centre = search_step_edges(s, centre_only, N, RegionStats{1.0, 0.0}, stay);
  const double gain0 = at_centre.costs[0] - free_move.costs[0];
  const double gain1 = at_centre.costs[1] - free_move.costs[1];
  ASSERT_GT(gain0, 0.05);
  EXPECT_NEAR(gain0, gain1, 1e-6);
  // The distance penalty adds penalty·(t/range)² to a candidate at offset t, whichever side.
  NormalSearchOptions penalized = o;
  penalized.distance_penalty = 0.02;
  const SearchResult pen = search_step_edges(s, V, N, RegionStats{1.0, 0.0}, penalized);
  for (int v = 0; v < 2; ++v) {
    // Same candidate; the sub-step refinement is pulled slightly towards staying.
    EXPECT_LT(std::abs(pen.offsets[v]), std::abs(free_move.offsets[v]));
    EXPECT_GT(pen.offsets[v] * free_move.offsets[v], 0.0);
    EXPECT_NEAR(pen.offsets[v], free_move.offsets[v], 0.5 * o.step_mm);
    EXPECT_NEAR(pen.costs[v] - free_move.costs[v], 0.02 * (1.0 / 3.0) * (1.0 / 3.0), 1e-9);
  }
  for (const double f : {0.5, 0.9, 1.1, 2.0}) {
    o.min_gain = f * gain0;
    const SearchResult r = search_step_edges(s, V, N, RegionStats{1.0, 0.0}, o);
    if (f < 1) {
      EXPECT_NEAR(r.offsets[0], -1.0, 0.15) << f;
      EXPECT_NEAR(r.offsets[1], 1.0, 0.15) << f;
    } else {  // stays: only the sub-step refinement around the centre, never a whole step
      EXPECT_LE(std::abs(r.offsets[0]), 0.5 * o.step_mm) << f;
      EXPECT_LE(std::abs(r.offsets[1]), 0.5 * o.step_mm) << f;
      EXPECT_NEAR(r.offsets[0], -r.offsets[1], 1e-9) << f;
    }
  }
}

TEST(Forces, RingSharingAveragesNoiseButKeepsASharpMatchOfItsOwn) {
  // Vertices on a 15 × 15 grid (1 mm apart) in the plane x = 9, normals +x.
  const int n = 15;
  const VertexRings rings = build_vertex_rings(grid_faces(n), n * n);
  RowMatrixX3d V(n * n, 3), N(n * n, 3);
  for (int y = 0; y < n; ++y)
    for (int z = 0; z < n; ++z) {
      V.row(y * n + z) = Eigen::RowVector3d(9.0, 1.0 + y, 1.0 + z);
      N.row(y * n + z) = Eigen::RowVector3d(1, 0, 0);
    }
  NormalSearchOptions alone;
  alone.range_mm = 4;
  alone.step_mm = 0.5;
  alone.window_mm = 2;
  alone.max_cost = 10;  // keep every match, to compare the errors
  NormalSearchOptions shared = alone;
  shared.rings = &rings;
  shared.ring_weight = 0.85;
  const auto interior = [n](int v) { return v / n > 0 && v / n < n - 1 && v % n > 0 && v % n < n - 1; };

  // 1. A plane boundary at x = 10.3 in strong noise (contrast 1, sigma 0.7): sharing the
  //    ring's evidence brings the offsets closer to the true 1.3 mm.
  const auto clean_plane_image = [] {
    Volume v = make_grid({24, 18, 18}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
    fill_object(
        v, [](const Eigen::Vector3d& p) { return p.x() - 10.3; }, 1.0f, 0.0f, 5);
    return v;
  };
  Volume noisy = clean_plane_image();
  add_noise(noisy, 0.7f, 7);
  const VolumeSampler s(noisy);
  const auto rms_error = [&](const SearchResult& r) {
    double sum = 0;
    int count = 0;
    for (int v = 0; v < n * n; ++v)
      if (interior(v)) {
        sum += (r.offsets[v] - 1.3) * (r.offsets[v] - 1.3);
        ++count;
      }
    return std::sqrt(sum / count);
  };
  const double error_alone = rms_error(search_step_edges(s, V, N, RegionStats{1.0, 0.0}, alone));
  const double error_shared = rms_error(search_step_edges(s, V, N, RegionStats{1.0, 0.0}, shared));
  EXPECT_GT(error_alone, 0.3);
  EXPECT_LT(error_shared, 0.6 * error_alone) << error_alone;
  // The cost-scaled weight shares too where the matches are poor, as they are in this noise.
  NormalSearchOptions scaled = shared;
  scaled.ring_full_weight_cost = 0.2;
  EXPECT_LT(rms_error(search_step_edges(s, V, N, RegionStats{1.0, 0.0}, scaled)), 0.8 * error_alone);

  // 2. A clean boundary with a 2 mm step at y = 7.5 (x = 10.3 below, 12.3 above): every
  //    vertex has a sharp match of its own. A fixed weight drags the rows next to the step
  //    towards the other side; the cost-scaled weight keeps each vertex on its own boundary.
  Volume clean = make_grid({24, 18, 18}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  fill_object(
      clean, [](const Eigen::Vector3d& p) { return p.x() - (p.y() < 7.5 ? 10.3 : 12.3); }, 1.0f, 0.0f, 5);
  const VolumeSampler c(clean);
  const SearchResult own = search_step_edges(c, V, N, RegionStats{1.0, 0.0}, alone);
  const SearchResult fixed = search_step_edges(c, V, N, RegionStats{1.0, 0.0}, shared);
  const SearchResult kept = search_step_edges(c, V, N, RegionStats{1.0, 0.0}, scaled);
  double worst_fixed = 0, worst_kept = 0;
  for (int v = 0; v < n * n; ++v) {
    if (!interior(v)) continue;
    const double truth = V(v, 1) < 7.5 ? 1.3 : 3.3;
    EXPECT_NEAR(own.offsets[v], truth, 0.15) << v;
    worst_fixed = std::max(worst_fixed, std::abs(fixed.offsets[v] - truth));
    worst_kept = std::max(worst_kept, std::abs(kept.offsets[v] - truth));
  }
  EXPECT_GT(worst_fixed, 0.25);  // measured 0.32
  EXPECT_LT(worst_kept, 0.12);   // measured 0.08

  // 3. The profile search shares the same way: profiles learned on the clean boundary,
  //    matched in the noisy image.
  RowMatrixX3d on = V;
  on.col(0).setConstant(10.3);
  const Eigen::MatrixXf learned = sample_profiles(VolumeSampler(clean_plane_image()), on, N, 5, 1.0);
  const double profile_alone = rms_error(search_profiles(s, V, N, learned, 1.0, alone));
  const double profile_shared = rms_error(search_profiles(s, V, N, learned, 1.0, scaled));
  EXPECT_GT(profile_alone, 0.3);
  EXPECT_LT(profile_shared, 0.8 * profile_alone) << profile_alone;
}

TEST(Appearance, ProfileStepResidualTellsACleanStepFromAWrappedObject) {
  // A sphere of radius 10 mm (bright, 1) on a dark background (0), and the same sphere
  // wrapped in a 2 mm shell of intermediate intensity (0.5), with noise of sigma 0.2 (SNR 5).
  // The profiles learned on the sphere's subdivided icosahedron must tell them apart.
  const auto image_of = [](double shell_mm, std::uint32_t seed) {
    Volume v = make_grid({40, 40, 40}, {1, 1, 1}, {-19.5, -19.5, -19.5}, Eigen::Matrix3d::Identity());
    fill_object(
        v, [](const Eigen::Vector3d& p) { return p.norm() - 10.0; }, 1.0f, 0.0f);
    if (shell_mm > 0) {
      Volume shell = v;
      fill_object(
          shell, [shell_mm](const Eigen::Vector3d& p) { return p.norm() - 10.0 - shell_mm; }, 0.5f, 0.0f);
      for (std::size_t i = 0; i < v.data.size(); ++i) v.data[i] = std::max(v.data[i], shell.data[i]);
    }
    add_noise(v, 0.2f, seed);
    return v;
  };
  const auto spheres = icosphere_levels(3, 10.0);
  const std::vector<RowMatrixX3d>& levels = spheres.first;
  const std::vector<RowMatrixX3i>& faces = spheres.second;
  const auto residual = [&](const Volume& image) {
    const Appearance a = build_appearance(build_pyramid(image, 3), levels, faces);
    return profile_step_residual(a, faces);
  };
  const double clean = residual(image_of(0, 1)), wrapped = residual(image_of(2.0, 2));
  // Measured 0.07 and 0.28, on either side of segment()'s threshold with a margin.
  const double threshold = SegmentOptions{}.clean_step_max_residual;
  EXPECT_LT(clean, 0.6 * threshold);
  EXPECT_GT(wrapped, 1.2 * threshold);
  // Levels and faces that do not match, or no contrast, give no verdict.
  const Appearance a = build_appearance(build_pyramid(image_of(0, 3), 3), levels, faces);
  EXPECT_TRUE(std::isinf(profile_step_residual(a, {faces[0]})));
  Appearance flat = a;
  flat.region.outside = flat.region.inside;
  EXPECT_TRUE(std::isinf(profile_step_residual(flat, faces)));
}

// A model surface 0.3 mm inside the image's edge (as a label's rounding leaves it): centred on
// the edges, the profiles of the full-resolution level move out by 0.3 mm and their centre
// sample reads the midpoint; centred on the labels, they stay at the vertices. A shift beyond
// half a voxel is clamped, and `automatic` takes the labels when the profiles are no step.
TEST(Appearance, ProfilesCentredOnTheImagesEdgesUndoTheLabelsRounding) {
  const auto sphere_image = [](double radius) {
    Volume v = make_grid({40, 40, 40}, {1, 1, 1}, {-19.5, -19.5, -19.5}, Eigen::Matrix3d::Identity());
    fill_object(
        v, [radius](const Eigen::Vector3d& p) { return p.norm() - radius; }, 1.0f, 0.0f, 7);
    return v;
  };
  const auto spheres = icosphere_levels(3, 10.0);
  const std::vector<RowMatrixX3d>& levels = spheres.first;
  const std::vector<RowMatrixX3i>& faces = spheres.second;
  const int finest = 2, half = AppearanceOptions{}.half_length;
  const auto learn = [&](const Volume& image, ProfileAlignment alignment, ProfileAlignmentReport& report,
                         double clean_edge_max_residual = AppearanceOptions{}.clean_edge_max_residual) {
    AppearanceOptions o;
    o.alignment = alignment;
    o.clean_edge_max_residual = clean_edge_max_residual;
    return build_appearance(build_pyramid(image, 3), levels, faces, o, &report);
  };
  const Volume image = sphere_image(10.3);
  ProfileAlignmentReport edges, labels, automatic;
  const Appearance on_edges = learn(image, ProfileAlignment::edges, edges);
  const Appearance on_labels = learn(image, ProfileAlignment::labels, labels);
  const Appearance chosen = learn(image, ProfileAlignment::automatic, automatic);
  ASSERT_TRUE(edges.to_edges);
  EXPECT_GE(edges.levels_aligned, 1);
  EXPECT_NEAR(edges.mean_shift_mm, 0.3, 0.08);
  EXPECT_NEAR(edges.mean_abs_shift_mm, 0.3, 0.08);
  EXPECT_FALSE(labels.to_edges);
  EXPECT_EQ(labels.levels_aligned, 0);
  EXPECT_EQ(labels.mean_abs_shift_mm, 0.0);
  EXPECT_TRUE(automatic.to_edges);  // a clean step
  EXPECT_LT(automatic.step_residual, AppearanceOptions{}.clean_edge_max_residual);
  EXPECT_EQ(chosen.levels[finest].profiles, on_edges.levels[finest].profiles);
  // Each level records where its profiles sit: exactly the aligned ones on the edges.
  int flagged = 0;
  for (std::size_t j = 0; j < on_edges.levels.size(); ++j) {
    flagged += on_edges.levels[j].centre == ProfileCentre::edges ? 1 : 0;
    EXPECT_EQ(on_labels.levels[j].centre, ProfileCentre::labels) << j;
  }
  EXPECT_EQ(flagged, edges.levels_aligned);
  EXPECT_EQ(on_edges.levels[finest].centre, ProfileCentre::edges);
  // The centre sample: the midpoint 0.5 on the edge, about 0.8 at the label's surface.
  EXPECT_NEAR(on_edges.levels[finest].profiles.col(half).mean(), 0.5, 0.06);
  EXPECT_GT(on_labels.levels[finest].profiles.col(half).mean(), 0.7);
  RowMatrixX3d N;
  vertex_normals(levels[finest], faces[finest], N);
  EXPECT_EQ(on_labels.levels[finest].profiles,
            sample_profiles(VolumeSampler(image), levels[finest], N, half, on_labels.levels[finest].spacing_mm));

  // 1.5 mm out: every vertex is clamped at half its voxel step along the normal, from 0.29 mm
  // (a diagonal normal) to 0.5 mm (an axis).
  ProfileAlignmentReport far;
  learn(sphere_image(11.5), ProfileAlignment::edges, far);
  ASSERT_EQ(far.levels_aligned, 1);
  double expected = 0;
  for (int v = 0; v < N.rows(); ++v) expected += 0.5 * N.row(v).cwiseAbs().maxCoeff() / N.rows();
  EXPECT_NEAR(far.mean_abs_shift_mm, expected, 1e-9);
  EXPECT_NEAR(far.mean_shift_mm, expected, 1e-9);

  // The same clean step above a stricter threshold: automatic keeps the labels.
  ProfileAlignmentReport strict;
  learn(image, ProfileAlignment::automatic, strict, 0.5 * automatic.step_residual);
  EXPECT_FALSE(strict.to_edges);
  EXPECT_EQ(strict.step_residual, automatic.step_residual);

  ProfileAlignmentReport no_step;
  learn(sphere_image(14.0), ProfileAlignment::automatic, no_step);  // bright on both sides of the surface
  EXPECT_FALSE(no_step.to_edges);
  EXPECT_EQ(no_step.mean_abs_shift_mm, 0.0);
}

TEST(Appearance, SerializationRoundTripsAndRejectsDamage) {
  Appearance a;
  a.half_length = 2;
  a.region = {0.8, 0.1};
  a.inside_spread = 0.05;
  a.levels.resize(2);
  a.levels[0].spacing_mm = 2;
  a.levels[0].profiles = Eigen::MatrixXf::Random(12, 5);
  a.levels[1].spacing_mm = 1;
  a.levels[1].profiles = Eigen::MatrixXf::Random(42, 5);
  a.levels[1].centre = ProfileCentre::edges;
  const auto bytes = serialize_appearance(a);
  const Appearance b = deserialize_appearance(bytes);
  EXPECT_EQ(b.half_length, 2);
  EXPECT_DOUBLE_EQ(b.region.inside, 0.8);
  ASSERT_EQ(b.levels.size(), 2u);
  EXPECT_EQ(b.levels[1].profiles, a.levels[1].profiles);
  EXPECT_EQ(b.levels[0].centre, ProfileCentre::labels);
  EXPECT_EQ(b.levels[1].centre, ProfileCentre::edges);
  // Version 01, as the old writer wrote it (the fuzz corpus's seed, after its selector byte):
  // the same layout without the flag byte; the centring reads as unrecorded. Its version 02
  // twin (a flag byte after each spacing, the last level on the edges) reads the same profiles.
  {
    const auto seed = [](const char* name) {
      const auto all =
          test::read_all(std::filesystem::path(MRSNAKE_SOURCE_DIR) / "tests/fuzz/corpus/model_sections" / name);
      return std::vector<std::uint8_t>(all.begin() + 1, all.end());
    };
    const Appearance old = deserialize_appearance(seed("appearance_two_levels"));
    const Appearance current = deserialize_appearance(seed("appearance_two_levels_v02"));
    ASSERT_EQ(old.levels.size(), 2u);
    ASSERT_EQ(current.levels.size(), 2u);
    for (int j = 0; j < 2; ++j) {
      EXPECT_EQ(old.levels[j].centre, ProfileCentre::unrecorded) << j;
      EXPECT_EQ(old.levels[j].profiles, current.levels[j].profiles) << j;
    }
    EXPECT_EQ(current.levels[0].centre, ProfileCentre::labels);
    EXPECT_EQ(current.levels[1].centre, ProfileCentre::edges);
    nlohmann::json summary = old;
    EXPECT_EQ(summary["profiles_centred_on"], nlohmann::json({"unrecorded", "unrecorded"}));
    summary = current;
    EXPECT_EQ(summary["profiles_centred_on"], nlohmann::json({"labels", "edges"}));
  }
  auto flag = bytes;
  flag[8 + 2 * 4 + 5 * 8 + 8] = 2;  // level 0's flag: neither 0 nor 1
  EXPECT_THROW(deserialize_appearance(flag), InputError);
  auto cut = bytes;
  cut.resize(cut.size() - 3);
  EXPECT_THROW(deserialize_appearance(cut), InputError);
  auto bad = bytes;
  bad[0] = 'X';
  EXPECT_THROW(deserialize_appearance(bad), InputError);
  // A non-finite profile sample or statistic is a defect, not a value the snake should use.
  Appearance nan_profile = a;
  nan_profile.levels[1].profiles(3, 2) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(deserialize_appearance(serialize_appearance(nan_profile)), InputError);
  Appearance infinite_spread = a;
  infinite_spread.outside_spread = std::numeric_limits<double>::infinity();
  EXPECT_THROW(deserialize_appearance(serialize_appearance(infinite_spread)), InputError);
}

TEST(Snake, AdversarialTargetsNeverFlipAFace) {
  // Targets alternate ±5 mm along the normals from vertex to vertex (a worst case a noisy
  // search can produce): the steps that would flip a face are halved or dropped.
  const TriMesh m = icosphere(3, 10.0);
  SnakeOptions o;
  o.external_weight = 1.0;
  o.offset_smoothing = 0;
  o.max_step_fraction = 1.0;
  o.prior_weight = 0;
  o.tangential_weight = 0;
  o.thin_plate_weight = 0;
  o.max_iterations = 20;
  const DeformableSurface snake(m.F, m.V, o);
  const ExternalSearch search = [](const RowMatrixX3d& V, const RowMatrixX3d&) {
    SearchResult r;
    r.offsets.resize(V.rows());
    r.costs.setZero(V.rows());
    for (int v = 0; v < V.rows(); ++v) r.offsets[v] = (v % 2 ? 5.0 : -5.0);
    return r;
  };
  RowMatrixX3d V = m.V;
  const SnakeLevelReport rep = snake.run(V, search, 0.5);
  EXPECT_GT(rep.rejected_steps, 0);
  EXPECT_EQ(rep.flipped_faces, 0);
  RowMatrixX3d N0, N1;
  face_normals(m.V, m.F, N0);
  face_normals(V, m.F, N1);
  for (int f = 0; f < m.num_faces(); ++f) EXPECT_GT(N0.row(f).dot(N1.row(f)), 0.0) << f;
  // The trust region holds every vertex within its radius of the start.
  RowMatrixX3d W = m.V;
  snake.run(W, search, 0.5, 1.5);
  EXPECT_LE((W - m.V).rowwise().norm().maxCoeff(), 1.5 + 1e-9);
}

TEST(Snake, ConvergesOntoASphereInAVolume) {
  Volume image = make_grid({48, 48, 48}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity());
  const Eigen::Vector3d c(24.2, 23.7, 24.4);
  fill_object(
      image, [&](const Eigen::Vector3d& p) { return (p - c).norm() - 14.0; }, 1.0f, 0.0f, 3);
  TriMesh m = icosphere(3, 11.0);
  m.V.rowwise() += c.transpose();
  const VolumeSampler s(image);
  NormalSearchOptions so;
  so.range_mm = 4;
  so.step_mm = 0.5;
  so.window_mm = 2;
  const ExternalSearch search = [&](const RowMatrixX3d& V, const RowMatrixX3d& N) {
    return search_step_edges(s, V, N, RegionStats{1.0, 0.0}, so);
  };
  const DeformableSurface snake(m.F, m.V, SnakeOptions{});
  RowMatrixX3d V = m.V;
  const SnakeLevelReport rep = snake.run(V, search, so.step_mm);
  EXPECT_TRUE(rep.converged);
  const Eigen::VectorXd radii = (V.rowwise() - c.transpose()).rowwise().norm();
  EXPECT_NEAR(radii.mean(), 14.0, 0.15);  // the prior is scale invariant: no shrinkage
  EXPECT_LT(radii.maxCoeff() - radii.minCoeff(), 0.6);
  // One history entry per iteration, the last one the report's final figures; the offsets
  // shrink from 3 mm (11 to 14) towards the edge.
  ASSERT_FALSE(rep.history.empty());
  EXPECT_LE(static_cast<int>(rep.history.size()), rep.iterations + 1);
  EXPECT_GE(static_cast<int>(rep.history.size()), rep.iterations);
  EXPECT_DOUBLE_EQ(rep.history.back().energy, rep.energy);
  EXPECT_DOUBLE_EQ(rep.history.back().mean_abs_offset_mm, rep.mean_abs_offset_mm);
  EXPECT_GT(rep.history.front().mean_abs_offset_mm, 2.0);
  EXPECT_LT(rep.history.back().mean_abs_offset_mm, 0.5 * rep.history.front().mean_abs_offset_mm);
}
