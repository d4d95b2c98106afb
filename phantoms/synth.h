#pragma once
/// \file synth.h
/// Synthetic volumes whose truth is known exactly: an analytic shape (an implicit function,
/// negative inside), optionally posed by a random similarity and warped by a random smooth
/// deformation, rendered with partial volume, contrast, blur, a bias field and noise. Or a
/// real image and its labels, warped alike. Everything is drawn from one seed and recorded,
/// so that the parameters alone regenerate the case bit for bit.
///
/// Geometry. A point p of the output image is mapped into the reference frame of the shape
/// (or of the source image) by M(p) = T⁻¹(p + u(p)), where u is the deformation and T the
/// similarity T(x) = c + t + s·R·(x − c) about the centre c. The object is
/// {p : φ(M(p)) < 0}; the truth label marks the voxels whose centre is inside.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "mesh/progress.h"
#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

enum class SynthShape { sphere, ellipsoid, blob, aneurysm, heart };
enum class SynthNoise { none, gaussian, rician };

/// Parses "sphere", "ellipsoid", "blob", "aneurysm", "heart".
/// \throw InputError for another name (the message lists the shapes).
SynthShape parse_synth_shape(const std::string& name);
std::string to_string(SynthShape shape);
/// Parses "none", "gaussian", "rician". \throw InputError otherwise.
SynthNoise parse_synth_noise(const std::string& name);
std::string to_string(SynthNoise noise);

/// What the user chooses. Defaults give a small, fast case.
struct SynthOptions {
  SynthShape shape = SynthShape::sphere;
  std::array<int, 3> size{64, 64, 64};           ///< voxels
  std::array<double, 3> spacing{1.0, 1.0, 1.0};  ///< mm; anisotropic allowed
  SynthNoise noise = SynthNoise::gaussian;
  /// Signal-to-noise ratio, defined as |foreground − background| / σ, σ the standard
  /// deviation of the Gaussian noise (of each channel for Rician). <= 0 means no noise.
  double snr = 10.0;
  double blur_mm = 0.5;  ///< standard deviation of the Gaussian blur in mm (0: none)
  /// Strength B of the smooth multiplicative bias field exp(B·g(x)), |g| <= 1, so the
  /// field lies within [e^−B, e^B]. 0: none.
  double bias = 0.0;
  double foreground = 200.0;  ///< intensity inside the object (the heart's cavity)
  double background = 50.0;   ///< intensity outside (the heart's wall; its surroundings
                              ///< take the mean of both)
  bool random_pose = false;   ///< random similarity: rotation <= 15°, shift <= 5% of the
                              ///< field of view, scale in [0.9, 1.1]
  double deform_mm = 0.0;     ///< largest displacement of the random smooth deformation
  std::uint64_t seed = 1;
  int supersampling = 4;  ///< partial volume: n³ samples in each boundary voxel

  /// --from-image mode: warp a real image and its label `source_label` instead of
  /// rendering a shape (the shape, contrast and supersampling are then unused).
  std::string source_image, source_labels;
  int source_label = 1;
  int source_component = 0;  ///< 0: all of the label; k >= 1: only its k-th largest connected part (keep_label_part)
  bool from_image() const { return !source_image.empty(); }
};

/// Shape parameters, drawn from the seed (only the fields of the chosen shape are used).
/// Lengths in mm, in the reference frame centred on the origin of the shape.
struct ShapeParams {
  SynthShape kind = SynthShape::sphere;
  double radius = 0;                   ///< sphere
  Eigen::Vector3d semi_axes{0, 0, 0};  ///< ellipsoid; heart: the cavity's
  // blob: r(u) = base_radius·(1 + Σ h_k·exp(κ_k·(u·n_k − 1))) for unit directions u
  double base_radius = 0;
  std::vector<Eigen::Vector3d> bump_directions;
  std::vector<double> bump_heights, bump_concentrations;
  // aneurysm: a tube of radius vessel_radius around a circular arc (radius arc_radius,
  // half-angle arc_half_angle, in the xy plane, its middle at (0, arc_offset, 0), bulging
  // towards +y), closed by round caps, merged smoothly with a spherical sac.
  double vessel_radius = 0, arc_radius = 0, arc_half_angle = 0, arc_offset = 0;
  Eigen::Vector3d sac_centre{0, 0, 0};
  double sac_radius = 0, neck_smoothing = 0;
  // heart: the cavity is the ellipsoid semi_axes cut by the base plane z = base_height
  // (rounded by rim_smoothing), the wall the same with the axes grown by wall_thickness;
  // both shifted by -z_offset along z.
  double wall_thickness = 0, base_height = 0, rim_smoothing = 0, z_offset = 0;
};

