#include "remesh/parameterization.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>

#include "mesh/errors.h"
#include "mesh/topology.h"

namespace mrsnake {
namespace {

double face_area(const RowMatrixX3d& P, const RowMatrixX3i& F, int f) {
  const Eigen::Vector3d a = P.row(F(f, 0)), b = P.row(F(f, 1)), c = P.row(F(f, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

double min_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  auto angle = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
    const Eigen::Vector3d u = q - p, v = r - p;
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

// The vertex whose star is best shaped (valence 5..7 preferred): its star becomes the cap
// around the pole.
int choose_puncture_vertex(const TriMesh& mesh) {
  const int n = mesh.num_vertices();
  std::vector<int> valence(n, 0);
  std::vector<double> worst(n, M_PI);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const double m = min_angle(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)), mesh.V.row(mesh.F(f, 2)));
    for (int k = 0; k < 3; ++k) {
      ++valence[mesh.F(f, k)];
      worst[mesh.F(f, k)] = std::min(worst[mesh.F(f, k)], m);
    }
  }
  int best = 0;
  double best_score = -1;
  for (int v = 0; v < n; ++v) {
    const double score = worst[v] - (valence[v] >= 5 && valence[v] <= 7 ? 0.0 : 1.0);
    if (score > best_score) {
      best_score = score;
      best = v;
    }
  }
  return best;
}

Eigen::VectorXd vertex_weights(const TriMesh& mesh) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const double a = face_area(mesh.V, mesh.F, f) / 3.0;
    for (int k = 0; k < 3; ++k) w[mesh.F(f, k)] += a;
  }
  return w;
}

// Möbius balancing on the sphere: the 3D-area-weighted centroid of the images goes to 0.
int balance_sphere(RowMatrixX3d& D, const Eigen::VectorXd& weights) {
  const double total = weights.sum();
  int it = 0;
  for (; it < 200; ++it) {
    const Eigen::Vector3d c = (D.transpose() * weights) / total;
    if (c.norm() < 1e-5) break;
    Eigen::Vector3d a = 0.75 * c;
    if (a.norm() > 0.9) a *= 0.9 / a.norm();
    for (int v = 0; v < D.rows(); ++v) D.row(v) = mobius_to_center(a, D.row(v).transpose()).normalized().transpose();
  }
  return it;
}

// Möbius balancing in the unit disk, z -> (z - a) / (1 - conj(a) z).
int balance_disk(RowMatrixX3d& D, const Eigen::VectorXd& weights) {
  const double total = weights.sum();
  int it = 0;
  for (; it < 200; ++it) {
    std::complex<double> c = 0;
    for (int v = 0; v < D.rows(); ++v) c += weights[v] * std::complex<double>(D(v, 0), D(v, 1));
    c /= total;
    if (std::abs(c) < 1e-5) break;
    std::complex<double> a = 0.9 * c;
    if (std::abs(a) > 0.9) a *= 0.9 / std::abs(a);
    for (int v = 0; v < D.rows(); ++v) {
      const std::complex<double> z(D(v, 0), D(v, 1));
      const std::complex<double> w = (z - a) / (1.0 - std::conj(a) * z);
      D(v, 0) = w.real();
      D(v, 1) = w.imag();
    }
  }
  return it;
}

}  // namespace

Eigen::Vector3d mobius_to_center(const Eigen::Vector3d& a, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - a;
  return (1.0 - a.squaredNorm()) * d / d.squaredNorm() - a;
}

