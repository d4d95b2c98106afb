// ITK translation unit: no Eigen and no CGAL here (ITK bundles its own Eigen).
#include "mesh/image_filters_itk.h"

#include <itkImage.h>
#include <itkImportImageFilter.h>
#include <itkLinearInterpolateImageFunction.h>
#include <itkNearestNeighborInterpolateImageFunction.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>
#include <itkVector.h>
#include <itkWarpImageFilter.h>

#include <algorithm>
#include <string>

#include "mesh/itk_volume.h"
#include "mesh/errors.h"

namespace mrsnake {
namespace {

using FloatImage = itk::Image<float, 3>;
using MaskImage = itk::Image<unsigned char, 3>;
using VectorImage = itk::Image<itk::Vector<float, 3>, 3>;

using itk_volume::allocate_like;
using itk_volume::to_itk;

Volume from_itk(const FloatImage* image, const Volume& like) {
  Volume out = like;
  out.data.assign(image->GetBufferPointer(), image->GetBufferPointer() + like.num_voxels());
  return out;
}

void require_buffer(const Volume& v, const char* what) {
  if (v.data.size() != v.num_voxels())
    throw Error(std::string("internal: ") + what + " buffer does not match its size");
}

bool same_grid(const Volume& a, const Volume& b) {
  return a.size == b.size && a.spacing == b.spacing && a.origin == b.origin && a.direction == b.direction;
}

}  // namespace

Volume gaussian_blur(const Volume& volume, double sigma_mm) {
  require_buffer(volume, "image");
  if (!(sigma_mm > 0)) return volume;
  for (int d = 0; d < 3; ++d)
    if (volume.size[d] < 4)
      throw InputError("cannot blur an image with fewer than 4 voxels along an axis; use a larger size");
  auto filter = itk::SmoothingRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  filter->SetInput(to_itk(volume));
  filter->SetSigma(sigma_mm);  // physical units: the filter uses the image spacing
  filter->Update();
  return from_itk(filter->GetOutput(), volume);
}

Volume distance_to_voxels(const Volume& mask) {
  require_buffer(mask, "mask");
  auto image = allocate_like<MaskImage>(mask);
  unsigned char* dst = image->GetBufferPointer();
  std::size_t count = 0;
  for (std::size_t i = 0; i < mask.num_voxels(); ++i) {
    dst[i] = mask.data[i] != 0.0f ? 1 : 0;
    count += dst[i];
  }
  if (count == 0) throw InputError("distance map of an empty mask: no voxel is set");
  auto filter = itk::SignedMaurerDistanceMapImageFilter<MaskImage, FloatImage>::New();
  filter->SetInput(image);
  filter->SetBackgroundValue(0);
  filter->SetUseImageSpacing(true);
  filter->SetSquaredDistance(false);
  filter->SetInsideIsPositive(false);
  filter->Update();
  Volume out = from_itk(filter->GetOutput(), mask);
  // Every voxel of the mask is on its own contour (value 0); clamp the rounding of the
  // filter and make sure the mask itself reads 0.
  for (std::size_t i = 0; i < out.data.size(); ++i) out.data[i] = dst[i] ? 0.0f : std::max(0.0f, out.data[i]);
  return out;
}

Volume warp_volume(const Volume& image, const Volume& dx, const Volume& dy, const Volume& dz,
                   Interpolation interpolation, float padding) {
  require_buffer(image, "image");
  for (const Volume* d : {&dx, &dy, &dz}) {
    require_buffer(*d, "displacement");
    if (!same_grid(image, *d)) throw Error("internal: displacement field and image grids differ");
  }
  auto field = allocate_like<VectorImage>(image);
  auto* f = field->GetBufferPointer();
  for (std::size_t i = 0; i < image.num_voxels(); ++i) {
    f[i][0] = dx.data[i];
    f[i][1] = dy.data[i];
    f[i][2] = dz.data[i];
  }
  auto input = to_itk(image);
  auto warp = itk::WarpImageFilter<FloatImage, FloatImage, VectorImage>::New();
  warp->SetInput(input);
  warp->SetDisplacementField(field);
  warp->SetOutputParametersFromImage(input);
  warp->SetEdgePaddingValue(padding);
  if (interpolation == Interpolation::nearest)
    warp->SetInterpolator(itk::NearestNeighborInterpolateImageFunction<FloatImage, double>::New());
  else
    warp->SetInterpolator(itk::LinearInterpolateImageFunction<FloatImage, double>::New());
  warp->Update();
  return from_itk(warp->GetOutput(), image);
}

}  // namespace mrsnake
