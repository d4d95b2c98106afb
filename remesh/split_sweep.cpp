#include "remesh/split_sweep.h"

#include <algorithm>

namespace mrsnake {

SplitSweep::SplitSweep(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars, int min_parallel)
    : part_(X.rows(), kBand), parallel_(X.rows() >= min_parallel) {
  const int n = static_cast<int>(X.rows());
  if (n == 0) return;
  int axis = 0;
  (X.colwise().maxCoeff() - X.colwise().minCoeff()).maxCoeff(&axis);
  std::vector<double> along(n);
  for (int v = 0; v < n; ++v) along[v] = X(v, axis);
  std::vector<double> sorted = along;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double median = sorted[n / 2];
  for (int v = 0; v < n; ++v) {
    const int half = along[v] < median ? 0 : 1;
    bool inner = true;
    for (int i = stars.offset[v]; i < stars.offset[v + 1] && inner; ++i)
      for (int k = 0; k < 3; ++k) inner = inner && (along[F(stars.faces[i], k)] < median ? 0 : 1) == half;
    part_[v] = inner ? half : kBand;
  }
}

}  // namespace mrsnake
