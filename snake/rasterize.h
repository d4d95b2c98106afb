#pragma once
/// \file rasterize.h
/// Closed surface → label volume on a given grid.
#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

/// Marks with `label` every voxel of `grid`'s lattice whose centre lies inside the closed
/// mesh, 0 elsewhere. Works in the grid's continuous index space (origin, spacing and an
/// oblique direction matrix honoured): along each row of voxel centres parallel to the
/// first index axis, the crossings with the triangles are sorted and the voxels between
/// pairs of crossings filled (parity rule, so orientation does not matter). Rows pass a
/// tiny fixed offset away from lattice lines so that they never hit an edge exactly.
/// The output has grid's geometry and no copy of its data beyond the labels.
/// \pre the mesh is closed (every row crosses it an even number of times); a row with an
///      odd count (an open mesh) is left empty rather than filled wrongly.
Volume rasterize_mesh(const TriMesh& mesh, const Volume& grid, float label = 1.0f);

}  // namespace mrsnake
