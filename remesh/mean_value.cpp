// Mean value coordinates parameterization of a disk (Floater 2003): the system CGAL's
// Mean_value_coordinates_parameterizer_3 solves with its default circular arc-length border,
// assembled straight from the triangle list and factored once with SuiteSparse's KLU.
//
// Why not CGAL's parameterizer itself: on the 31k-vertex mask, building its Surface_mesh and
// running it around the same KLU factorization took 0.07 s more (the parameterization: 0.40 s,
// now 0.33 s, medians of 7 runs). tests/remesh/test_parameterization.cpp checks this map
// against it.
#include <Eigen/KLUSupport>
#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mesh/errors.h"
#include "mesh/vertex_stars.h"
#include "remesh/domain.h"
#include "remesh/parameterization.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The rim's vertices in CGAL's order: from the tail of the first border halfedge of its
/// Surface_mesh (the twin of the first boundary edge in face order), walking against the
/// faces' orientation.
std::vector<int> rim_loop(const TriMesh& disk) {
  const std::vector<std::pair<int, int>> rim_edges = boundary_edges(disk.F, VertexStars(disk.F, disk.num_vertices()));
  if (rim_edges.empty()) throw AlgorithmError("the surface to parameterize has no boundary");
  std::vector<int> rim_next(disk.num_vertices(), -1);
  for (const auto& [a, b] : rim_edges) {
    if (rim_next[b] >= 0)
      throw AlgorithmError("the surface to parameterize has a rim that meets itself at vertex " + std::to_string(b) +
                           ", or faces oriented inconsistently; repair the mesh first");
    rim_next[b] = a;  // the border halfedge b -> a
  }
  const int start = rim_edges.front().second;
  std::vector<int> loop;
  for (int v = start; loop.empty() || v != start; v = rim_next[v]) {
    if (v < 0 || loop.size() == rim_edges.size()) break;
    loop.push_back(v);
  }
  if (loop.size() != rim_edges.size() || rim_next[loop.back()] != start)
    throw AlgorithmError("the surface to parameterize has more than one boundary loop; it must be a disk");
  return loop;
}

/// The rim by arc length on the circle of centre (0.5, 0.5) and radius 0.5, clockwise from
/// (1, 0.5), as CGAL's Circular_border_arc_length_parameterizer_3 places it.
Eigen::MatrixX2d rim_on_circle(const TriMesh& disk, const std::vector<int>& loop) {
  const auto n = static_cast<int>(loop.size());
  std::vector<double> edge(n);
  double total = 0;
  for (int i = 0; i < n; ++i) total += edge[i] = (disk.V.row(loop[(i + 1) % n]) - disk.V.row(loop[i])).norm();
  if (!(total > 0)) throw AlgorithmError("the surface to parameterize has a rim of zero length; repair the mesh first");
  Eigen::MatrixX2d uv(n, 2);
  double length = 0;
  for (int i = 0; i < n; ++i) {
    const double angle = length * (2 * kPi / total);
    uv.row(i) << 0.5 + 0.5 * std::cos(-angle), 0.5 + 0.5 * std::sin(-angle);
    length += edge[i];
  }
  return uv;
}

/// tan(θ/2) of the angle θ between u and v, as CGAL's tangent weight computes it: from the
/// arccosine of the unit vectors' dot product, a zero vector left as it is (θ = π/2 then).
double half_angle_tangent(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  const auto unit = [](const Eigen::Vector3d& w) -> Eigen::Vector3d {
    const double length = w.norm();
    return length == 0 ? w : Eigen::Vector3d(w / length);
  };
  return std::tan(0.5 * std::acos(std::clamp(unit(u).dot(unit(v)), -1.0, 1.0)));
}

/// Rows of the system: a rim vertex's is the identity's; an interior vertex i's holds
/// −w_ij off the diagonal and Σ_j w_ij on it, w_ij = (tan(α/2) + tan(β/2)) / |x_j − x_i| with α, β
/// the angles at x_i beside edge ij (0 for an edge of zero length, as in CGAL), summed here
/// corner by corner.
Eigen::SparseMatrix<double> mean_value_matrix(const TriMesh& disk, const std::vector<char>& on_rim) {
  const int n = disk.num_vertices();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(6 * static_cast<std::size_t>(disk.num_faces()) + n);
  std::vector<double> diagonal(n, 0.0);
  for (int f = 0; f < disk.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int i = disk.F(f, k);
      if (on_rim[i]) continue;
      const int j = disk.F(f, (k + 1) % 3), l = disk.F(f, (k + 2) % 3);
      const Eigen::Vector3d u = disk.V.row(j) - disk.V.row(i), v = disk.V.row(l) - disk.V.row(i);
      const double t = half_angle_tangent(u, v);
      for (const auto& [neighbour, length] : {std::pair{j, u.norm()}, std::pair{l, v.norm()}}) {
        if (length == 0) continue;
        entries.emplace_back(i, neighbour, -t / length);
        diagonal[i] += t / length;
      }
    }
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, on_rim[i] ? 1.0 : diagonal[i]);
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(entries.begin(), entries.end());
  return A;
}

/// Solves A X = B with KLU. A mean value matrix is an M-matrix, so the diagonal stays the
/// pivot and the work is the fill of KLU's AMD ordering of A + Aᵀ. Its block triangular form
/// is off: a connected mesh's matrix is one irreducible block, and looking for blocks costs time.
Eigen::MatrixX2d solve_with_klu(const Eigen::SparseMatrix<double>& A, const Eigen::MatrixX2d& B) {
  Eigen::KLU<Eigen::SparseMatrix<double>> lu;
  lu.kluCommon().btf = 0;
  lu.compute(A);
  const auto failed = [] {
    return AlgorithmError(
        "the parameterization's linear system could not be solved; the surface may have degenerate triangles: "
        "repair or smooth it first");
  };
  if (lu.info() != Eigen::Success) throw failed();
  Eigen::MatrixX2d X = lu.solve(B);
  if (lu.info() != Eigen::Success) throw failed();
  return X;
}

}  // namespace

Eigen::MatrixX2d mean_value_disk_map(const TriMesh& disk) {
  const std::vector<int> loop = rim_loop(disk);
  const Eigen::MatrixX2d circle = rim_on_circle(disk, loop);
  std::vector<char> on_rim(disk.num_vertices(), 0);
  Eigen::MatrixX2d rhs = Eigen::MatrixX2d::Zero(disk.num_vertices(), 2);
  for (std::size_t r = 0; r < loop.size(); ++r) {
    on_rim[loop[r]] = 1;
    rhs.row(loop[r]) = circle.row(static_cast<Eigen::Index>(r));
  }
  Eigen::MatrixX2d uv = solve_with_klu(mean_value_matrix(disk, on_rim), rhs);
  for (int v = 0; v < disk.num_vertices(); ++v)
    if (on_rim[v]) uv.row(v) = rhs.row(v);  // exactly on the circle, as CGAL leaves them
  if (!uv.allFinite())
    throw AlgorithmError(
        "the parameterization produced non-finite coordinates; the surface may have degenerate "
        "triangles: repair or smooth it first");
  return uv;
}

}  // namespace mrsnake
