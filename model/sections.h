#pragma once
/// \file sections.h
/// The binary sections of a model folder that the snake adds: the appearance (profiles and
/// region statistics, snake/appearance.h) and the reference image crop
/// (snake/reference_image.h). Each is little-endian, versioned and written with
/// model/byte_codec.h; docs/model-format.md gives the layouts.
#include <cstdint>
#include <vector>

#include "mesh/volume.h"
#include "snake/appearance.h"

namespace mrsnake {

/// Binary form (little-endian, versioned), for the model's optional "appearance" section.
/// Version 02 adds each level's centre (labels or edges).
std::vector<std::uint8_t> serialize_appearance(const Appearance& appearance);
/// Reads versions 01 (every level's centre ProfileCentre::unrecorded) and 02.
/// \throw InputError if the bytes are truncated, of another version or inconsistent.
Appearance deserialize_appearance(const std::vector<std::uint8_t>& bytes);

/// Binary form (little-endian, versioned, with its own FNV-1a 64 checksum).
/// \pre reference.data has reference.num_voxels() values; each size is 8..1024 (as the
///      reader requires: a larger crop would write a section its own reader refuses).
std::vector<std::uint8_t> serialize_reference_image(const Volume& reference);
/// \throw InputError if the bytes are truncated, of another format or version, altered
///        (checksum), or describe an impossible image (sizes, spacing, direction, values).
Volume deserialize_reference_image(const std::vector<std::uint8_t>& bytes);

}  // namespace mrsnake
