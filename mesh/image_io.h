#pragma once
/// \file image_io.h
/// Reading and writing 3D images through ITK. The only interface is the plain `Volume`;
/// the ITK code lives in image_io.cpp, a translation unit that sees no Eigen or CGAL.
#include <string>
#include <utility>
#include <vector>

#include "mesh/volume.h"

namespace mrsnake {

/// Pixel type on disk for write_volume.
enum class VoxelType { uint8, int16, float32 };

/// Reads a 3D scalar image (.nii .nii.gz .nrrd .nhdr .mha .mhd .gipl .gipl.gz) or a DICOM
/// series (a folder) into a float volume with its origin, spacing and direction.
/// \throw InputError if the file is missing, unreadable, corrupt, not 3D, not scalar, or
///        has non-finite or non-positive spacing.
Volume read_volume(const std::string& path);

/// Writes a volume; the format follows the extension (.nii.gz for labels and images).
/// Written to a temporary name first and renamed into place.
/// \pre volume.data.size() == volume.num_voxels()
/// \throw OutputError if it cannot be written.
void write_volume(const std::string& path, const Volume& volume, VoxelType type);

/// Writes a volume as write_volume does, with `fields` as key/value pairs of its header (NRRD
/// writes each as a `key:=value` line; formats without such pairs drop them).
/// \pre volume.data.size() == volume.num_voxels(); no key or value holds a line break.
/// \throw OutputError if it cannot be written.
void write_volume(const std::string& path, const Volume& volume, VoxelType type,
                  const std::vector<std::pair<std::string, std::string>>& fields);

}  // namespace mrsnake
