#pragma once
/// \file slices.h
/// Orthogonal slices through a volume with contours drawn over them, without OpenGL.
#include <string>
#include <vector>

#include "apps/report/canvas.h"
#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake::reports {

/// A surface drawn as its intersection with the slice plane.
struct MeshContour {
  const TriMesh* mesh = nullptr;
  Rgb color{255, 64, 64};
  std::string name;
};

/// A label volume (same grid as the image) drawn as the outline of label == value.
struct LabelContour {
  const Volume* labels = nullptr;
  float value = 1;
  Rgb color{64, 220, 64};
  std::string name;
};

/// The slice index[axis] = position of the image (nearest voxel for the grey values, the
/// exact plane for the mesh contours), shown with physical aspect ratio; the longer side
/// is `max_pixels` long. Grey levels span the 1st to 99th percentile of the whole volume.
/// \pre axis in {0, 1, 2}; the image is not empty.
Canvas slice_with_contours(const Volume& image, int axis, double position, const std::vector<MeshContour>& meshes,
                           const std::vector<LabelContour>& labels, int max_pixels = 320);

/// The continuous voxel index of the centroid of a mesh's vertices (a natural slice centre).
std::array<double, 3> mesh_centre_index(const Volume& image, const TriMesh& mesh);

}  // namespace mrsnake::reports
