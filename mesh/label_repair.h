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

/// The labels with `label` kept on one of its connected parts only: the `rank`-th largest
/// (rank 1 = the largest; parts of the same size in the order of their first voxel). Its
/// other parts become background (0); other labels are untouched. A label whose voxels form
/// two organs (a left and a right caudate) is modelled and scored one organ at a time.
/// Parts are face-connected (6-neighbourhood), as marching cubes separates them.
/// \pre rank >= 1
/// \throw InputError if `label` has no voxel, or fewer than `rank` parts.
Volume keep_label_part(const Volume& labels, int label, int rank);

}  // namespace mrsnake
