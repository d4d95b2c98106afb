#pragma once
/// \file snake_adapter.h
/// The shape model on disk (model/shape_model.h) as the segmentation sees it: its levels, a
/// synthesis step from a deformed S_j with the stored details, and the optional appearance
/// section ("appearance") that build-model --image adds.
#include <cstdint>
#include <vector>

#include "mesh/volume.h"
#include "snake/appearance.h"
#include "snake/reference_image.h"
#include "snake/segment.h"
#include "model/model_set.h"
#include "model/shape_model.h"

namespace mrsnake {

/// Name of the model section holding the appearance.
constexpr const char* kAppearanceSection = "appearance";

/// The SnakeModel of a wavelet shape model: levels S_0..S_L (level_positions, or synthesized
/// when not loaded), synthesis by WaveletTransform::synthesize_level with the model's
/// details, the appearance and the reference image if the model has their sections.
/// \throw InputError if the model has no levels or a damaged appearance or reference image section.
SnakeModel snake_model_from(const ShapeModel& model);

/// The SnakeModel of every structure of a model, in its order; each carries the shared
/// reference crop when the model has one (decoded once), else its own.
/// \throw InputError as snake_model_from does.
std::vector<SnakeModel> snake_models_from(const ModelSet& set);

/// Learns the appearance of every level from the reference image (in which the model's
/// levels lie, in physical coordinates) and stores it in the model's "appearance" section.
/// \return what was done about the profiles' alignment (AppearanceOptions::alignment).
/// \throw InputError if the image is constant.
ProfileAlignmentReport add_appearance(ShapeModel& model, const Volume& reference_image,
                                      const AppearanceOptions& options = {});

/// Stores the robustly normalized crop of the reference image around the model's finest
/// level (snake/reference_image.h) in the model's "reference_image" section, for
/// `segment --init register`.
/// \throw InputError if the image is constant or does not hold the model.
void add_reference_image(ShapeModel& model, const Volume& reference_image, const ReferenceImageOptions& options = {});

/// The reference_image section's bytes for a crop of `reference_image` around the points
/// V (every structure's finest level, stacked), normalized by the whole image's robust window.
/// \throw InputError if the image is constant or does not hold the points.
std::vector<std::uint8_t> reference_image_section(const Volume& reference_image, const RowMatrixX3d& V,
                                                  const ReferenceImageOptions& options = {});

}  // namespace mrsnake
