#pragma once
/// \file volume.h
/// A plain 3D image that crosses the line between ITK translation units and the rest
/// (ITK bundles its own Eigen, so no Eigen or ITK type may appear here).
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace mrsnake {

/// A scalar 3D image in ITK's conventions: voxel (i,j,k) is stored at
/// data[i + size[0]*(j + size[1]*k)], and its physical centre is
/// origin + direction * diag(spacing) * (i,j,k). direction is row-major 3×3.
struct Volume {
  std::array<std::size_t, 3> size{0, 0, 0};
  std::array<double, 3> spacing{1, 1, 1};
  std::array<double, 3> origin{0, 0, 0};
  std::array<double, 9> direction{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::vector<float> data;

  std::size_t num_voxels() const { return size[0] * size[1] * size[2]; }
  /// The largest voxel side, in mm.
  double max_spacing() const { return std::max({spacing[0], spacing[1], spacing[2]}); }
  std::size_t index(std::size_t i, std::size_t j, std::size_t k) const { return i + size[0] * (j + size[1] * k); }
  float& at(std::size_t i, std::size_t j, std::size_t k) { return data[index(i, j, k)]; }
  float at(std::size_t i, std::size_t j, std::size_t k) const { return data[index(i, j, k)]; }

  /// Physical position of a (possibly fractional) voxel index.
  std::array<double, 3> index_to_physical(double i, double j, double k) const {
    const double s[3] = {i * spacing[0], j * spacing[1], k * spacing[2]};
    std::array<double, 3> p{};
    for (int r = 0; r < 3; ++r)
      p[r] = origin[r] + direction[3 * r] * s[0] + direction[3 * r + 1] * s[1] + direction[3 * r + 2] * s[2];
    return p;
  }

  /// Continuous voxel index of a physical point (direction is orthonormal, so its inverse
  /// is its transpose).
  std::array<double, 3> physical_to_index(const std::array<double, 3>& p) const {
    const double d[3] = {p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]};
    std::array<double, 3> idx{};
    for (int c = 0; c < 3; ++c)
      idx[c] = (direction[c] * d[0] + direction[3 + c] * d[1] + direction[6 + c] * d[2]) / spacing[c];
    return idx;
  }
};

}  // namespace mrsnake
