#pragma once
/// \file marching_cubes.h
/// Surfaces from volumes (VTK flying edges), in physical coordinates: the image origin,
/// spacing and direction matrix are applied to the output vertices.
#include <string>
#include <vector>

#include "mesh/progress.h"
#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

struct LabelSurfaceOptions {
  int smoothing_iterations = 0;  ///< windowed-sinc iterations (volume-preserving); 0 = none
  double smoothing_passband = 0.1;
  bool keep_largest_component = true;
  /// When the surface is not genus 0, retry after closing the label (label_repair.h) with
  /// radii 1..max_closing_radius voxels until it is. 0 = no repair.
  int max_closing_radius = 0;
  /// > 0: extract the 0.5 isosurface (flying edges) of the label's Gaussian-smoothed
  /// occupancy resampled to this isotropic spacing in mm (mesh/label_resample.h) instead of
  /// the voxels' own surface: no staircase, and a surface whose size follows the spacing
  /// rather than the image's resolution. 0 = the voxels' surface (discrete flying edges).
  double resample_spacing_mm = 0;
  /// Remove the label's spurs first (label_spurs.h): voxels hanging by at most one face,
  /// which smoothing would turn into needles.
  bool remove_spurs = false;
};

/// What was extracted, with anything worth a warning.
struct LabelSurface {
  TriMesh mesh;
  int components_found = 0;                  ///< connected components before keeping the largest
  std::vector<int> dropped_component_faces;  ///< face counts of the dropped components
  int genus_before_repair = 0;               ///< genus of the surface of the label as given
  int closing_radius = 0;                    ///< closing radius (voxels) that made it genus 0; 0 = none
  int spur_voxels_removed = 0;               ///< voxels removed as spurs (LabelSurfaceOptions::remove_spurs)
};

/// Extracts the surface of the voxels equal to `label` with discrete flying edges (or of their
/// resampled occupancy, see LabelSurfaceOptions::resample_spacing_mm), oriented outward,
/// optionally smoothed, keeping the largest component; with options.remove_spurs, of the
/// label without its spurs.
/// \throw InputError if no voxel has the label (message lists the labels present), or if
///        the surface is empty.
LabelSurface extract_label_surface(const Volume& labels, int label, const LabelSurfaceOptions& options = {},
                                   const ProgressFn& progress = {});

/// The isosurface field == iso of a continuous field, oriented so that normals point to
/// increasing values... unless `inside_is_greater`, in which case outward means decreasing.
/// \throw InputError if the surface is empty.
TriMesh extract_isosurface(const Volume& field, double iso, bool inside_is_greater = true);

/// Enclosed volume of a closed, outward-oriented mesh (divergence theorem).
double enclosed_volume(const TriMesh& mesh);

}  // namespace mrsnake
