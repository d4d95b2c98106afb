#pragma once
/// \file image_pyramid.h
/// The image side of the snake: robust intensity normalization and a pyramid whose
/// levels match the mesh levels. Plain Volume in and out.
#include <vector>

#include "mesh/volume.h"
#include "snake/sampler.h"

namespace mrsnake {

/// The intensities that normalize_intensities mapped to 0 and 1.
struct IntensityWindow {
  double low = 0;   ///< the `low_percentile` intensity, mapped to 0
  double high = 1;  ///< the `high_percentile` intensity, mapped to 1
};

/// The low and high percentiles of the intensities, estimated on at most max_samples voxels
/// taken on a regular stride (min and max if they coincide).
/// \throw InputError if the image is empty or constant.
IntensityWindow robust_intensity_window(const Volume& volume, double low_percentile = 1.0,
                                        double high_percentile = 99.0, std::size_t max_samples = 1u << 20);

/// Maps every voxel v to (v − window.low)/(window.high − window.low) in place (non-finite → 0).
void apply_intensity_window(Volume& volume, const IntensityWindow& window);

/// Robust normalization: the low and high percentiles of the intensities (estimated on at
/// most about max_samples voxels on a regular 3D lattice) map to 0 and 1, linearly; values
/// outside are kept (not clipped), so bright outliers stay bright.
/// \pre 0 <= low_percentile < high_percentile <= 100; volume not empty.
/// \throw InputError if the image is constant (nothing to segment).
IntensityWindow normalize_intensities(Volume& volume, double low_percentile = 1.0, double high_percentile = 99.0,
                                      std::size_t max_samples = 1u << 20);

/// Halves the resolution: each output voxel is the mean of a 2×2×2 block (the last block
/// of an odd axis is smaller). Spacing doubles, and the origin moves to the centre of the
/// first block, so physical positions are kept. An axis of size 1 is kept as is.
Volume downsample_by_two(const Volume& volume);

/// pyramid[0] is the input; pyramid[k] is downsample_by_two of pyramid[k-1]. Stops early
/// when an axis would drop below min_size voxels.
/// \pre levels >= 1.
std::vector<Volume> build_pyramid(const Volume& volume, int levels, std::size_t min_size = 16);

/// The segmentation's image side: the pyramid of an image normalized by `window`, at most 8
/// levels, each axis halved while it keeps at least 16 voxels. The full-resolution image is
/// not copied: its sampler normalizes on the fly, and only the (8× smaller and below) levels
/// are stored normalized; a tiny image (no level 1) is normalized in a copy.
/// Holds pointers to `image`, which must outlive it; neither copied nor moved.
class NormalizedPyramid {
 public:
  NormalizedPyramid(const Volume& image, const IntensityWindow& window);
  NormalizedPyramid(const NormalizedPyramid&) = delete;
  NormalizedPyramid& operator=(const NormalizedPyramid&) = delete;

  IntensityWindow window;
  double level0_scale = 1.0, level0_offset = 0.0;  ///< the normalization of the full-resolution image
  std::vector<const Volume*> levels;               ///< levels[0]: the image itself when level0_raw
  bool level0_raw = false;                         ///< levels[0] holds raw intensities (sampled normalized)
  std::vector<double> spacings;                    ///< max_spacing of each level
  std::vector<VolumeSampler> samplers;             ///< normalized samples of each level

 private:
  std::vector<Volume> owned_;  // levels 1.. (level 0 too when the image is too small for a pyramid)
};

}  // namespace mrsnake
