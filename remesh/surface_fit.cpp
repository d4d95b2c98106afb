#include "remesh/surface_fit.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include "mesh/normals.h"
#include "mesh/parallel.h"
#include "mesh/quality.h"

namespace mrsnake {

namespace {

// Quadrature points of the whole level: the vertices (rows 0..n-1), then the face centroids.
// Per face, corners 1/12 and centroid 3/4 of its area: a rule exact for quadratic integrands.
// The chord error of a triangle on a curved patch is quadratic, so the integrands of the normal
// equations are cubic and quartic and the rule only approximates them; on a sphere it still
// gives the continuous optimum's uniform offset, and it needs a third of the closest-point
// queries of a rule with edge midpoints (the vertices start on the surface: none at first).
struct Quadrature {
  Eigen::VectorXd weight;  // per point
  Eigen::VectorXd mass;    // per vertex: a third of the area of its faces (the regularization's)
};

Quadrature build_quadrature(const RowMatrixX3i& F, const RowMatrixX3d& X) {
  const Eigen::Index n = X.rows();
  Quadrature q;
  q.weight.setZero(n + F.rows());
  q.mass.setZero(n);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = X.row(F(f, 0)), b = X.row(F(f, 1)), c = X.row(F(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    q.weight(n + f) = 0.75 * area;
    for (int k = 0; k < 3; ++k) {
      q.weight(F(f, k)) += area / 12.0;
      q.mass(F(f, k)) += area / 3.0;
    }
  }
  return q;
}

// Mean length of the edges at each vertex.
Eigen::VectorXd mean_edge_lengths(const RowMatrixX3i& F, const RowMatrixX3d& X) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(X.rows()), count = Eigen::VectorXd::Zero(X.rows());
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      const double length = (X.row(a) - X.row(b)).norm();  // an interior edge counts once from each face
      sum(a) += length;
      sum(b) += length;
      count(a) += 1;
      count(b) += 1;
    }
  return sum.cwiseQuotient(count.cwiseMax(1.0));
}

}  // namespace

