// The one translation unit that sees CGAL's AABB tree and self-intersection test.
#include "mesh/distance.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/parallel.h"

namespace mrsnake {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Point to_cgal(const Eigen::Vector3d& p) { return Point(p.x(), p.y(), p.z()); }
Eigen::Vector3d to_eigen(const Point& p) { return {p.x(), p.y(), p.z()}; }

/// Barycentric coordinates of p (on or near the triangle's plane) in triangle abc, by the
/// areas of the sub-triangles projected on the normal; falls back to the nearest corner
/// for a degenerate triangle.
Eigen::Vector3d barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  if (nn <= 0) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    const double d[3] = {(p - a).squaredNorm(), (p - b).squaredNorm(), (p - c).squaredNorm()};
    w[static_cast<int>(std::min_element(d, d + 3) - d)] = 1.0;
    return w;
  }
  Eigen::Vector3d w((c - b).cross(p - b).dot(n) / nn, (a - c).cross(p - c).dot(n) / nn, 0.0);
  // The closest point lies in the closed triangle; clamp rounding noise so weights are >= 0.
  w[0] = std::clamp(w[0], 0.0, 1.0);
  w[1] = std::clamp(w[1], 0.0, 1.0 - w[0]);
  w[2] = 1.0 - w[0] - w[1];
  return w;
}

/// A 53-bit uniform double in [0, 1) from a 64-bit Mersenne twister: the same stream on
/// every standard library, unlike std::uniform_real_distribution.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// Every referenced vertex plus `per_face` uniformly random points in each face.
RowMatrixX3d sample_surface(const TriMesh& mesh, int per_face, std::mt19937_64& rng) {
  std::vector<char> used(mesh.num_vertices(), 0);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) used[mesh.F(f, k)] = 1;
  const long long n_used = std::count(used.begin(), used.end(), 1);
  const long long per = std::max(per_face, 0);
  RowMatrixX3d P(n_used + per * mesh.num_faces(), 3);
  Eigen::Index row = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (used[v]) P.row(row++) = mesh.V.row(v);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    for (long long s = 0; s < per; ++s) {
      // Uniform on the triangle: the square root warps the first coordinate (Turk 1990).
      const double r1 = std::sqrt(uniform01(rng)), r2 = uniform01(rng);
      P.row(row++) = (1.0 - r1) * a + r1 * (1.0 - r2) * b + r1 * r2 * c;
    }
  }
  return P;
}

/// A uniform random subset of `cap` rows of P (partial Fisher-Yates; rows kept in order), or
/// P itself when it has no more than cap rows or cap <= 0.
RowMatrixX3d subsample_rows(RowMatrixX3d P, long long cap, std::mt19937_64& rng) {
  const auto n = static_cast<long long>(P.rows());
  if (cap <= 0 || n <= cap) return P;
  std::vector<Eigen::Index> index(static_cast<std::size_t>(n));
  for (long long i = 0; i < n; ++i) index[i] = static_cast<Eigen::Index>(i);
  for (long long i = 0; i < cap; ++i) {
    const long long j = i + static_cast<long long>(rng() % static_cast<unsigned long long>(n - i));
    std::swap(index[i], index[j]);
  }
  std::sort(index.begin(), index.begin() + cap);
  RowMatrixX3d out(cap, 3);
  for (long long i = 0; i < cap; ++i) out.row(i) = P.row(index[i]);
  return out;
}

}  // namespace

struct SurfaceLocator::Impl {
  TriMesh mesh;
  std::vector<Triangle> triangles;
  Tree tree;
};

SurfaceLocator::SurfaceLocator(const TriMesh& mesh) : impl_(std::make_unique<Impl>()) {
  if (mesh.empty()) throw InputError("the mesh has no faces: a closest-point search needs at least one triangle");
  impl_->mesh = mesh;
  impl_->triangles.reserve(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f)
    impl_->triangles.emplace_back(to_cgal(mesh.V.row(mesh.F(f, 0))), to_cgal(mesh.V.row(mesh.F(f, 1))),
                                  to_cgal(mesh.V.row(mesh.F(f, 2))));
  impl_->tree.insert(impl_->triangles.cbegin(), impl_->triangles.cend());
  impl_->tree.build();
  impl_->tree.accelerate_distance_queries();
}

