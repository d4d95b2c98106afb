#pragma once
/// \file label_files.h
/// The files that name a label map's values beside it, so that it opens by name in ITK-SNAP
/// and 3D Slicer: an ITK-SNAP label description file, a Slicer colour table (.ctbl), and the
/// header fields of a Slicer segmentation (.seg.nrrd), one segment per value in one layer.
#include <string>
#include <utility>
#include <vector>

#include "mesh/image_io.h"
#include "mesh/volume.h"
#include "model/label_names.h"

namespace mrsnake {

/// One value of a label map and its name and colour.
struct NamedValue {
  int value = 1;
  LabelName label;
};

/// An ITK-SNAP label description file: its header, the clear label 0, then a row
/// `VALUE R G B 1 1 1 "NAME"` per value (a quote in a name becomes an apostrophe).
std::string itksnap_label_description(const std::vector<NamedValue>& values);

/// A 3D Slicer colour table (.ctbl): `0 Background 0 0 0 0`, then `VALUE NAME R G B 255` per
/// value; Slicer splits a row on spaces, so spaces in a name become underscores.
std::string slicer_color_table(const std::vector<NamedValue>& values);

/// The key/value fields of a Slicer segmentation of the label map `labels`: every value a
/// segment of layer 0 with its ID `Segment_VALUE`, name, colour (0..1), label value and
/// voxel extent (`0 -1 0 -1 0 -1` when it holds no voxel), and the segmentation's fields
/// (binary labelmap as the source representation).
/// \pre labels.data.size() == labels.num_voxels()
std::vector<std::pair<std::string, std::string>> slicer_segmentation_fields(const std::vector<NamedValue>& values,
                                                                            const Volume& labels);

/// Every non-zero value of `labels`, in increasing order, with its default name and colour.
std::vector<NamedValue> numbered_values(const Volume& labels);

/// Writes the label map `labels` as DIR/STEM.nii.gz and, naming its values, DIR/STEM.seg.nrrd
/// (the same voxels with slicer_segmentation_fields), DIR/STEM.ctbl and DIR/STEM.itksnap.txt.
/// \pre labels.data.size() == labels.num_voxels(); `values` lists every non-zero value once.
/// \throw OutputError if a file cannot be written.
void write_named_label_map(const std::string& dir, const std::string& stem, const Volume& labels,
                           const std::vector<NamedValue>& values, VoxelType type);

}  // namespace mrsnake
