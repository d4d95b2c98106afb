#include "snake/sampler.h"

#include <algorithm>
#include <cmath>

namespace mrsnake {

VolumeSampler::VolumeSampler(const Volume& volume, double scale, double offset)
    : volume_(&volume), scale_(scale), offset_(offset) {
  Eigen::Matrix3d D;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) D(r, c) = volume.direction[3 * r + c];
  const Eigen::Vector3d inv_s(1.0 / volume.spacing[0], 1.0 / volume.spacing[1], 1.0 / volume.spacing[2]);
  A_ = inv_s.asDiagonal() * D.transpose();
  b_ = -A_ * Eigen::Vector3d(volume.origin[0], volume.origin[1], volume.origin[2]);
  index_gradient_to_physical_ = D * inv_s.asDiagonal();
  nx_ = static_cast<long>(volume.size[0]);
  ny_ = static_cast<long>(volume.size[1]);
  nz_ = static_cast<long>(volume.size[2]);
}

namespace {
// Splits a continuous coordinate into a base index in [0, n-2] and a fraction in [0, 1],
// clamping to the image (n == 1 gives base 0, fraction 0 and a zero-width cell).
inline void split(double x, long n, long& i0, long& i1, double& f) {
  if (n == 1) {
    i0 = i1 = 0;
    f = 0;
    return;
  }
  x = std::clamp(x, 0.0, static_cast<double>(n - 1));
  i0 = std::min(static_cast<long>(x), n - 2);
  i1 = i0 + 1;
  f = x - static_cast<double>(i0);
}
}  // namespace

float VolumeSampler::value_at_index(const Eigen::Vector3d& idx) const {
  long i0, i1, j0, j1, k0, k1;
  double fx, fy, fz;
  split(idx.x(), nx_, i0, i1, fx);
  split(idx.y(), ny_, j0, j1, fy);
  split(idx.z(), nz_, k0, k1, fz);
  const float* d = volume_->data.data();
  const long sy = nx_, sz = nx_ * ny_;
  const double c000 = d[i0 + j0 * sy + k0 * sz], c100 = d[i1 + j0 * sy + k0 * sz];
  const double c010 = d[i0 + j1 * sy + k0 * sz], c110 = d[i1 + j1 * sy + k0 * sz];
  const double c001 = d[i0 + j0 * sy + k1 * sz], c101 = d[i1 + j0 * sy + k1 * sz];
  const double c011 = d[i0 + j1 * sy + k1 * sz], c111 = d[i1 + j1 * sy + k1 * sz];
  const double c00 = c000 + fx * (c100 - c000), c10 = c010 + fx * (c110 - c010);
  const double c01 = c001 + fx * (c101 - c001), c11 = c011 + fx * (c111 - c011);
  const double c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
  return static_cast<float>(scale_ * (c0 + fz * (c1 - c0)) + offset_);
}

float VolumeSampler::value_and_gradient(const Eigen::Vector3d& p, Eigen::Vector3d& gradient) const {
  const Eigen::Vector3d idx = to_index(p);
  long i0, i1, j0, j1, k0, k1;
  double fx, fy, fz;
  split(idx.x(), nx_, i0, i1, fx);
  split(idx.y(), ny_, j0, j1, fy);
  split(idx.z(), nz_, k0, k1, fz);
  const float* d = volume_->data.data();
  const long sy = nx_, sz = nx_ * ny_;
  const double c000 = d[i0 + j0 * sy + k0 * sz], c100 = d[i1 + j0 * sy + k0 * sz];
  const double c010 = d[i0 + j1 * sy + k0 * sz], c110 = d[i1 + j1 * sy + k0 * sz];
  const double c001 = d[i0 + j0 * sy + k1 * sz], c101 = d[i1 + j0 * sy + k1 * sz];
  const double c011 = d[i0 + j1 * sy + k1 * sz], c111 = d[i1 + j1 * sy + k1 * sz];
  const double c00 = c000 + fx * (c100 - c000), c10 = c010 + fx * (c110 - c010);
  const double c01 = c001 + fx * (c101 - c001), c11 = c011 + fx * (c111 - c011);
  const double c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
  // Derivatives of the interpolant in index space; zero along an axis that is clamped
  // outside the image or has a single voxel.
  const auto inside_axis = [](double x, long n) { return n > 1 && x >= 0.0 && x <= static_cast<double>(n - 1); };
  Eigen::Vector3d g_idx;
  {
    const double d0 = (c100 - c000) + fy * ((c110 - c010) - (c100 - c000));
    const double d1 = (c101 - c001) + fy * ((c111 - c011) - (c101 - c001));
    g_idx.x() = inside_axis(idx.x(), nx_) ? d0 + fz * (d1 - d0) : 0.0;
  }
  g_idx.y() = inside_axis(idx.y(), ny_) ? (c10 - c00) + fz * ((c11 - c01) - (c10 - c00)) : 0.0;
  g_idx.z() = inside_axis(idx.z(), nz_) ? c1 - c0 : 0.0;
  gradient = scale_ * (index_gradient_to_physical_ * g_idx);
  return static_cast<float>(scale_ * (c0 + fz * (c1 - c0)) + offset_);
}

bool VolumeSampler::inside(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d idx = to_index(p);
  return idx.x() >= 0 && idx.y() >= 0 && idx.z() >= 0 && idx.x() <= nx_ - 1 && idx.y() <= ny_ - 1 &&
         idx.z() <= nz_ - 1;
}

}  // namespace mrsnake
