#pragma once
/// \file reference_image.h
/// The model's reference image: a crop of the (robustly normalized) image the model was
/// built from, around the organ with a margin, box-averaged down so that it stays small,
/// with its physical frame. `segment --init register` registers it to a new image
/// (snake/registration_itk.h) to place the model. Stored as the model section
/// "reference_image" (layout in docs/model-format.md).
#include <cstdint>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

/// Name of the model section holding the reference image.
constexpr const char* kReferenceImageSection = "reference_image";

struct ReferenceImageOptions {
  double margin_mm = 20;         ///< around the organ's bounding box, per side
  int max_voxels_per_axis = 72;  ///< box-average by an integer factor per axis to stay within this
};

/// The crop of `image` around the points V (the model's finest level, in the image's
/// physical space): their bounding box grown by margin_mm, clamped to the image, then
/// averaged over blocks of f_a voxels along axis a, f_a = ceil(size_a / max_voxels_per_axis).
/// The result lies in the same physical place (its origin is the first block's centre).
/// \pre image.data has image.num_voxels() values; V is not empty.
/// \throw InputError if the points miss the image or the crop has fewer than 8 voxels along an axis.
Volume make_reference_crop(const Volume& image, const RowMatrixX3d& V, const ReferenceImageOptions& options = {});

/// Summary for reports: size, spacing, origin, extent, voxel count.
void reference_image_to_json(nlohmann::json& j, const Volume& reference);

}  // namespace mrsnake