SurfaceLocator::~SurfaceLocator() = default;
SurfaceLocator::SurfaceLocator(SurfaceLocator&&) noexcept = default;
SurfaceLocator& SurfaceLocator::operator=(SurfaceLocator&&) noexcept = default;

SurfaceLocator::Hit SurfaceLocator::closest(const Eigen::Vector3d& p) const {
  const auto [point, it] = impl_->tree.closest_point_and_primitive(to_cgal(p));
  Hit hit;
  hit.point = to_eigen(point);
  hit.face = static_cast<int>(std::distance(impl_->triangles.cbegin(), it));
  const TriMesh& m = impl_->mesh;
  hit.barycentric =
      barycentric(hit.point, m.V.row(m.F(hit.face, 0)), m.V.row(m.F(hit.face, 1)), m.V.row(m.F(hit.face, 2)));
  hit.distance = (hit.point - p).norm();
  return hit;
}

Eigen::VectorXd SurfaceLocator::distances(const RowMatrixX3d& P) const {
  Eigen::VectorXd d(P.rows());
  // The tree (and its search hints) are built; const queries are thread-safe, and each
  // distance is independent of the others.
  parallel_ranges(static_cast<std::size_t>(P.rows()), [&](std::size_t begin, std::size_t end) {
    for (auto i = static_cast<Eigen::Index>(begin); i < static_cast<Eigen::Index>(end); ++i)
      d[i] = std::sqrt(impl_->tree.squared_distance(to_cgal(P.row(i))));
  });
  return d;
}

SurfaceDistance surface_distance(const TriMesh& mesh, const TriMesh& reference, const DistanceOptions& options) {
  if (mesh.empty() || reference.empty())
    throw InputError("a surface distance needs two meshes with at least one face each");
  return surface_distance(mesh, reference, SurfaceLocator(reference), options);
}

SurfaceDistance surface_distance(const TriMesh& mesh, const TriMesh& reference, const SurfaceLocator& reference_locator,
                                 const DistanceOptions& options) {
  if (mesh.empty() || reference.empty())
    throw InputError("a surface distance needs two meshes with at least one face each");
  std::mt19937_64 rng(options.seed);
  RowMatrixX3d on_mesh = sample_surface(mesh, options.samples_per_face, rng);
  RowMatrixX3d on_reference = sample_surface(reference, options.samples_per_face, rng);
  if (options.max_samples_per_mesh > 0) {
    // One fraction for both sets, so that each direction keeps its weight in the pooled figures.
    const double larger = static_cast<double>(std::max(on_mesh.rows(), on_reference.rows()));
    const double keep = std::min(1.0, static_cast<double>(options.max_samples_per_mesh) / larger);
    const auto thin = [&](RowMatrixX3d P) {
      const auto cap = std::max<long long>(1, std::llround(keep * static_cast<double>(P.rows())));
      return subsample_rows(std::move(P), cap, rng);
    };
    on_mesh = thin(std::move(on_mesh));
    on_reference = thin(std::move(on_reference));
  }
  const Eigen::VectorXd forward = reference_locator.distances(on_mesh);
  const Eigen::VectorXd backward = SurfaceLocator(mesh).distances(on_reference);

  SurfaceDistance r;
  const double count = static_cast<double>(forward.size() + backward.size());
  r.mean_mm = (forward.sum() + backward.sum()) / count;
  r.rms_mm = std::sqrt((forward.squaredNorm() + backward.squaredNorm()) / count);
  r.hausdorff_mm = std::max(forward.maxCoeff(), backward.maxCoeff());
  r.reference_diagonal_mm = bounding_box_diagonal(reference.V);
  if (r.reference_diagonal_mm > 0) {
    r.mean_pct = 100.0 * r.mean_mm / r.reference_diagonal_mm;
    r.rms_pct = 100.0 * r.rms_mm / r.reference_diagonal_mm;
    r.hausdorff_pct = 100.0 * r.hausdorff_mm / r.reference_diagonal_mm;
  }
  return r;
}

