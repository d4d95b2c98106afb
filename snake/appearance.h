#pragma once
/// \file appearance.h
/// What the organ looks like in the reference image, stored with the model: per level, the
/// intensity profile along the normal at each vertex (as in active shape models), and the
/// intensity statistics inside the object and in a shell outside it. Intensities are those
/// of the robustly normalized image (image_pyramid.h), so they compare across scans.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "mesh/trimesh.h"
#include "mesh/volume.h"
#include "snake/forces.h"

namespace mrsnake {

/// Where a level's learned profiles are centred along the normals.
enum class ProfileCentre {
  labels,  ///< on the label's surface
  /// On the image's edges (ProfileAlignment::edges): then they locate the object's boundary
  /// below the label's rounding, and the segmentation deforms the level even when it is finer
  /// than the image (segment.h).
  edges,
  /// Not recorded (appearance format 01, whose profiles may sit on either); treated as labels.
  unrecorded,
};
/// "labels", "edges" or "unrecorded".
std::string to_string(ProfileCentre centre);

/// The profiles of one level of the hierarchy.
struct LevelAppearance {
  double spacing_mm = 1;     ///< distance between profile samples (the pyramid voxel size used)
  Eigen::MatrixXf profiles;  ///< n_j × K, sample k at offset (k − K/2)·spacing_mm along the normal
  ProfileCentre centre = ProfileCentre::labels;
};

struct Appearance {
  int half_length = 5;  ///< K = 2·half_length + 1 samples per profile
  std::vector<LevelAppearance> levels;
  RegionStats region;                            ///< medians inside and in a shell outside (normalized units)
  double inside_spread = 0, outside_spread = 0;  ///< robust spreads (1.4826·MAD)
  double shell_mm = 0;                           ///< thickness of the shells the statistics come from
};

/// Where each learned profile is centred along its normal.
enum class ProfileAlignment {
  /// edges when the profiles are clean steps (profile_step_residual at most
  /// AppearanceOptions::clean_edge_max_residual), labels otherwise.
  automatic,
  /// On the image's edge near the vertex. The model's surface comes from a binary label,
  /// whose boundary lies up to half a voxel from the object's true boundary, coherently over
  /// a flat, axis-aligned region (the synthetic heart's flat base lay 0.11 mm inside on its
  /// 128³ model, and 0.21 mm inside on the segmentations, which inherited it through the profiles).
  edges,
  /// On the label's surface: the labels define the boundary. On real images an expert's
  /// boundary need not be the intensity midpoint (aligning to edges lowered the Dice of the
  /// real liver 0.9722 → 0.9662 and the left hippocampus 0.9531 → 0.9143).
  labels,
};

struct AppearanceOptions {
  int half_length = 5;
  double shell_voxels = 3;  ///< statistics shell thickness, in voxels of the full-resolution image
  ProfileAlignment alignment = ProfileAlignment::automatic;
  /// automatic: the largest step residual of profiles still taken for a clean step (between
  /// the residuals of synthetic phantoms and of real images; docs/snake.md).
  double clean_edge_max_residual = 0.5;
  /// edges: the largest shift of a profile's centre, in voxel steps of the full-resolution
  /// image along the vertex normal (the largest axis step projected on it: a label's rounding
  /// moves its boundary by at most half of that).
  double max_alignment_voxels = 0.5;
};

/// What build_appearance did about ProfileAlignment.
struct ProfileAlignmentReport {
  bool to_edges = false;     ///< the profiles were centred on the image's edges
  double step_residual = 0;  ///< profile_step_residual of the profiles at the label's surface
  int levels_aligned = 0;    ///< levels whose profiles use the full-resolution image (only these move)
  double mean_shift_mm = 0;  ///< over the vertices of the aligned levels, + outwards
  double mean_abs_shift_mm = 0;
};

/// Picks the pyramid level for a mesh level: the one whose largest voxel size is closest
/// (in log scale) to edge_mm / edge_per_voxel.
/// \pre pyramid_spacings is not empty.
int pyramid_level_for_edge(double edge_mm, const std::vector<double>& pyramid_spacings, double edge_per_voxel = 2.0);

/// Mean edge length of a mesh.
double mean_edge_length(const RowMatrixX3d& V, const RowMatrixX3i& F);

/// Learns the appearance of every level S_j (faces F_j, in the reference image's physical
/// space) from the normalized reference image's pyramid (pyramid[0] full resolution).
/// With ProfileAlignment::edges (or automatic on clean steps), the profiles of the levels
/// sampled at full resolution are centred on the image's edge: per vertex, the crossing of
/// the mid level between the samples two steps in and out on its closed 1-ring's mean
/// profile, averaged once over the ring and clamped to max_alignment_voxels (none with
/// half_length < 2). What was done goes to *alignment when given.
/// \pre levels.size() == faces.size(); pyramid not empty.
Appearance build_appearance(const std::vector<Volume>& pyramid, const std::vector<RowMatrixX3d>& levels,
                            const std::vector<RowMatrixX3i>& faces, const AppearanceOptions& options = {},
                            ProfileAlignmentReport* alignment = nullptr);

/// Parses "auto", "edges" or "labels".
/// \throw InputError for any other name.
ProfileAlignment parse_profile_alignment(const std::string& name);
/// Keys: centred_on ("edges" or "labels"), step_residual (null when infinite: no contrast),
/// levels_aligned, mean_shift_mm, mean_abs_shift_mm.
void to_json(nlohmann::json& j, const ProfileAlignmentReport& r);

/// How far the learned profiles are from a clean step between the region medians: per
/// vertex of level j (faces[j]), the mean profile of its closed 1-ring (so that the reference
/// image's noise averages out) against the ideal step (region.inside before the surface,
/// region.outside after it, their mean on it), as an RMS difference over the contrast
/// |inside − outside|; the result is the largest, over the levels, of its 90th percentile.
/// \return +infinity if there is no contrast, or faces do not match the levels.
double profile_step_residual(const Appearance& appearance, const std::vector<RowMatrixX3i>& faces);

/// Summary for reports: levels, samples per profile, region statistics, and per level the
/// profile spacing and where the profiles are centred ("edges", "labels", or "unrecorded").
void to_json(nlohmann::json& j, const Appearance& a);

}  // namespace mrsnake
