#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/parallel.h"
#include "mesh/primitives.h"

using namespace mrsnake;

namespace {

TriMesh unit_right_triangle() {
  TriMesh m;
  m.V.resize(3, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  return m;
}

TriMesh merged(const TriMesh& a, const TriMesh& b) {
  TriMesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + a.num_vertices()).matrix();
  return m;
}

/// Sag of a sphere mesh whose vertices lie on radius R: R minus the smallest distance from
/// the centre to any point of a face (for these near-equilateral faces, the foot of the
/// perpendicular from the centre lies inside the face, so it is the plane distance).
double max_sag(const TriMesh& m, double radius) {
  double sag = 0;
  for (int f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    sag = std::max(sag, radius - std::abs(n.dot(a)));
  }
  return sag;
}

}  // namespace

TEST(SurfaceLocator, ClosestPointOnKnownTriangle) {
  const SurfaceLocator locator(unit_right_triangle());
  // Above the interior: the foot of the perpendicular.
  auto hit = locator.closest({0.2, 0.3, 5.0});
  EXPECT_EQ(hit.face, 0);
  EXPECT_NEAR((hit.point - Eigen::Vector3d(0.2, 0.3, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(hit.distance, 5.0, 1e-12);
  EXPECT_NEAR((hit.barycentric - Eigen::Vector3d(0.5, 0.2, 0.3)).norm(), 0.0, 1e-12);
  // Beyond the hypotenuse x + y = 1: its midpoint.
  hit = locator.closest({2.0, 2.0, 1.0});
  EXPECT_NEAR((hit.point - Eigen::Vector3d(0.5, 0.5, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(hit.distance, std::sqrt(1.5 * 1.5 * 2 + 1.0), 1e-12);
  EXPECT_NEAR((hit.barycentric - Eigen::Vector3d(0.0, 0.5, 0.5)).norm(), 0.0, 1e-12);
  // Behind the right-angle corner: the corner itself.
  hit = locator.closest({-1.0, -2.0, 0.0});
  EXPECT_NEAR(hit.point.norm(), 0.0, 1e-12);
  EXPECT_NEAR(hit.distance, std::sqrt(5.0), 1e-12);
  EXPECT_NEAR((hit.barycentric - Eigen::Vector3d(1, 0, 0)).norm(), 0.0, 1e-12);

  RowMatrixX3d P(2, 3);
  P << 0.2, 0.3, -2.0, 1.0, 0.0, 3.0;
  const Eigen::VectorXd d = locator.distances(P);
  EXPECT_NEAR(d[0], 2.0, 1e-12);
  EXPECT_NEAR(d[1], 3.0, 1e-12);
}

TEST(SurfaceLocator, FindsTheRightFaceOnASphere) {
  const TriMesh sphere = icosphere(3, 2.0);
  const SurfaceLocator locator(sphere);
  for (int f = 0; f < sphere.num_faces(); f += 37) {
    const Eigen::Vector3d centroid =
        (sphere.V.row(sphere.F(f, 0)) + sphere.V.row(sphere.F(f, 1)) + sphere.V.row(sphere.F(f, 2))) / 3.0;
    // Pushed outward along the radius, the centroid still projects onto its own face.
    const auto hit = locator.closest(centroid * 1.05);
    EXPECT_EQ(hit.face, f);
    EXPECT_NEAR((hit.barycentric - Eigen::Vector3d::Constant(1.0 / 3.0)).norm(), 0.0, 0.02);
    const Eigen::Vector3d rebuilt = hit.barycentric[0] * sphere.V.row(sphere.F(f, 0)).transpose() +
                                    hit.barycentric[1] * sphere.V.row(sphere.F(f, 1)).transpose() +
                                    hit.barycentric[2] * sphere.V.row(sphere.F(f, 2)).transpose();
    EXPECT_NEAR((rebuilt - hit.point).norm(), 0.0, 1e-12);
  }
}

TEST(SurfaceLocator, ParallelDistancesEqualTheClosestPointOneByOne) {
  // distances() splits the points over threads: every point must get its own distance.
  const TriMesh sphere = icosphere(3, 2.0);
  const SurfaceLocator locator(sphere);
  RowMatrixX3d P(5000, 3);
  for (int i = 0; i < P.rows(); ++i)
    P.row(i) << std::sin(0.37 * i) * (1 + 0.001 * i), std::cos(0.11 * i) * 1.5, 0.0004 * i - 1;
  const Eigen::VectorXd d = locator.distances(P);
  ASSERT_EQ(d.size(), P.rows());
  for (int i = 0; i < P.rows(); ++i) ASSERT_NEAR(d[i], locator.closest(P.row(i).transpose()).distance, 1e-12) << i;
}

TEST(SurfaceDistance, PrebuiltReferenceLocatorGivesTheSameNumbers) {
  const TriMesh a = icosphere(3, 1.0);
  TriMesh b = icosphere(2, 1.1);
  b.V.col(0) *= 1.2;
  const SurfaceLocator locator(b);
  const SurfaceDistance fresh = surface_distance(a, b), reused = surface_distance(a, b, locator);
  EXPECT_EQ(fresh.rms_mm, reused.rms_mm);
  EXPECT_EQ(fresh.hausdorff_mm, reused.hausdorff_mm);
  EXPECT_EQ(fresh.mean_mm, reused.mean_mm);
  EXPECT_GT(fresh.hausdorff_mm, 0.1);
}

TEST(ParallelRanges, CoversEveryIndexOnceAndRethrows) {
  for (std::size_t n : {0u, 1u, 7u, 1000u, 100003u}) {
    std::vector<std::atomic<int>> hits(n);
    parallel_ranges(
        n,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t i = begin; i < end; ++i) ++hits[i];
        },
        16);
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << "n " << n << " index " << i;
  }
  EXPECT_THROW(parallel_ranges(
                   100000,
                   [](std::size_t, std::size_t end) {
                     if (end == 100000) throw std::runtime_error("the last range's worker");
                   },
                   16),
               std::runtime_error);
}

TEST(ParallelRanges, ARangeWhoseThreadCannotStartRunsOnTheCaller) {
  const std::size_t n = 1000, parts = 4;
  std::vector<std::atomic<int>> hits(n);
  auto count = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) ++hits[i];
  };
  int starts = 0;
  // The first worker starts, every later one fails as std::thread does without resources.
  detail::parallel_ranges_with(n, parts, count, [&](auto&& job) {
    if (++starts > 1) throw std::system_error(std::make_error_code(std::errc::resource_unavailable_try_again));
    return std::thread(std::move(job));
  });
  EXPECT_EQ(starts, 2);
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << "index " << i;
}

// Both jobs run, whichever throws; a()'s exception wins, and b()'s is not lost when a() succeeds.
TEST(ParallelRanges, RunBothRunsBothAndRethrowsAFirst) {
  std::atomic<int> ran{0};
  run_both_in_parallel([&] { ++ran; }, [&] { ++ran; });
  EXPECT_EQ(ran.load(), 2);
  ran = 0;
  try {
    run_both_in_parallel(
        [&] {
          ++ran;
          throw std::runtime_error("a");
        },
        [&] {
          ++ran;
          throw std::logic_error("b");
        });
    ADD_FAILURE() << "nothing thrown";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "a");
  }
  EXPECT_EQ(ran.load(), 2);
  EXPECT_THROW(run_both_in_parallel([] {}, [] { throw std::logic_error("b"); }), std::logic_error);
}

// Counts one thread at work per core but `spare` (the test's own thread is one).
std::vector<std::unique_ptr<ThreadAtWork>> fill_cores_but(int spare) {
  std::vector<std::unique_ptr<ThreadAtWork>> fill;
  for (int i = 1 + spare; i < static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); ++i)
    fill.push_back(std::make_unique<ThreadAtWork>());
  return fill;
}

