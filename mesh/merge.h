#pragma once
/// \file merge.h
/// Several meshes as one, side by side (no vertex shared between them).
#include <vector>

#include "mesh/trimesh.h"

namespace mrsnake {

/// The meshes' vertices and faces one after another, each mesh's face indices offset by the
/// vertices before it.
/// \pre every pointer is non-null.
TriMesh merged_meshes(const std::vector<const TriMesh*>& meshes);

}  // namespace mrsnake