Parameterization parameterize(const TriMesh& input) {
  const auto start = std::chrono::steady_clock::now();
  Parameterization param;
  param.surface = remove_unreferenced_vertices(input);
  const TriMesh& mesh = param.surface;
  const TopologyReport topo = topology_report(mesh);
  require_disk_or_sphere(topo, "the input surface");
  const int n = mesh.num_vertices();
  param.domain.resize(n, 3);
  int balance_iterations = 0;
  const Eigen::VectorXd weights = vertex_weights(mesh);

  if (topo.is_disk()) {
    param.kind = DomainKind::disk;
    const auto solve_start = std::chrono::steady_clock::now();
    const Eigen::MatrixX2d uv = mean_value_disk_map(mesh);
    param.summary["solver_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_start).count();
    for (int v = 0; v < n; ++v) param.domain.row(v) << 2 * uv(v, 0) - 1, 2 * uv(v, 1) - 1, 1.0;
    double signed_area = 0;
    for (int f = 0; f < mesh.num_faces(); ++f)
      signed_area += domain_orientation(param.domain.row(mesh.F(f, 0)), param.domain.row(mesh.F(f, 1)),
                                        param.domain.row(mesh.F(f, 2)));
    if (signed_area < 0) param.domain.col(1) *= -1.0;
    balance_iterations = balance_disk(param.domain, weights);
  } else {
    param.kind = DomainKind::sphere;
    const int pole = choose_puncture_vertex(mesh);
    std::vector<int> keep;
    std::vector<int> star;
    for (int f = 0; f < mesh.num_faces(); ++f)
      ((mesh.F(f, 0) == pole || mesh.F(f, 1) == pole || mesh.F(f, 2) == pole) ? star : keep).push_back(f);
    // The punctured surface with `pole` dropped; old -> new vertex indices.
    std::vector<int> to_disk(n, -1), to_mesh;
    for (int v = 0; v < n; ++v)
      if (v != pole) {
        to_disk[v] = static_cast<int>(to_mesh.size());
        to_mesh.push_back(v);
      }
    TriMesh disk;
    disk.V.resize(n - 1, 3);
    for (int i = 0; i < n - 1; ++i) disk.V.row(i) = mesh.V.row(to_mesh[i]);
    disk.F.resize(static_cast<int>(keep.size()), 3);
    for (std::size_t i = 0; i < keep.size(); ++i)
      for (int k = 0; k < 3; ++k) disk.F(static_cast<int>(i), k) = to_disk[mesh.F(keep[i], k)];
    const auto solve_start = std::chrono::steady_clock::now();
    const Eigen::MatrixX2d uv = mean_value_disk_map(disk);
    param.summary["solver_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_start).count();
    for (int i = 0; i < n - 1; ++i) {
      // Inverse stereographic projection from the pole (0, 0, 1); the disk's rim goes to the equator.
      const double x = 2 * uv(i, 0) - 1, y = 2 * uv(i, 1) - 1, s = x * x + y * y;
      param.domain.row(to_mesh[i]) << 2 * x / (1 + s), 2 * y / (1 + s), (s - 1) / (1 + s);
    }
    param.domain.row(pole) << 0, 0, 1;
    int negative = 0;
    for (int f = 0; f < mesh.num_faces(); ++f)
      if (domain_orientation(param.domain.row(mesh.F(f, 0)), param.domain.row(mesh.F(f, 1)),
                             param.domain.row(mesh.F(f, 2))) < 0)
        ++negative;
    if (2 * negative > mesh.num_faces()) param.domain.col(0) *= -1.0;  // stereographic projection reverses orientation
    balance_iterations = balance_sphere(param.domain, weights);
    param.summary["pole_vertex"] = pole;
  }

  const int flipped = count_flipped(param.domain, mesh.F);
  if (flipped > 0)
    throw AlgorithmError("the parameterization has " + std::to_string(flipped) +
                         " flipped triangles; the surface cannot be parameterized well (repair degenerate triangles or "
                         "smooth it first)");

  // Area distortion.
  const int m = mesh.num_faces();
  param.face_stretch.resize(m);
  Eigen::VectorXd area3(n), aread(n);
  area3.setZero();
  aread.setZero();
  double total3 = 0, totald = 0;
  for (int f = 0; f < m; ++f) {
    const double a3 = face_area(mesh.V, mesh.F, f), ad = face_area(param.domain, mesh.F, f);
    param.face_stretch[f] = a3 / ad;
    total3 += a3;
    totald += ad;
    for (int k = 0; k < 3; ++k) {
      area3[mesh.F(f, k)] += a3;
      aread[mesh.F(f, k)] += ad;
    }
  }
  param.vertex_stretch = area3.cwiseQuotient(aread);
  const double mean_stretch = total3 / totald;
  // Spread of the distortion, ignoring the 0.1% most extreme faces on each side.
  std::vector<double> sorted(param.face_stretch.data(), param.face_stretch.data() + m);
  std::sort(sorted.begin(), sorted.end());
  const double lo = sorted[m / 1000], hi = sorted[m - 1 - m / 1000];
  if (!std::isfinite(param.vertex_stretch.sum()) || !(sorted.front() > 0) || !std::isfinite(sorted.back()))
    throw AlgorithmError("the parameterization is degenerate (zero-area triangles in the domain); the surface cannot "
                         "be parameterized well: repair degenerate triangles first");
  if (hi / lo > 1e12)
    throw AlgorithmError("the parameterization is too distorted (area stretch spans " +
                         std::to_string(static_cast<int>(std::log10(hi / lo))) +
                         " orders of magnitude): long protrusions cannot be remeshed from one chart; simplify the shape");

  param.summary["method"] = param.kind == DomainKind::sphere
                                ? "mean value coordinates of the punctured sphere, inverse stereographic, Mobius balanced"
                                : "mean value coordinates on the unit disk, Mobius balanced";
  param.summary["domain"] = param.kind == DomainKind::sphere ? "sphere" : "disk";
  param.summary["balance_iterations"] = balance_iterations;
  param.summary["stretch_min"] = sorted.front() / mean_stretch;
  param.summary["stretch_max"] = sorted.back() / mean_stretch;
  param.summary["stretch_spread_log10"] = std::log10(hi / lo);
  param.summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return param;
}

}  // namespace mrsnake