// A helper starts a thread only on an idle core: where the cores are at work (the remesher's
// two domains side by side), a nested sweep runs its parts one after the other.
TEST(ParallelRanges, ThreadsStartOnlyOnIdleCores) {
  const std::thread::id caller = std::this_thread::get_id();
  {
    const auto fill = fill_cores_but(0);
    std::thread::id ran_b;
    run_both_in_parallel([] {}, [&] { ran_b = std::this_thread::get_id(); });
    EXPECT_EQ(ran_b, caller);
    std::atomic<int> elsewhere{0};
    parallel_ranges(
        64, [&](std::size_t, std::size_t) { elsewhere += std::this_thread::get_id() != caller; }, 1);
    EXPECT_EQ(elsewhere.load(), 0);
    EXPECT_FALSE(claim_idle_core());
  }
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one core: every job runs on the calling thread";
  std::thread::id ran_b;
  run_both_in_parallel([] {}, [&] { ran_b = std::this_thread::get_id(); });
  EXPECT_NE(ran_b, caller);
}

// A thread that waits for another to end leaves its core: with a() done at once, the caller
// waits for b(), and a job nested in b() finds that core idle.
TEST(ParallelRanges, AThreadWaitingForAnotherLeavesItsCore) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one core: b() runs on the calling thread";
  const auto fill = fill_cores_but(1);  // the caller and b() take the last two
  bool found_idle = false;
  run_both_in_parallel([] {},
                       [&] {
                         for (int tries = 0; tries < 5000 && !found_idle; ++tries)
                           if (claim_idle_core()) {
                             found_idle = true;
                             release_core();
                           } else {
                             std::this_thread::sleep_for(std::chrono::milliseconds(1));
                           }
                       });
  EXPECT_TRUE(found_idle);
  EXPECT_TRUE(claim_idle_core());  // every claim was released
  release_core();
}

