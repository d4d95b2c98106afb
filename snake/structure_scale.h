#pragma once
/// \file structure_scale.h
/// The size of one labelled structure, and the model-building defaults derived from it. No
/// default of build-model is a fixed length: a mouse globus pallidus at 0.15 mm (1.7 mm³) and
/// a human liver at 0.6 mm (1.6 litres) get the same treatment relative to their own size
/// and voxels.
#include <array>

#include <nlohmann/json_fwd.hpp>

#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

/// What a label volume says about the size of one structure (all voxels of the label: every
/// connected part of it).
struct StructureScale {
  double finest_voxel_mm = 0;       ///< the smallest voxel side of the label volume
  double largest_voxel_mm = 0;      ///< the largest voxel side
  double volume_mm3 = 0;            ///< voxels of the label × voxel volume
  double equivalent_radius_mm = 0;  ///< radius of the sphere of that volume
  /// Bounding box of the label's voxel centres along the physical axes, grown by the largest
  /// voxel side.
  std::array<double, 3> extent_mm{0, 0, 0};
};

/// Measures the voxels equal to `label` (volume and extent 0 when there is none).
/// \throw nothing.
StructureScale measure_structure(const Volume& labels, int label);

/// How many marching-cubes cells span the equivalent radius at least: a finer label grid is
/// resampled to radius / this (the 1.6-litre liver at 0.62 mm to about 1.2 mm), a coarser
/// one is used as it is (mesh/marching_cubes.h).
constexpr double kCellsPerRadius = 60.0;

/// The marching-cubes spacing build-model uses by default: radius / kCellsPerRadius when the
/// label's finest voxel side is below that; else, for voxels longer than 1.5 times their
/// finest side along some axis (thick slices), the finest side, so that the surface has no
/// slice staircase; else 0 (the voxels' own surface).
/// \pre scale comes from measure_structure (0 for an empty label gives 0).
double default_marching_cubes_spacing(const StructureScale& scale);

/// The default finest face count: equilateral triangles whose edge is half the surface's
/// sampling length (`sampling_mm`: the marching-cubes spacing, or the finest voxel) covering
/// the area of `surface`, clamped to [min_faces, max_faces]. The levels finer than the image
/// are synthesized rather than deformed, and give the rasterization its sub-voxel shape; the
/// cap keeps a large organ's model within the snake's budget (docs/initialization.md).
/// \pre sampling_mm > 0 (otherwise max_faces).
/// \throw nothing.
int default_face_count(const TriMesh& surface, double sampling_mm, int min_faces = 1024, int max_faces = 32768);

/// Margin, per side, of the reference image crop that segment registers: this many
/// equivalent radii, so that the crop holds the structure's surroundings whatever its size
/// (docs/initialization.md gives the measurement).
constexpr double kReferenceMarginRadii = 6.0;

/// The default reference-crop margin per side: kReferenceMarginRadii equivalent radii (mm).
/// \throw nothing.
double default_reference_margin(const StructureScale& scale);

/// Keys: finest_voxel_mm, largest_voxel_mm, volume_mm3, equivalent_radius_mm, extent_mm.
void to_json(nlohmann::json& j, const StructureScale& s);

}  // namespace mrsnake
