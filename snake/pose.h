#pragma once
/// \file pose.h
/// The start of the segmentation (segment.h): the pose of the model's coarse mesh in the
/// image, by the route of InitMode (registration of the model's reference image, moments of
/// a rough threshold, a similarity fit to the search targets), and the two-class statistics
/// of the step-edge force. The building blocks are in initialize.h.
#include <optional>
#include <string>
#include <vector>

#include "snake/image_pyramid.h"
#include "snake/initialize.h"
#include "snake/level_search.h"
#include "snake/segment.h"

namespace mrsnake {

/// The route `mode` names for `model`: automatic is register+fit when the model has a
/// reference image, else moments+fit; the others are themselves.
InitMode resolve_init_mode(InitMode mode, const SnakeModel& model);

/// True for the routes that start with the registration (register, register+fit).
bool registers(InitMode mode);

/// The moments' similarity of a mid-resolution model level (at most level 2) to a coarse
/// pyramid level (at most level 2: noise averaged out). With the model's appearance and no
/// threshold given, the threshold sits towards the inside class (70 % of the way from the
/// outside's intensity), so that a neighbour of intermediate intensity stays out.
/// \throw AlgorithmError if nothing passes the threshold near the model.
Similarity model_moments_pose(const SnakeModel& model, const NormalizedPyramid& pyramid, const MomentsOptions& options);

/// Registers the model's reference image to the image, from the model's pose; if that is
/// rejected and the moments' translation of the model's centroid exceeds half a reference
/// voxel, once more from that translation (the times add up; the first rejection is kept).
/// `mode` names the route asked for, for the message.
/// \throw InputError if the model has no reference image.
ReferenceRegistration register_model_reference(const SnakeModel& model, const NormalizedPyramid& pyramid, InitMode mode,
                                               const ReferenceRegistrationOptions& options,
                                               const MomentsOptions& moments);

/// One start of the similarity fit, and its name in the report.
struct FitStart {
  Similarity pose;
  std::string name;
};

/// Start hypotheses for the fit: the pose found, and the same without its rotation about
/// the centroid of `level0` (principal axes can mislead on elongated or curved shapes),
/// unless registered. After moments+fit, the model's own pose too: a neighbour of the organ's
/// intensity (the liver's kidney, the hippocampus' grey matter) drags the threshold's moments
/// far off, while scans of a study are usually framed like the reference.
std::vector<FitStart> fit_starts(const Similarity& pose, InitMode mode, bool registered, const RowMatrixX3d& level0);

/// Two classes near the surface V, at full resolution: independent of how well the surface
/// is placed, so a poor start cannot teach the force the wrong contrast. Inside is the upper
/// class unless `appearance` learned a dark object.
RegionStats threshold_region_stats(const NormalizedPyramid& pyramid, const RowMatrixX3d& V,
                                   const Appearance* appearance);

/// The fit's outcome: the pose (the start's composed with the fit's), its iterations and
/// the start it came from.
struct FittedPose {
  Similarity pose;
  int iterations = 0;
  std::string start;  ///< empty when no start gave a finite cost
};

/// Fits the mesh (V, F) from every start (fit_similarity_to_targets) and keeps the one with
/// the lowest mean search cost at its end (every start is scored with the same search).
/// Without a finite cost, the first start's pose, without iterations or name.
/// \pre starts is not empty.
FittedPose best_fitted_pose(const std::vector<FitStart>& starts, const RowMatrixX3d& V, const RowMatrixX3i& F,
                            const ExternalSearch& search, const TargetFitOptions& options);

/// The settings of initial_pose; segment() takes each from the SegmentOptions field of the
/// same name (segment.h, where their defaults are).
struct InitialPoseOptions {
  MomentsOptions moments;
  TargetFitOptions fit;
  double fit_tolerance_voxels = 0;
  int fit_patience_after_registration = 0;
  int fit_level = 0;
  double coarse_range_edge_fraction = 0;
  double fit_min_range_voxels = 0;
  double profile_step_fraction = 0;
};

/// Where the coarse-to-fine run starts.
struct InitialPose {
  RowMatrixX3d coarse;             ///< S_0 placed
  Similarity pose;                 ///< applied to the model's S_0
  InitMode init = InitMode::pose;  ///< the route taken, after any fallback
  int fit_iterations = 0;
  std::string fit_start;  ///< FittedPose::start; empty without a fit
  RegionStats region;     ///< the appearance's with profiles, else threshold_region_stats
};

/// The pose by the route `mode` (resolved, see resolve_init_mode), after `registration` when
/// that route ran it: its pose when accepted, else the moments route instead (register →
/// moments, register+fit → moments+fit); then the moments, then the fit (from fit_starts,
/// on model level min(L, fit_level), the search of `searches` between the region's classes).
/// \throw AlgorithmError if the moments find nothing to align to, or the step-edge force
///        finds no contrast between the inside and the outside.
InitialPose initial_pose(const SnakeModel& model, const NormalizedPyramid& pyramid, const LevelSearches& searches,
                         const std::optional<ReferenceRegistration>& registration, InitMode mode,
                         const InitialPoseOptions& options);

}  // namespace mrsnake