TEST(SurfaceDistance, MeshAgainstItselfIsZero) {
  const TriMesh sphere = icosphere(3, 4.0);
  const SurfaceDistance d = surface_distance(sphere, sphere);
  EXPECT_LT(d.hausdorff_mm, 1e-9);
  EXPECT_LT(d.rms_mm, 1e-9);
  EXPECT_GT(d.reference_diagonal_mm, 8.0);
}

TEST(SurfaceDistance, ConcentricSpheresAreTheRadiusDifferenceApart) {
  // Vertices of both meshes lie on spheres of radius R = 10 and 1.01·R; faces are chords
  // that dip at most s (sag, ≈ 0.002 mm at level 5) inside their sphere, 1.01·s for the
  // larger. A point of the small mesh has |x| ∈ [R − s, R], so its distance to the large
  // mesh (which lies in the shell [1.01R − 1.01s, 1.01R]) is in [0.1 − 1.01s, 0.1 + s];
  // the same bound holds the other way. So mean, RMS and Hausdorff all lie in
  // [0.1 − 1.01s, 0.1 + 1.01s] mm.
  const double R = 10.0;
  const TriMesh small = icosphere(5, R);
  TriMesh large = small;
  large.V *= 1.01;
  const double s = max_sag(small, R);
  EXPECT_LT(s, 0.005);
  const double lo = 0.1 - 1.01 * s - 1e-12, hi = 0.1 + 1.01 * s + 1e-12;
  DistanceOptions options;
  options.samples_per_face = 2;
  const SurfaceDistance d = surface_distance(small, large, options);
  EXPECT_GE(d.mean_mm, lo);
  EXPECT_LE(d.mean_mm, hi);
  EXPECT_GE(d.rms_mm, lo);
  EXPECT_LE(d.rms_mm, hi);
  EXPECT_GE(d.hausdorff_mm, lo);
  EXPECT_LE(d.hausdorff_mm, hi);
  EXPECT_NEAR(d.hausdorff_mm, 0.1, 0.005);
  EXPECT_NEAR(d.reference_diagonal_mm, bounding_box_diagonal(large.V), 1e-12);
  EXPECT_NEAR(d.rms_pct, 100.0 * d.rms_mm / d.reference_diagonal_mm, 1e-12);
  EXPECT_NEAR(d.hausdorff_pct, 100.0 * d.hausdorff_mm / d.reference_diagonal_mm, 1e-12);
}

