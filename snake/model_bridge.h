#pragma once
/// \file model_bridge.h
/// The shape model on disk (wavelets/model.h) as the segmentation sees it: its levels, a
/// synthesis step from a deformed S_j with the stored details, and the optional appearance
/// section ("appearance") that build-model --image adds.
#include "mesh/volume.h"
#include "snake/appearance.h"
#include "snake/segment.h"
#include "wavelets/model.h"

namespace mrsnake {

/// Name of the model section holding the appearance.
constexpr const char* kAppearanceSection = "appearance";

/// The SnakeModel of a wavelet shape model: levels S_0..S_L (level_positions, or synthesized
/// when not loaded), synthesis by WaveletTransform::synthesize_level with the model's
/// details, and the appearance if the model has the section.
/// \throw InputError if the model has no levels or a damaged appearance section.
SnakeModel snake_model_from(const ShapeModel& model);

/// Learns the appearance of every level from the reference image (in which the model's
/// levels lie, in physical coordinates) and stores it in the model's "appearance" section.
/// \throw InputError if the image is constant.
void add_appearance(ShapeModel& model, const Volume& reference_image, const AppearanceOptions& options = {});

}  // namespace mrsnake
