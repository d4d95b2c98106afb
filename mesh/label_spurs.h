#pragma once
/// \file label_spurs.h
/// The spurs of a label: voxels that hang by at most one face. Marching cubes turns a line of
/// voxels one voxel wide into a tube one voxel wide, and smoothing shrinks that tube into a
/// needle thinner than any edge of a remesh, which then cuts it off (docs/remesh.md).
#include "mesh/volume.h"

namespace mrsnake {

/// Removes the spurs of `label` (sets them to 0), repeatedly, until every voxel of the label has
/// at least two of its six face neighbours in the label: a line one voxel wide that ends in the
/// air goes back to the voxel that holds it; a line that joins two parts at both ends stays. A
/// label made of spurs only (a single line of voxels) is left as it is.
/// \return the number of voxels removed.
int remove_label_spurs(Volume& labels, int label);

}  // namespace mrsnake
