#include "remesh/lift.h"

#include "mesh/parallel.h"

namespace mrsnake {

RowMatrixX3d lift_to_surface(const DomainMesh& param, const RowMatrixX3d& surface_V, const RowMatrixX3d& U,
                             std::vector<int>& hints) {
  RowMatrixX3d X(U.rows(), 3);
  const auto& F = param.faces();
  // Each point walks from its own hint: independent, so in parallel.
  parallel_ranges(static_cast<std::size_t>(U.rows()), [&](std::size_t begin, std::size_t end) {
    for (auto v = static_cast<Eigen::Index>(begin); v < static_cast<Eigen::Index>(end); ++v) {
      const DomainMesh::Location loc = param.locate(U.row(v).transpose(), hints[v]);
      hints[v] = loc.face;
      X.row(v) = lift_location(surface_V, F, loc).transpose();
    }
  });
  return X;
}

}  // namespace mrsnake
