#pragma once
/// \file label_repair.h
/// Topology repair of a label in its volume (ITK morphology; plain Volume interface).
#include "mesh/volume.h"

namespace mrsnake {

/// A binary mask (1 = label, 0 = rest) of `label` after a morphological closing with a
/// ball of `radius_voxels` voxels and the filling of enclosed cavities. Closing removes
/// thin tunnels (handles), so the surface of the mask tends to genus 0.
/// \pre radius_voxels >= 0
Volume close_label(const Volume& labels, int label, int radius_voxels);

}  // namespace mrsnake
