#pragma once
/// \file image_filters_itk.h
/// ITK image filters behind plain `Volume`s. The implementation is part of mesh_itk, the mesh
/// module's ITK side (ITK bundles its own Eigen), so this header exposes nothing but
/// mesh/volume.h and std types.
#include <array>

#include "mesh/volume.h"

namespace mrsnake {

/// Gaussian smoothing with a standard deviation of sigma_mm millimetres along every axis
/// (ITK's recursive Gaussian, image spacing honoured, so anisotropic voxels are right).
/// sigma_mm <= 0 returns the input unchanged.
/// \pre volume.data.size() == volume.num_voxels(); every size >= 4 when sigma_mm > 0.
/// \throw InputError if the volume is too small for the filter.
Volume gaussian_blur(const Volume& volume, double sigma_mm);

/// Euclidean distance, in mm, from each voxel centre to the nearest centre of a voxel
/// whose value is non-zero in `mask` (0 on those voxels). Built on ITK's
/// SignedMaurerDistanceMapImageFilter with image spacing, unsquared: voxels of the mask are
/// their own contour, so the signed map's outside values are exactly this distance.
/// \pre mask has at least one non-zero voxel.
/// \throw InputError if the mask is empty.
Volume distance_to_voxels(const Volume& mask);

/// How warp_volume interpolates.
enum class Interpolation { linear, nearest };

/// Resamples `image` through a displacement field on its own grid:
/// out(p) = image(p + d(p)), where d = (dx, dy, dz) holds, per voxel, a physical
/// displacement in mm. Points that land outside the image take `padding`.
/// (ITK's WarpImageFilter.)
/// \pre dx, dy, dz have the grid of image.
Volume warp_volume(const Volume& image, const Volume& dx, const Volume& dy, const Volume& dz,
                   Interpolation interpolation, float padding);

}  // namespace mrsnake
