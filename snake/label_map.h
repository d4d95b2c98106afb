#pragma once
/// \file label_map.h
/// One label map from the surfaces of several structures, with no voxel claimed twice.
#include <vector>

#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

/// The label map of several closed surfaces on the grid of `grid`, and what it settled.
struct StructureLabelMap {
  Volume labels;                ///< the structure's value inside it, 0 outside every surface
  std::vector<long> voxels;     ///< per structure, the voxels it holds in `labels`
  std::vector<long> contested;  ///< per structure, its voxels that another surface also enclosed
};

/// Rasterizes each surface (rasterize_mesh) and writes its value. A voxel inside two or more
/// surfaces goes to the one it lies deepest inside: the surface whose closest point is the
/// farthest from the voxel's centre. Where two overlapping structures meet, the voxels are
/// thus split along the middle of their overlap, so that neither one's volume swallows the
/// other's boundary layer. Ties go to the structure listed first.
/// \pre surfaces and values have the same size; each surface is closed, with at least one face;
///      values are positive.
/// \throw std::invalid_argument if the sizes differ.
StructureLabelMap structure_label_map(const std::vector<TriMesh>& surfaces, const std::vector<int>& values,
                                      const Volume& grid);

}  // namespace mrsnake
