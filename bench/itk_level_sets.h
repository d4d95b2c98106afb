#pragma once
/// \file itk_level_sets.h
/// The two ITK level sets the segmentation benchmark compares against (bench/bench_segment):
/// GeodesicActiveContourLevelSetImageFilter and ThresholdSegmentationLevelSetImageFilter,
/// each started from a given initial label (the snake's initial surface, rasterized).
/// The implementation is an ITK-only translation unit, so this header exposes nothing but
/// mesh/volume.h and std types.
#include <string>

#include "mesh/volume.h"

namespace mrsnake::bench {

/// Parameters shared by both filters; every intensity-dependent value (sigmoid, thresholds)
/// is derived from the image around the initial label, so the same options serve all cases.
struct LevelSetOptions {
  int max_iterations = 200;      ///< evolution steps at most (the start is a few voxels from the boundary)
  double max_rms_change = 0.01;  ///< stop when the RMS change of the level set falls below this
  double sigma_mm = 1.0;         ///< Gaussian smoothing of the threshold level set's feature image
  double gac_sigma_mm = 1.5;     ///< scale of the GAC's gradient magnitude (recursive Gaussian)
  // Geodesic active contour: speed g = sigmoid(|∇(G_σ * I)|), edges → 0, flat regions → 1.
  double gac_propagation = 0.3, gac_curvature = 1.0, gac_advection = 1.0;
  /// Sigmoid: β = flat + gac_beta_fraction·(edge − flat), α = −(edge − flat)/gac_alpha_divisor,
  /// with flat the median gradient deep inside and edge its 90th percentile near the surface.
  double gac_beta_fraction = 0.35, gac_alpha_divisor = 12.0;
  // Threshold level set: inside [lower, upper] = median ∓ threshold_spread·(robust σ) of the
  // smoothed image inside the initial label.
  double threshold_propagation = 1.0, threshold_curvature = 1.0;
  double threshold_spread = 3.0;
};

/// What one run produced.
struct LevelSetRun {
  Volume labels;                 ///< 1 where the final level set is < 0, 0 elsewhere; the image's grid
  double seconds = 0;            ///< everything after loading: features, initial level set, evolution, labels
  double evolution_seconds = 0;  ///< the level set iterations alone
  int iterations = 0;
  double rms_change = 0;
  std::string parameters_json;  ///< the parameters used (derived ones included), as a JSON object
};

/// Sets ITK's global default thread count (1 for the benchmark's one-thread comparison).
void set_itk_threads(int threads);

/// Geodesic active contour (Caselles et al.) from the initial label `init` (non-zero inside).
/// Feature image: sigmoid of the gradient magnitude (recursive Gaussian, gac_sigma_mm); the
/// sigmoid maps the typical gradient deep inside the initial label to ~1 and the 90th
/// percentile of the gradient in a ±3 mm band around the initial surface to ~0 (see
/// gac_beta_fraction and gac_alpha_divisor).
/// \pre image and init share a grid; init has voxels inside and outside.
/// \throw InputError if the grids differ or the initial label is empty or full.
LevelSetRun geodesic_active_contour(const Volume& image, const Volume& init, const LevelSetOptions& options = {});

/// Threshold level set: grows where the smoothed image lies within [lower, upper] and
/// shrinks elsewhere. The window is median ∓ threshold_spread·σ of the raw image inside the
/// initial label (median and 1.4826·MAD), its side towards the outside clipped at the
/// midpoint between the inside median and the median of a 3 mm shell outside the label,
/// so that heavy noise cannot open the window onto the background.
/// \pre and \throw as geodesic_active_contour.
LevelSetRun threshold_level_set(const Volume& image, const Volume& init, const LevelSetOptions& options = {});

}  // namespace mrsnake::bench
