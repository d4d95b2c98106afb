#pragma once
/// \file image_io.h
/// Reading and writing 3D images through ITK. The only interface is the plain `Volume`;
/// the ITK code lives in image_io.cpp, a translation unit that sees no Eigen or CGAL.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "mesh/volume.h"

namespace mrsnake {

/// Pixel type on disk for write_volume.
enum class VoxelType { uint8, int16, float32 };

/// Reads a 3D scalar image (.nii .nii.gz .nrrd .nhdr .mha .mhd .gipl .gipl.gz) or a DICOM
/// series (a folder) into a float volume with its origin, spacing and direction. A folder of
/// several series needs `series`: a series' Series Instance UID, or its id as
/// list_dicom_series gives it.
/// \throw InputError if the file is missing, unreadable, corrupt, not 3D, not scalar, or
///        has non-finite or non-positive spacing; if a folder holds several series and `series`
///        names none of them (the message lists them); if `series` is given for a file.
Volume read_volume(const std::string& path, const std::string& series = "");

/// One DICOM series of a folder: its id (the Series Instance UID, with the details that tell
/// series of one UID apart), its Series Instance UID, its file count and its Series Description
/// (empty when its first file's header cannot be read).
struct DicomSeries {
  std::string id, uid, description;
  std::size_t files = 0;
};

/// The DICOM series in a folder, as read_volume tells them apart.
/// \throw InputError if the folder cannot be read.
std::vector<DicomSeries> list_dicom_series(const std::string& dir);

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
