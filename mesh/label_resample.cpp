// ITK translation unit: no Eigen and no CGAL here (ITK bundles its own Eigen).
#include "mesh/label_resample.h"

#include <itkIdentityTransform.h>
#include <itkLinearInterpolateImageFunction.h>
#include <itkResampleImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "mesh/errors.h"
#include "mesh/itk_volume.h"

namespace mrsnake {

Volume label_occupancy(const Volume& labels, int label, const OccupancyOptions& options) {
  if (!(options.spacing_mm > 0)) throw std::invalid_argument("the occupancy grid spacing must be positive");
  const auto target = static_cast<float>(label);
  // Bounding box of the label's voxels.
  long lo[3] = {static_cast<long>(labels.size[0]), static_cast<long>(labels.size[1]), static_cast<long>(labels.size[2])};
  long hi[3] = {-1, -1, -1};
  for (std::size_t k = 0; k < labels.size[2]; ++k)
    for (std::size_t j = 0; j < labels.size[1]; ++j) {
      const float* row = labels.data.data() + labels.index(0, j, k);
      bool any = false;
      for (std::size_t i = 0; i < labels.size[0]; ++i)
        if (row[i] == target) {
          lo[0] = std::min(lo[0], static_cast<long>(i));
          hi[0] = std::max(hi[0], static_cast<long>(i));
          any = true;
        }
      if (any) {
        lo[1] = std::min(lo[1], static_cast<long>(j));
        hi[1] = std::max(hi[1], static_cast<long>(j));
        lo[2] = std::min(lo[2], static_cast<long>(k));
        hi[2] = std::max(hi[2], static_cast<long>(k));
      }
    }
  if (hi[0] < 0) throw InputError("label " + std::to_string(label) + " is not present in the volume");

  const double sigma = options.sigma_mm > 0 ? options.sigma_mm : options.spacing_mm / 3;
  // A margin of zeros wider than the Gaussian's reach and one output cell, on every side:
  // the cropped mask is padded beyond the volume too, so objects touching its border close.
  Volume crop;
  long start[3];
  for (int d = 0; d < 3; ++d) {
    const long margin = static_cast<long>(std::ceil((3 * sigma + 2 * options.spacing_mm) / labels.spacing[d])) + 1;
    start[d] = lo[d] - margin;
    crop.size[d] = static_cast<std::size_t>(hi[d] - lo[d] + 1 + 2 * margin);
    crop.spacing[d] = labels.spacing[d];
  }
  // A spacing far from the voxels' (a margin of hundreds of voxels, or a grid far finer than
  // the image) asks for grids no machine holds: say so before allocating anything.
  const auto refuse_grid = [&](double voxels) {
    if (voxels <= kMaxOccupancyGridVoxels) return;
    char text[64];
    std::snprintf(text, sizeof text, "%.3g mm makes a grid of %.3g voxels", options.spacing_mm, voxels);
    throw InputError(std::string("an occupancy grid spacing of ") + text +
                     " (too many to hold); choose a spacing nearer the image's voxel size, e.g. 1.2 mm");
  };
  refuse_grid(static_cast<double>(crop.size[0]) * static_cast<double>(crop.size[1]) * static_cast<double>(crop.size[2]));
  double output_voxels = 1;
  for (int d = 0; d < 3; ++d)
    output_voxels *= std::floor((static_cast<double>(crop.size[d]) - 1) * crop.spacing[d] / options.spacing_mm) + 1;
  refuse_grid(output_voxels);
  crop.direction = labels.direction;
  crop.origin = labels.index_to_physical(start[0], start[1], start[2]);
  crop.data.assign(crop.num_voxels(), 0.0f);
  for (long k = lo[2]; k <= hi[2]; ++k)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long i = lo[0]; i <= hi[0]; ++i)
        if (labels.at(i, j, k) == target) crop.at(i - start[0], j - start[1], k - start[2]) = 1.0f;

  using Image = itk_volume::FloatImage;
  try {
    const Image::Pointer mask = itk_volume::to_itk(crop);
    auto smooth = itk::SmoothingRecursiveGaussianImageFilter<Image, Image>::New();
    smooth->SetInput(mask);
    smooth->SetSigma(sigma);

    // The output grid: isotropic, the input's direction, covering the crop.
    Volume out;
    out.direction = labels.direction;
    out.origin = crop.origin;
    out.spacing = {options.spacing_mm, options.spacing_mm, options.spacing_mm};
    Image::SizeType size;
    Image::SpacingType spacing;
    Image::PointType origin;
    Image::DirectionType direction;
    for (int d = 0; d < 3; ++d) {
      const double extent = (static_cast<double>(crop.size[d]) - 1) * crop.spacing[d];
      out.size[d] = static_cast<std::size_t>(std::floor(extent / options.spacing_mm)) + 1;
      size[d] = out.size[d];
      spacing[d] = options.spacing_mm;
      origin[d] = out.origin[d];
      for (int c = 0; c < 3; ++c) direction(d, c) = labels.direction[3 * d + c];
    }
    auto resample = itk::ResampleImageFilter<Image, Image>::New();
    resample->SetInput(smooth->GetOutput());
    resample->SetTransform(itk::IdentityTransform<double, 3>::New());
    resample->SetInterpolator(itk::LinearInterpolateImageFunction<Image, double>::New());
    resample->SetSize(size);
    resample->SetOutputSpacing(spacing);
    resample->SetOutputOrigin(origin);
    resample->SetOutputDirection(direction);
    resample->SetDefaultPixelValue(0.0f);
    resample->Update();
    const float* r = resample->GetOutput()->GetBufferPointer();
    out.data.assign(r, r + out.num_voxels());
    for (float& v : out.data) v = std::clamp(v, 0.0f, 1.0f);
    return out;
  } catch (const itk::ExceptionObject& e) {
    throw AlgorithmError(std::string("smoothing and resampling the label failed (") + e.GetDescription() +
                         "); try another --mc-spacing, or 0 for the voxels' own surface");
  }
}

}  // namespace mrsnake