TEST(SurfaceDistance, DeterministicFromTheSeedAndSensitiveToAFarVertex) {
  const TriMesh a = icosphere(2, 1.0);
  TriMesh b = icosphere(2, 1.0);
  b.V.row(0) *= 1.5;  // one vertex pulled out by 0.5
  DistanceOptions options;
  options.seed = 7;
  const SurfaceDistance d1 = surface_distance(b, a, options), d2 = surface_distance(b, a, options);
  EXPECT_EQ(d1.rms_mm, d2.rms_mm);
  EXPECT_EQ(d1.hausdorff_mm, d2.hausdorff_mm);
  // The pulled vertex is 0.5 from the unit sphere and farther than 0.45 from any flat face of a.
  EXPECT_GT(d1.hausdorff_mm, 0.45);
  EXPECT_LE(d1.hausdorff_mm, 0.5 + 1e-12);
  options.seed = 8;
  EXPECT_NE(surface_distance(b, a, options).rms_mm, d1.rms_mm);
  EXPECT_THROW(surface_distance(TriMesh{}, a), InputError);

  const nlohmann::json j = d1;
  for (const char* key :
       {"mean_mm", "rms_mm", "hausdorff_mm", "mean_pct", "rms_pct", "hausdorff_pct", "reference_diagonal_mm"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST(SurfaceDistance, CappedSamplesAreAnHonestSubsetOfTheFullMeasure) {
  const TriMesh a = icosphere(4, 1.0);  // 2562 vertices, 5120 faces
  TriMesh b = icosphere(4, 1.0);
  b.V.col(0) *= 1.3;  // an ellipsoid: distances vary from 0 to 0.3 over the surface
  DistanceOptions full;
  full.samples_per_face = 2;
  const SurfaceDistance all = surface_distance(a, b, full);
  // A cap above the number of points changes nothing.
  DistanceOptions loose = full;
  loose.max_samples_per_mesh = 100000;
  const SurfaceDistance same = surface_distance(a, b, loose);
  EXPECT_EQ(same.rms_mm, all.rms_mm);
  EXPECT_EQ(same.hausdorff_mm, all.hausdorff_mm);
  // A cap of 3000 of the 12,802 points per mesh: a different, deterministic subset whose RMS
  // and mean estimate the full ones and whose Hausdorff distance is at most the full one.
  DistanceOptions capped = full;
  capped.max_samples_per_mesh = 3000;
  const SurfaceDistance sub = surface_distance(a, b, capped), again = surface_distance(a, b, capped);
  EXPECT_NE(sub.rms_mm, all.rms_mm);
  EXPECT_EQ(sub.rms_mm, again.rms_mm);
  EXPECT_NEAR(sub.rms_mm, all.rms_mm, 0.03 * all.rms_mm);
  EXPECT_NEAR(sub.mean_mm, all.mean_mm, 0.03 * all.mean_mm);
  EXPECT_LE(sub.hausdorff_mm, all.hausdorff_mm);
  EXPECT_GT(sub.hausdorff_mm, 0.95 * all.hausdorff_mm);
  EXPECT_NEAR(all.hausdorff_mm, 0.3, 0.01);
}

TEST(SelfIntersections, NoneOnASphereSomeOnTwoInterpenetratingSpheres) {
  const TriMesh sphere = icosphere(3, 1.0);
  EXPECT_EQ(count_self_intersections(sphere), 0);

  TriMesh apart = icosphere(3, 1.0);
  apart.V.col(0).array() += 3.0;
  EXPECT_EQ(count_self_intersections(merged(sphere, apart)), 0);

  TriMesh overlapping = icosphere(3, 1.0);
  overlapping.V.col(0).array() += 1.0;  // centres 1 apart, radii 1: they cross on a circle
  const int pairs = count_self_intersections(merged(sphere, overlapping));
  // The circle of intersection (radius √3/2) crosses many faces of both spheres.
  EXPECT_GT(pairs, 20);
  // The pairs as a list, and the crossing pairs (no shared vertex): here the same pairs.
  const TriMesh both = merged(sphere, overlapping);
  const auto listed = self_intersecting_face_pairs(both);
  EXPECT_EQ(static_cast<int>(listed.size()), pairs);
  for (const auto& [f, g] : listed) {
    EXPECT_LT(f, g);
    EXPECT_TRUE((f < sphere.num_faces()) != (g < sphere.num_faces())) << f << " " << g;  // one face of each
  }
  auto sorted = listed;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(crossing_face_pairs(both), sorted);
  EXPECT_TRUE(crossing_face_pairs(merged(sphere, apart)).empty());
}

TEST(SelfIntersections, CrossingPairsIgnoreAFoldOfNeighboursThatTheFullCountSees) {
  // One vertex of a sphere pushed just through the far side of its own ring: its faces
  // cross faces that share no vertex with them. A fan of two triangles folded onto each
  // other (sharing an edge) is seen by the full count only.
  TriMesh sphere = icosphere(2, 1.0);
  sphere.V.row(0) *= -1.5;
  EXPECT_GT(crossing_face_pairs(sphere).size(), 0u);
  TriMesh folded;
  folded.V.resize(4, 3);
  folded.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0;  // the 4th corner lies inside the first face
  folded.F.resize(2, 3);
  folded.F << 0, 1, 2, 1, 0, 3;
  EXPECT_TRUE(crossing_face_pairs(folded).empty());
  EXPECT_EQ(count_self_intersections(folded), 1);
}