/// The similarity T(x) = centre + translation + scale·rotation·(x − centre).
struct SimilarityParams {
  Eigen::Vector3d centre{0, 0, 0};
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  double scale = 1.0;
  Eigen::Vector3d translation{0, 0, 0};
};

/// u(p) = Σ_k d_k·exp(−|p − c_k|² / (2w²)), Gaussian radial basis functions.
struct DeformationParams {
  double width_mm = 1.0;
  std::vector<Eigen::Vector3d> centres, displacements;
  Eigen::Vector3d displacement(const Eigen::Vector3d& p) const;
  /// The Jacobian of u at p.
  Eigen::Matrix3d jacobian(const Eigen::Vector3d& p) const;
};

/// exp(strength·g(x̂)), x̂ = (p − centre)/half_extent, g = Σ c_i·m_i(x̂) over the monomials
/// x, y, z, x²−1/3, y²−1/3, z²−1/3, xy, yz, zx, normalized so that |g| <= 1 on the box.
struct BiasParams {
  double strength = 0;
  Eigen::Vector3d centre{0, 0, 0}, half_extent{1, 1, 1};
  std::array<double, 9> coefficients{};
  double factor(const Eigen::Vector3d& p) const;
};

/// Everything needed to regenerate a case: the options plus every drawn value.
struct SynthParams {
  SynthOptions options;
  ShapeParams shape;
  SimilarityParams pose;
  DeformationParams deformation;
  BiasParams bias_field;
  /// Maps an output point into the reference frame: M(p) = T⁻¹(p + u(p)).
  Eigen::Vector3d to_reference(const Eigen::Vector3d& p) const;
};

/// A generated case. truth: 1 on the object (voxel centre inside), 0 elsewhere (the heart
/// marks its wall 2). truth_mesh: the object's surface, outward, in physical coordinates.
struct SynthResult {
  Volume image;
  Volume truth;
  TriMesh truth_mesh;
};

/// The label value of the object in truth volumes (recorded as "label" in params.json).
constexpr int kTruthLabel = 1;
/// The heart's wall in its truth volume.
constexpr int kWallLabel = 2;

/// Draws the shape, pose, deformation and bias from options.seed. For --from-image,
/// `source_grid` and `source_mask` (the label's voxels, non-zero) give the grid and where
/// the object is.
/// \throw InputError for invalid options (non-positive size or spacing, supersampling < 1,
///        a deformation so large that it folds, a source label with no voxel).
SynthParams draw_synth_params(const SynthOptions& options, const Volume* source_mask = nullptr);

/// The shape's implicit function in output (physical) coordinates, negative inside the
/// object. Zero exactly on the true surface.
double object_function(const SynthParams& params, const Eigen::Vector3d& p);

/// Renders an analytic case.
/// \pre !params.options.from_image()
/// \throw InputError if the object does not fit inside the image.
SynthResult render_synth(const SynthParams& params, const ProgressFn& progress = {});

/// Warps a real image and its labels through the drawn pose and deformation, then applies
/// blur, bias and noise. The truth is 1 where the trilinear interpolation of the warped
/// label mask is >= 0.5, and the truth mesh is that field's 0.5 isosurface.
/// \throw InputError if image and labels are on different grids or the label is absent.
SynthResult render_from_image(const SynthParams& params, const Volume& image, const Volume& labels,
                              const ProgressFn& progress = {});

/// params.json: every option and drawn value; key "label" holds kTruthLabel.
void to_json(nlohmann::json& j, const SynthParams& params);
/// Reads params.json back.
/// \throw InputError naming the missing or malformed key.
SynthParams synth_params_from_json(const nlohmann::json& j);

}  // namespace mrsnake
