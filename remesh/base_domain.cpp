#include "remesh/base_domain.h"

#include <cmath>

#include <Eigen/Geometry>

namespace mrsnake {

std::vector<Eigen::Vector2d> flatten_star(const Eigen::Vector3d& center, const std::vector<Eigen::Vector3d>& ring,
                                          bool closed) {
  const int k = static_cast<int>(ring.size());
  const int wedges = closed ? k : k - 1;
  std::vector<double> phi(k, 0.0);
  double total = 0;
  for (int i = 0; i < wedges; ++i) {
    const Eigen::Vector3d a = ring[i] - center, b = ring[(i + 1) % k] - center;
    // atan2 of |a×b| and a·b: accurate for angles near 0 and π, where acos is not.
    total += std::atan2(a.cross(b).norm(), a.dot(b));
    if (i + 1 < k) phi[i + 1] = total;
  }
  const double a = (closed ? 2 * M_PI : M_PI) / total;
  // Radii relative to their mean before the power, so that the chart keeps the star's size
  // and a sharp tip (a large a) does not underflow: a scaling does not change the shapes.
  double mean_radius = 0;
  for (const Eigen::Vector3d& r : ring) mean_radius += (r - center).norm() / k;
  std::vector<Eigen::Vector2d> flat(k);
  for (int i = 0; i < k; ++i) {
    const double r = mean_radius * std::pow((ring[i] - center).norm() / mean_radius, a);
    flat[i] = r * Eigen::Vector2d(std::cos(a * phi[i]), std::sin(a * phi[i]));
  }
  return flat;
}

}  // namespace mrsnake