SurfaceFitStats fit_to_surface(const RowMatrixX3i& F, RowMatrixX3d& X, const SurfaceLocator& surface_locator,
                               const SurfaceFitOptions& options, const std::vector<bool>& fixed) {
  if (options.rounds < 0) throw std::invalid_argument("surface fit rounds must be >= 0");
  if (!(options.regularization > 0)) throw std::invalid_argument("surface fit regularization must be > 0");
  if (!(options.max_offset >= 0)) throw std::invalid_argument("surface fit max_offset must be >= 0");
  if (!(options.max_sample_distance > 0)) throw std::invalid_argument("surface fit max_sample_distance must be > 0");
  if (!(options.quality_floor >= 0 && options.quality_floor <= 1))
    throw std::invalid_argument("surface fit quality_floor must be in [0, 1]");
  if (!fixed.empty() && fixed.size() != static_cast<std::size_t>(X.rows()))
    throw std::invalid_argument("surface fit: fixed must have one entry per vertex");
  SurfaceFitStats stats;
  const Eigen::Index n = X.rows(), m = F.rows();
  if (options.rounds == 0 || n == 0 || m == 0) return stats;
  auto is_fixed = [&](Eigen::Index v) { return !fixed.empty() && fixed[static_cast<std::size_t>(v)]; };

  RowMatrixX3d normals, face_normals_before;
  vertex_normals(X, F, normals);
  face_normals(X, F, face_normals_before);
  const Quadrature quadrature = build_quadrature(F, X);
  const Eigen::VectorXd edge_length = mean_edge_lengths(F, X);
  const Eigen::Index points = n + m;
  // The vertices of point s and their barycentric weights (a vertex point is its own corner).
  auto corner = [&](Eigen::Index s, int k) { return s < n ? static_cast<int>(s) : F(s - n, k); };
  auto corner_weight = [&](Eigen::Index s, int k) { return s < n ? (k == 0 ? 1.0 : 0.0) : 1.0 / 3.0; };

  Eigen::VectorXd offset = Eigen::VectorXd::Zero(n);
  // Per point: the normal distance to the surface, its weight this round (0 = left out), the
  // coefficients of the corners' offsets in that distance, and the target of the least squares.
  Eigen::VectorXd distance(points), weight(points), target(points);
  RowMatrixX3d coefficient(points, 3);
  for (int round = 0; round < options.rounds; ++round) {
    parallel_ranges(static_cast<std::size_t>(points), [&](std::size_t begin, std::size_t end) {
      for (auto s = static_cast<Eigen::Index>(begin); s < static_cast<Eigen::Index>(end); ++s) {
        Eigen::Vector3d p = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
        double length = 0;
        for (int k = 0; k < 3; ++k) {
          const int v = corner(s, k);
          const double b = corner_weight(s, k);
          p += b * (X.row(v).transpose() + offset(v) * normals.row(v).transpose());
          normal += b * normals.row(v).transpose();
          length += b * edge_length(v);
        }
        const double normal_length = normal.norm();
        normal /= std::max(normal_length, 1e-300);
        weight(s) = normal_length > 0 ? quadrature.weight(s) : 0.0;
        if (round == 0 && s < n) {
          distance(s) = 0;  // a vertex starts on the surface (precondition)
        } else {
          const SurfaceLocator::Hit hit = surface_locator.closest(p);
          if (hit.distance > options.max_sample_distance * length) weight(s) = 0;
          distance(s) = normal.dot(hit.point - p);
        }
        for (int k = 0; k < 3; ++k)
          coefficient(s, k) = corner_weight(s, k) * normal.dot(normals.row(corner(s, k)).transpose());
      }
    });
    // Normal equations of  sum_s w_s (a_s . t - (d_s + a_s . t_now))^2 + lambda sum_v mass_v t_v^2,
    // with a_s the coefficients: each round linearizes at the offsets t_now it starts from.
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(static_cast<std::size_t>(2 * n + 9 * m));  // vertex points, centroids, regularization
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    double weight_sum = 0, squared_before = 0;
    for (Eigen::Index s = 0; s < points; ++s) {
      if (weight(s) <= 0) continue;
      target(s) = distance(s);
      for (int k = 0; k < 3; ++k) target(s) += coefficient(s, k) * offset(corner(s, k));
      weight_sum += weight(s);
      squared_before += weight(s) * distance(s) * distance(s);
      for (int i = 0; i < 3; ++i) {
        if (coefficient(s, i) == 0) continue;
        rhs(corner(s, i)) += weight(s) * coefficient(s, i) * target(s);
        for (int j = 0; j < 3; ++j)
          if (coefficient(s, j) != 0)
            triplets.emplace_back(corner(s, i), corner(s, j), weight(s) * coefficient(s, i) * coefficient(s, j));
      }
    }
    if (weight_sum <= 0) break;
    if (round == 0) stats.rms_before = std::sqrt(squared_before / weight_sum);
    for (Eigen::Index v = 0; v < n; ++v) triplets.emplace_back(v, v, options.regularization * quadrature.mass(v));
    Eigen::SparseMatrix<double> normal_matrix(n, n);
    normal_matrix.setFromTriplets(triplets.begin(), triplets.end());
    // A fixed vertex keeps offset 0: its row and column become the identity's.
    if (!fixed.empty()) {
      for (int col = 0; col < normal_matrix.outerSize(); ++col)
        for (Eigen::SparseMatrix<double>::InnerIterator it(normal_matrix, col); it; ++it)
          if (is_fixed(it.row()) || is_fixed(it.col())) it.valueRef() = it.row() == it.col() ? 1.0 : 0.0;
      for (Eigen::Index v = 0; v < n; ++v)
        if (is_fixed(v)) rhs(v) = 0;
    }
    // Mass-matrix-like and diagonally dominant: Jacobi-preconditioned CG takes ~15 iterations.
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> solver;
    solver.setTolerance(1e-8);
    solver.setMaxIterations(500);
    solver.compute(normal_matrix);
    const Eigen::VectorXd solved = solver.solveWithGuess(rhs, offset);
    // A solve that failed (or produced a NaN) keeps the offsets of the round before.
    if (solver.info() == Eigen::NumericalIssue || !solved.allFinite()) break;
    offset = solved;
    stats.clamped_vertices = 0;
    for (Eigen::Index v = 0; v < n; ++v) {
      const double limit = options.max_offset * edge_length(v);
      if (std::abs(offset(v)) > limit) {
        offset(v) = std::copysign(limit, offset(v));
        ++stats.clamped_vertices;
      }
    }
    // The linearized distance this round's offsets leave.
    double squared_after = 0;
    for (Eigen::Index s = 0; s < points; ++s) {
      if (weight(s) <= 0) continue;
      double residual = target(s);
      for (int k = 0; k < 3; ++k) residual -= coefficient(s, k) * offset(corner(s, k));
      squared_after += weight(s) * residual * residual;
    }
    stats.rms_after = std::sqrt(squared_after / weight_sum);
  }

  // A guard on the triangles: the offsets around one that would turn by 30 degrees or more,
  // or end with a quality below min(its own, quality_floor), are undone. Chord corrections are
  // far too small for either on a surface the level resolves; a staircase's voxel steps are not.
  RowMatrixX3d Y = X + normals.cwiseProduct(offset.replicate(1, 3));
  const double cos_limit = std::cos(30.0 * M_PI / 180.0);
  auto quality = [&](const RowMatrixX3d& P, Eigen::Index f) {
    return frey_borouchaki_quality(P.row(F(f, 0)), P.row(F(f, 1)), P.row(F(f, 2)));
  };
  Eigen::VectorXd quality_floor(m);
  for (Eigen::Index f = 0; f < m; ++f) quality_floor(f) = std::min(quality(X, f), options.quality_floor);
  RowMatrixX3d face_normals_after;
  for (bool changed = true; changed;) {  // ends: every pass that goes on zeroes an offset
    changed = false;
    face_normals(Y, F, face_normals_after);
    for (Eigen::Index f = 0; f < m; ++f) {
      if (face_normals_after.row(f).dot(face_normals_before.row(f)) >= cos_limit && quality(Y, f) >= quality_floor(f))
        continue;
      for (int k = 0; k < 3; ++k) {
        const int v = F(f, k);
        if (offset(v) == 0) continue;
        offset(v) = 0;
        Y.row(v) = X.row(v);
        ++stats.held_vertices;
        changed = true;
      }
    }
  }
  X = std::move(Y);
  stats.mean_offset = offset.cwiseAbs().mean();
  stats.max_offset = offset.cwiseAbs().maxCoeff();
  return stats;
}

}  // namespace mrsnake
