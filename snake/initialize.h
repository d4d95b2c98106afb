#pragma once
/// \file initialize.h
/// Initial pose of the model in a new volume: a similarity from the moments of a rough
/// threshold, then (optionally) a fit of the whole coarse mesh to its own search targets,
/// which does most of the work on real images.
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "mesh/trimesh.h"
#include "mesh/volume.h"
#include "snake/deformable_surface.h"
#include "snake/registration_itk.h"

namespace mrsnake {

/// x ↦ scale·rotation·x + translation.
struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  double scale = 1.0;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return scale * (rotation * x) + translation; }
  RowMatrixX3d apply(const RowMatrixX3d& V) const;
  /// (this ∘ other)(x) = this(other(x)).
  Similarity compose(const Similarity& other) const;
  double rotation_angle_deg() const;
};

/// Volume, centroid and covariance (second central moments) of a set of voxels in physical space.
struct Moments {
  double volume = 0;  ///< mm³
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

/// Moments of the voxels where mask > 0.5.
Moments mask_moments(const Volume& mask);

/// Otsu's threshold of the voxels of `image` within the axis-aligned index box [lo, hi].
double otsu_threshold(const Volume& image, const std::array<long, 3>& lo, const std::array<long, 3>& hi);

/// The index box of `image` covering the mesh's bounding box grown by `margin` (a fraction
/// of its size) on each side, clamped to the image.
void mesh_index_box(const Volume& image, const RowMatrixX3d& V, double margin, std::array<long, 3>& lo,
                    std::array<long, 3>& hi);

/// Two-class statistics near a surface: Otsu's threshold on `smooth` (a coarser, less
/// noisy version of `image`, e.g. a pyramid level) within the box of `image` indices [lo, hi],
/// then the medians of `image`'s voxels in the box whose smooth value is above and below it.
/// The smoothing keeps Otsu from splitting the noise of a large background when the object
/// is small. What the edge force needs on a clean-contrast image, whatever the pose.
/// The medians come from at most about max_samples voxels of the box, on a regular lattice
/// (a 256³ image's box holds millions: visiting them all took 0.4 s).
struct ThresholdClasses {
  double threshold = 0;
  double upper_median = 0, lower_median = 0;
};
ThresholdClasses threshold_classes(const Volume& image, const Volume& smooth, const std::array<long, 3>& lo,
                                   const std::array<long, 3>& hi, std::size_t max_samples = 1u << 18);

struct MomentsOptions {
  double roi_margin = 0.3;            ///< the region of interest: the model's box grown by this fraction per side
  bool rotate = true;                 ///< also align principal axes (when they are well separated)
  double min_axis_separation = 0.15;  ///< relative eigenvalue gap below which axes are ambiguous
  double max_rotation_deg = 60;       ///< larger principal-axis rotations are rejected
  /// Threshold between object and background; NaN: Otsu's within the region of interest.
  double threshold = std::numeric_limits<double>::quiet_NaN();
  bool bright_object = true;  ///< the object is above the threshold
};

/// The similarity mapping the model (closed mesh in its physical pose) onto the moments of
/// the thresholded image near it: translation to the centroid, scale from the volume ratio
/// (cube root) and, if the principal axes are distinct enough in both, the rotation (the
/// sign choice closest to the identity) between them.
/// \pre model is closed and outward oriented; image is small enough to threshold (use a
///      coarse pyramid level).
/// \throw AlgorithmError if no voxel passes the threshold near the model.
Similarity moments_alignment(const Volume& image, const TriMesh& model, const MomentsOptions& options = {});

struct TargetFitOptions {
  int iterations = 30;
  bool with_scale = true;  ///< similarity (true) or rigid (false)
  /// Stop when the mean vertex motion of an iteration is below this (mm). segment sets it
  /// from SegmentOptions::fit_tolerance_voxels and the image's voxels.
  double tolerance_mm = 0.01;
  double trim_fraction = 0.2;  ///< drop the worst-matching fraction of vertices each iteration
  /// Stop once the mean search cost has not improved for this many iterations, and return
  /// the pose with the lowest cost seen (0: run on and return the last pose).
  int patience = 0;
};

/// Fits a similarity of the whole mesh to its search targets x + o·n, repeatedly (a rigid
/// or similarity "active shape" step): each iteration searches, solves the Umeyama
/// least-squares similarity from the current vertices to their targets (trimmed), and applies it.
/// Returns the total similarity; V is updated. With options.patience > 0 the pose returned
/// (and left in V) is the one whose search had the lowest mean cost, the last pose searched
/// once more to judge it; *iterations_done counts every iteration run, also those past it.
/// \throw nothing beyond what `search` throws.
Similarity fit_similarity_to_targets(RowMatrixX3d& V, const RowMatrixX3i& F, const ExternalSearch& search,
                                     const TargetFitOptions& options = {}, int* iterations_done = nullptr);

struct ReferenceRegistrationOptions {
  RegistrationOptions itk;
  double min_scale = 0.5, max_scale = 2.0;  ///< a scale outside this range is a failure
};

/// The outcome of placing the model by registering its reference image to the new one.
struct ReferenceRegistration {
  bool ran = false;           ///< ITK's registration ran to its end
  bool accepted = false;      ///< its pose is used
  std::string rejection;      ///< why not (empty when accepted)
  Similarity pose;            ///< reference space → new image (the identity when rejected)
  RegistrationResult result;  ///< ITK's outcome (when it ran)
  int pyramid_level = 0;      ///< the level of the new image's pyramid registered to
  double seconds = 0;
  /// When the start from the identity was rejected and a second start (the moments'
  /// translation) was tried: the first rejection and that start.
  std::string first_rejection;
  std::array<double, 3> retry_translation{0, 0, 0};
};

/// Registers the model's reference image (FIXED) to the new image (MOVING), on the level of
/// its pyramid whose voxel size is closest to the reference's, and judges the result: it is
/// rejected, with the reason, if ITK fails, if the metric at the result is not better than
/// at the start, or if the scale leaves [min_scale, max_scale].
/// `level0_scale`, `level0_offset` normalize pyramid[0] when it holds raw intensities.
/// `start_translation` (mm) moves the reference before the registration (default none).
/// A failed registration (ITK gave up, or the images do not overlap) is reported in the
/// result as a rejection, not thrown.
/// \pre pyramid is not empty.
ReferenceRegistration register_reference(const Volume& reference, const std::vector<const Volume*>& pyramid,
                                         double level0_scale, double level0_offset,
                                         const ReferenceRegistrationOptions& options = {},
                                         const Eigen::Vector3d& start_translation = Eigen::Vector3d::Zero());

}  // namespace mrsnake
