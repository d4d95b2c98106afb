#include "mesh/quality.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Angle between two vectors in degrees; atan2 stays accurate near 0° and 180° and gives 0
/// (not NaN) for a zero-length vector.
double angle_deg(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return std::atan2(u.cross(v).norm(), u.dot(v)) * 180.0 / kPi;
}

/// Running mean and population variance (Welford), stable for large meshes.
struct Moments {
  long long n = 0;
  double mean = 0, m2 = 0;
  void add(double x) {
    ++n;
    const double d = x - mean;
    mean += d / static_cast<double>(n);
    m2 += d * (x - mean);
  }
  double variance() const { return n > 0 ? m2 / static_cast<double>(n) : 0.0; }
  double cv() const { return mean != 0 ? std::sqrt(variance()) / std::abs(mean) : 0.0; }
};

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

}  // namespace

double frey_borouchaki_quality(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const double half_perimeter = 0.5 * (la + lb + lc);
  const double longest = std::max({la, lb, lc});
  if (half_perimeter <= 0 || longest <= 0) return 0.0;
  return (6.0 / std::sqrt(3.0)) * area / (half_perimeter * longest);
}

double radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // r_in = A/p and r_circ = abc/(4A), so 2·r_in/r_circ = 8A²/(p·abc).
  const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const double half_perimeter = 0.5 * (la + lb + lc);
  const double denom = half_perimeter * la * lb * lc;
  if (denom <= 0) return 0.0;
  return 8.0 * area * area / denom;
}

QualityReport mesh_quality(const TriMesh& mesh) {
  if (mesh.empty()) throw InputError("the mesh has no faces: quality needs at least one triangle");
  QualityReport r;
  const int n = mesh.num_vertices();
  const int m = mesh.num_faces();
  r.vertices = n;
  r.faces = m;

  Moments all_angles, min_angles, deviation, q, rho, areas;
  double min_angle = std::numeric_limits<double>::infinity();
  double q_min = std::numeric_limits<double>::infinity();
  double rho_min = std::numeric_limits<double>::infinity();
  long long below_30 = 0;

  // Undirected edge -> number of faces on it; gives edge lengths, valence and the boundary.
  std::unordered_map<std::uint64_t, int> edge_faces;
  edge_faces.reserve(static_cast<std::size_t>(3 * m));
  for (int f = 0; f < m; ++f) {
    const Eigen::Vector3d p[3] = {mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)), mesh.V.row(mesh.F(f, 2))};
    double face_min = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double theta = angle_deg(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
      all_angles.add(theta);
      deviation.add(std::abs(theta - 60.0));
      face_min = std::min(face_min, theta);
      ++edge_faces[edge_key(mesh.F(f, k), mesh.F(f, (k + 1) % 3))];
    }
    min_angles.add(face_min);
    min_angle = std::min(min_angle, face_min);
    if (face_min < 30.0) ++below_30;
    const double qf = frey_borouchaki_quality(p[0], p[1], p[2]);
    q.add(qf);
    q_min = std::min(q_min, qf);
    const double rf = radius_ratio(p[0], p[1], p[2]);
    rho.add(rf);
    rho_min = std::min(rho_min, rf);
    areas.add(0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm());
  }
  r.min_angle_deg = min_angle;
  r.mean_min_angle_deg = min_angles.mean;
  r.pct_min_angle_below_30 = 100.0 * static_cast<double>(below_30) / m;
  r.angle_deviation_deg = deviation.mean;
  r.angle_variance_deg2 = all_angles.variance();
  r.q_min = q_min;
  r.q_mean = q.mean;
  r.radius_ratio_min = rho_min;
  r.radius_ratio_mean = rho.mean;
  r.area_cv = areas.cv();

  std::vector<int> valence(n, 0);
  std::vector<char> boundary(n, 0), referenced(n, 0);
  std::vector<double> lengths;
  lengths.reserve(edge_faces.size());
  Moments length;
  for (const auto& [key, count] : edge_faces) {
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    if (a == b) continue;  // a degenerate face's repeated corner is no edge
    ++valence[a];
    ++valence[b];
    referenced[a] = referenced[b] = 1;
    if (count == 1) boundary[a] = boundary[b] = 1;
    const double l = (mesh.V.row(a) - mesh.V.row(b)).norm();
    lengths.push_back(l);
    length.add(l);
  }
  r.edge_length_mean = length.mean;
  r.edge_length_cv = length.cv();
  if (length.mean > 0) {
    Moments normalized;
    for (double l : lengths) normalized.add(l / length.mean);
    r.edge_length_variance = normalized.variance();
  }

  long long interior = 0, interior6 = 0, border = 0, border4 = 0;
  for (int v = 0; v < n; ++v) {
    if (!referenced[v]) continue;
    if (boundary[v]) {
      ++border;
      if (valence[v] == 4) ++border4;
    } else {
      ++interior;
      if (valence[v] == 6) ++interior6;
    }
  }
  r.pct_valence6_interior = interior ? 100.0 * static_cast<double>(interior6) / static_cast<double>(interior) : 0.0;
  r.pct_valence4_boundary = border ? 100.0 * static_cast<double>(border4) / static_cast<double>(border) : 0.0;
  return r;
}

void to_json(nlohmann::json& j, const QualityReport& q) {
  j = nlohmann::json{
      {"vertices", q.vertices},
      {"faces", q.faces},
      {"min_angle_deg", q.min_angle_deg},
      {"mean_min_angle_deg", q.mean_min_angle_deg},
      {"pct_min_angle_below_30", q.pct_min_angle_below_30},
      {"angle_deviation_deg", q.angle_deviation_deg},
      {"angle_variance_deg2", q.angle_variance_deg2},
      {"q_min", q.q_min},
      {"q_mean", q.q_mean},
      {"radius_ratio_min", q.radius_ratio_min},
      {"radius_ratio_mean", q.radius_ratio_mean},
      {"edge_length_mean", q.edge_length_mean},
      {"edge_length_cv", q.edge_length_cv},
      {"edge_length_variance", q.edge_length_variance},
      {"pct_valence6_interior", q.pct_valence6_interior},
      {"pct_valence4_boundary", q.pct_valence4_boundary},
      {"area_cv", q.area_cv},
  };
}

}  // namespace mrsnake
