#pragma once
/// \file itk_volume.h
/// Conversions between the plain Volume and ITK images, for ITK translation units only
/// (it includes ITK, so never include it next to Eigen or CGAL).
#include <itkImage.h>

#include <algorithm>

#include "mesh/volume.h"

namespace mrsnake::itk_volume {

using FloatImage = itk::Image<float, 3>;

/// An allocated ITK image with the volume's size, spacing, origin and direction.
template <class Image>
typename Image::Pointer allocate_like(const Volume& v) {
  auto image = Image::New();
  typename Image::RegionType region;
  typename Image::SpacingType spacing;
  typename Image::PointType origin;
  typename Image::DirectionType direction;
  for (int d = 0; d < 3; ++d) {
    region.SetSize(d, v.size[d]);
    spacing[d] = v.spacing[d];
    origin[d] = v.origin[d];
    for (int c = 0; c < 3; ++c) direction(d, c) = v.direction[3 * d + c];
  }
  image->SetRegions(region);
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->SetDirection(direction);
  image->Allocate();
  return image;
}

/// The volume as a float ITK image (a copy).
inline FloatImage::Pointer to_itk(const Volume& v) {
  auto image = allocate_like<FloatImage>(v);
  std::copy(v.data.begin(), v.data.end(), image->GetBufferPointer());
  return image;
}

}  // namespace mrsnake::itk_volume
