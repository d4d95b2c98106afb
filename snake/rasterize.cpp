#include "snake/rasterize.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mrsnake {

Volume rasterize_mesh(const TriMesh& mesh, const Volume& grid, float label) {
  Volume out;
  out.size = grid.size;
  out.spacing = grid.spacing;
  out.origin = grid.origin;
  out.direction = grid.direction;
  out.data.assign(out.num_voxels(), 0.0f);
  if (mesh.empty() || out.num_voxels() == 0) return out;

  const long nx = static_cast<long>(grid.size[0]), ny = static_cast<long>(grid.size[1]),
             nz = static_cast<long>(grid.size[2]);
  std::vector<Eigen::Vector3d> P(mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const auto idx = grid.physical_to_index({mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)});
    P[v] = Eigen::Vector3d(idx[0], idx[1], idx[2]);
  }
  // Rows are at (j + e1, k + e2): irrational-looking offsets far below a voxel, so that
  // exact hits on triangle edges have probability zero for real data.
  constexpr double e1 = 1.2345e-7, e2 = 2.7182e-7;
  std::vector<std::vector<double>> crossings(static_cast<std::size_t>(ny * nz));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d& a = P[mesh.F(f, 0)];
    const Eigen::Vector3d& b = P[mesh.F(f, 1)];
    const Eigen::Vector3d& c = P[mesh.F(f, 2)];
    const double ymin = std::min({a.y(), b.y(), c.y()}), ymax = std::max({a.y(), b.y(), c.y()});
    const double zmin = std::min({a.z(), b.z(), c.z()}), zmax = std::max({a.z(), b.z(), c.z()});
    const long j0 = std::max(0L, static_cast<long>(std::ceil(ymin - e1))),
               j1 = std::min(ny - 1, static_cast<long>(std::floor(ymax - e1)));
    const long k0 = std::max(0L, static_cast<long>(std::ceil(zmin - e2))),
               k1 = std::min(nz - 1, static_cast<long>(std::floor(zmax - e2)));
    if (j0 > j1 || k0 > k1) continue;
    // 2D barycentric coordinates in the (y, z) projection.
    const double det = (b.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (b.z() - a.z());
    if (det == 0.0) continue;  // edge-on triangle: rows never cross it
    for (long k = k0; k <= k1; ++k) {
      const double z = static_cast<double>(k) + e2;
      for (long j = j0; j <= j1; ++j) {
        const double y = static_cast<double>(j) + e1;
        const double wb = ((y - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (z - a.z())) / det;
        const double wc = ((b.y() - a.y()) * (z - a.z()) - (y - a.y()) * (b.z() - a.z())) / det;
        const double wa = 1.0 - wb - wc;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        crossings[static_cast<std::size_t>(j + ny * k)].push_back(wa * a.x() + wb * b.x() + wc * c.x());
      }
    }
  }
  for (long k = 0; k < nz; ++k)
    for (long j = 0; j < ny; ++j) {
      auto& xs = crossings[static_cast<std::size_t>(j + ny * k)];
      if (xs.empty() || xs.size() % 2 != 0) continue;
      std::sort(xs.begin(), xs.end());
      float* row = &out.data[out.index(0, static_cast<std::size_t>(j), static_cast<std::size_t>(k))];
      for (std::size_t p = 0; p + 1 < xs.size(); p += 2) {
        const long i0 = std::max(0L, static_cast<long>(std::ceil(xs[p])));
        const long i1 = std::min(nx - 1, static_cast<long>(std::floor(xs[p + 1])));
        for (long i = i0; i <= i1; ++i) row[i] = label;
      }
    }
  return out;
}

}  // namespace mrsnake