std::vector<std::pair<int, int>> crossing_face_pairs(const TriMesh& mesh) {
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int>;
  std::vector<Box> boxes;
  std::vector<Triangle> triangles(static_cast<std::size_t>(mesh.num_faces()));
  boxes.reserve(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    if (a == b || b == c || c == a) continue;
    triangles[f] = Triangle(to_cgal(mesh.V.row(a)), to_cgal(mesh.V.row(b)), to_cgal(mesh.V.row(c)));
    // CGAL's triangle-triangle test requires non-degenerate triangles; a collapsed face has
    // no area to cross with, and the fold tests of the snake see it.
    if (triangles[f].is_degenerate()) continue;
    boxes.emplace_back(triangles[f].bbox(), f);
  }
  std::vector<std::pair<int, int>> out;
  // The cutoff is the range size below which CGAL scans boxes pairwise instead of splitting
  // further. Its default of 10 made this 2.4-2.7x slower on the snake's 15k-61k-face levels
  // (21 -> 8.7 ms at 15k faces, 30 -> 11 ms at 20k): a surface's boxes overlap mostly with
  // their neighbours', so deep splitting buys little.
  const std::ptrdiff_t cutoff = 400;
  CGAL::box_self_intersection_d(
      boxes.begin(), boxes.end(),
      [&](const Box& x, const Box& y) {
        const int f = x.info(), g = y.info();
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k)
            if (mesh.F(f, i) == mesh.F(g, k)) return;  // neighbours: left to the fold tests
        if (CGAL::do_intersect(triangles[f], triangles[g])) out.emplace_back(std::min(f, g), std::max(f, g));
      },
      cutoff);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<int, int>> self_intersecting_face_pairs(const TriMesh& mesh) {
  using SurfaceMesh = CGAL::Surface_mesh<Point>;
  using Face = SurfaceMesh::Face_index;
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> vertices;
  vertices.reserve(mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) vertices.push_back(sm.add_vertex(to_cgal(mesh.V.row(v))));
  std::vector<int> original;  // mesh.F row of each CGAL face (faces with a repeated corner are skipped)
  original.reserve(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    if (a == b || b == c || c == a) continue;  // a repeated corner: no triangle to intersect
    const Face face = sm.add_face(vertices[a], vertices[b], vertices[c]);
    if (face == SurfaceMesh::null_face())
      throw TopologyError("face " + std::to_string(f) +
                              " makes the mesh non-manifold or inconsistently oriented, so its self-intersections "
                              "cannot be counted",
                          Remedy::inspect_mesh);
    original.push_back(f);
  }
  std::vector<std::pair<Face, Face>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  std::vector<std::pair<int, int>> out;
  out.reserve(pairs.size());
  for (const auto& [f, g] : pairs) {
    const int a = original[static_cast<std::size_t>(f.idx())], b = original[static_cast<std::size_t>(g.idx())];
    out.emplace_back(std::min(a, b), std::max(a, b));
  }
  return out;
}

int count_self_intersections(const TriMesh& mesh) {
  return static_cast<int>(self_intersecting_face_pairs(mesh).size());
}

void to_json(nlohmann::json& j, const SurfaceDistance& d) {
  j = nlohmann::json{
      {"mean_mm", d.mean_mm},
      {"rms_mm", d.rms_mm},
      {"hausdorff_mm", d.hausdorff_mm},
      {"mean_pct", d.mean_pct},
      {"rms_pct", d.rms_pct},
      {"hausdorff_pct", d.hausdorff_pct},
      {"reference_diagonal_mm", d.reference_diagonal_mm},
  };
}

}  // namespace mrsnake
