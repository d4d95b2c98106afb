#pragma once
/// \file sampler.h
/// Trilinear sampling of a Volume in physical space (mm): value and gradient. Plain C++,
/// no ITK, so the snake's inner loops stay inlined and fast.
#include <Eigen/Core>

#include "mesh/volume.h"

namespace mrsnake {

/// Samples a volume at physical points. Holds a reference to the volume, which must
/// outlive the sampler. Outside the image, the nearest border voxel's value is used
/// (clamped coordinates), so a search that leaves the image sees a flat profile.
class VolumeSampler {
 public:
  /// Samples are returned as scale·v + offset (an intensity normalization applied on the
  /// fly, so a large image need not be copied).
  /// \pre volume.data.size() == volume.num_voxels() and every size >= 1.
  explicit VolumeSampler(const Volume& volume, double scale = 1.0, double offset = 0.0);

  /// Continuous voxel index of a physical point.
  Eigen::Vector3d to_index(const Eigen::Vector3d& p) const { return A_ * p + b_; }

  /// Trilinear value at a physical point.
  float value(const Eigen::Vector3d& p) const { return value_at_index(to_index(p)); }

  /// Trilinear value and its exact gradient (the derivative of the trilinear interpolant)
  /// with respect to the physical position, in intensity per mm.
  float value_and_gradient(const Eigen::Vector3d& p, Eigen::Vector3d& gradient) const;

  /// Value at a continuous index (clamped to the image).
  float value_at_index(const Eigen::Vector3d& idx) const;

  /// The values at the points p + (t0 + s·dt)·direction, s = 0..count−1, each as value()
  /// gives it (rounded to float, then widened), written to out[0..count−1]; nothing when
  /// count <= 0. One call per line: the searches along the normals sample millions of points
  /// per segmentation, and here each point's index costs one multiply-add, and the clamping is
  /// skipped when the whole segment lies inside the image.
  /// \pre out holds max(count, 0) values.
  void values_along(const Eigen::Vector3d& p, const Eigen::Vector3d& direction, double t0, double dt, int count,
                    double* out) const;

  /// True when the physical point lies within the voxel centres' bounding box.
  bool inside(const Eigen::Vector3d& p) const;

  const Volume& volume() const { return *volume_; }

 private:
  const Volume* volume_;
  Eigen::Matrix3d A_;  ///< physical -> index: diag(1/spacing)·directionᵀ
  Eigen::Vector3d b_;
  Eigen::Matrix3d index_gradient_to_physical_;  ///< direction·diag(1/spacing)
  long nx_, ny_, nz_;
  double scale_ = 1.0, offset_ = 0.0;
};

}  // namespace mrsnake
