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
  // (NaN goes to 0: a cast of NaN to an integer is undefined.)
  x = x > 0.0 ? std::min(x, static_cast<double>(n - 1)) : 0.0;
  i0 = std::min(static_cast<long>(x), n - 2);
  i1 = i0 + 1;
  f = x - static_cast<double>(i0);
}
}  // namespace

// The voxel cell around a continuous index, blended along x and y: what both the value
// and its gradient are made of.
namespace {
struct TrilinearCell {
  double fx, fy, fz;
  double c000, c100, c010, c110, c001, c101, c011, c111;  // corner values
  double c00, c10, c01, c11, c0, c1;                      // blends along x, then y
  double value() const { return c0 + fz * (c1 - c0); }
};

inline TrilinearCell trilinear_cell(const float* d, long nx, long ny, long nz, const Eigen::Vector3d& idx) {
  TrilinearCell c;
  long i0, i1, j0, j1, k0, k1;
  split(idx.x(), nx, i0, i1, c.fx);
  split(idx.y(), ny, j0, j1, c.fy);
  split(idx.z(), nz, k0, k1, c.fz);
  const long sy = nx, sz = nx * ny;
  c.c000 = d[i0 + j0 * sy + k0 * sz], c.c100 = d[i1 + j0 * sy + k0 * sz];
  c.c010 = d[i0 + j1 * sy + k0 * sz], c.c110 = d[i1 + j1 * sy + k0 * sz];
  c.c001 = d[i0 + j0 * sy + k1 * sz], c.c101 = d[i1 + j0 * sy + k1 * sz];
  c.c011 = d[i0 + j1 * sy + k1 * sz], c.c111 = d[i1 + j1 * sy + k1 * sz];
  c.c00 = c.c000 + c.fx * (c.c100 - c.c000), c.c10 = c.c010 + c.fx * (c.c110 - c.c010);
  c.c01 = c.c001 + c.fx * (c.c101 - c.c001), c.c11 = c.c011 + c.fx * (c.c111 - c.c011);
  c.c0 = c.c00 + c.fy * (c.c10 - c.c00), c.c1 = c.c01 + c.fy * (c.c11 - c.c01);
  return c;
}
}  // namespace

float VolumeSampler::value_at_index(const Eigen::Vector3d& idx) const {
  const TrilinearCell c = trilinear_cell(volume_->data.data(), nx_, ny_, nz_, idx);
  return static_cast<float>(scale_ * c.value() + offset_);
}

void VolumeSampler::values_along(const Eigen::Vector3d& p, const Eigen::Vector3d& direction, double t0, double dt,
                                 int count, double* out) const {
  if (count <= 0) return;
  const Eigen::Vector3d start = to_index(p), step = A_ * direction;
  const Eigen::Vector3d first = start + t0 * step, last = start + (t0 + (count - 1) * dt) * step;
  // Inside the cells of the image on every axis at both ends, so at every point between them
  // (a segment is convex): the base index needs no clamping. An axis of one voxel always clamps.
  const auto within = [](double a, double b, long n) {
    return n > 1 && a >= 0.0 && b >= 0.0 && a < static_cast<double>(n - 1) && b < static_cast<double>(n - 1);
  };
  const float* d = volume_->data.data();
  if (!(within(first.x(), last.x(), nx_) && within(first.y(), last.y(), ny_) && within(first.z(), last.z(), nz_))) {
    for (int s = 0; s < count; ++s) out[s] = value_at_index(start + (t0 + s * dt) * step);
    return;
  }
  const long sy = nx_, sz = nx_ * ny_;
  for (int s = 0; s < count; ++s) {
    const Eigen::Vector3d idx = start + (t0 + s * dt) * step;
    // As trilinear_cell, without the clamps: 0 <= idx < n − 1 on each axis. (The min keeps the
    // cell inside should a point round differently from the ends, e.g. with fused multiply-adds.)
    const long i = std::min(static_cast<long>(idx.x()), nx_ - 2), j = std::min(static_cast<long>(idx.y()), ny_ - 2),
               k = std::min(static_cast<long>(idx.z()), nz_ - 2);
    const double fx = idx.x() - static_cast<double>(i), fy = idx.y() - static_cast<double>(j),
                 fz = idx.z() - static_cast<double>(k);
    const float* c = d + i + j * sy + k * sz;
    const double c000 = c[0], c100 = c[1], c010 = c[sy], c110 = c[sy + 1];
    const double c001 = c[sz], c101 = c[sz + 1], c011 = c[sz + sy], c111 = c[sz + sy + 1];
    const double c00 = c000 + fx * (c100 - c000), c10 = c010 + fx * (c110 - c010);
    const double c01 = c001 + fx * (c101 - c001), c11 = c011 + fx * (c111 - c011);
    const double c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    out[s] = static_cast<float>(scale_ * (c0 + fz * (c1 - c0)) + offset_);
  }
}

float VolumeSampler::value_and_gradient(const Eigen::Vector3d& p, Eigen::Vector3d& gradient) const {
  const Eigen::Vector3d idx = to_index(p);
  const TrilinearCell c = trilinear_cell(volume_->data.data(), nx_, ny_, nz_, idx);
  // Derivatives of the interpolant in index space; zero along an axis that is clamped
  // outside the image or has a single voxel.
  const auto inside_axis = [](double x, long n) { return n > 1 && x >= 0.0 && x <= static_cast<double>(n - 1); };
  Eigen::Vector3d g_idx;
  {
    const double d0 = (c.c100 - c.c000) + c.fy * ((c.c110 - c.c010) - (c.c100 - c.c000));
    const double d1 = (c.c101 - c.c001) + c.fy * ((c.c111 - c.c011) - (c.c101 - c.c001));
    g_idx.x() = inside_axis(idx.x(), nx_) ? d0 + c.fz * (d1 - d0) : 0.0;
  }
  g_idx.y() = inside_axis(idx.y(), ny_) ? (c.c10 - c.c00) + c.fz * ((c.c11 - c.c01) - (c.c10 - c.c00)) : 0.0;
  g_idx.z() = inside_axis(idx.z(), nz_) ? c.c1 - c.c0 : 0.0;
  gradient = scale_ * (index_gradient_to_physical_ * g_idx);
  return static_cast<float>(scale_ * c.value() + offset_);
}

bool VolumeSampler::inside(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d idx = to_index(p);
  return idx.x() >= 0 && idx.y() >= 0 && idx.z() >= 0 && idx.x() <= nx_ - 1 && idx.y() <= ny_ - 1 && idx.z() <= nz_ - 1;
}

}  // namespace mrsnake
