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
  std::vector<Eigen::Vector2d> flat(k);
  for (int i = 0; i < k; ++i) {
    const double r = std::pow((ring[i] - center).norm(), a);
    flat[i] = r * Eigen::Vector2d(std::cos(a * phi[i]), std::sin(a * phi[i]));
  }
  return flat;
}

}  // namespace mrsnake
