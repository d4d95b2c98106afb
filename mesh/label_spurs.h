#pragma once
/// \file label_spurs.h
/// The spurs of a label: voxels that hang by at most one face. Marching cubes turns a line of
/// voxels one voxel wide into a tube one voxel wide, and smoothing shrinks that tube into a
/// needle thinner than any edge of a remesh, which then cuts it off (docs/remesh.md).
#include <cstddef>
#include <vector>

#include "mesh/volume.h"

namespace mrsnake {

/// The spurs of `label`: the voxels that go when voxels of the label with at most one of their
/// six face neighbours in the label are removed, again until every voxel left has two. A line
/// one voxel wide that ends in the air goes back to the voxel that holds it; a line that joins
/// two parts at both ends stays. A label made of spurs only (a single line of voxels) has none,
/// so that it is kept whole; so has the background (label 0).
/// \return their indices into labels.data, in the order they go.
std::vector<std::size_t> label_spurs(const Volume& labels, int label);

/// Sets the spurs of `label` (label_spurs()) to 0.
/// \return the number of voxels removed.
int remove_label_spurs(Volume& labels, int label);

}  // namespace mrsnake
