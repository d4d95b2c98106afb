// ITK translation unit: no Eigen and no CGAL here (ITK bundles its own Eigen).
#include "mesh/label_repair.h"

#include <itkBinaryBallStructuringElement.h>
#include <itkBinaryFillholeImageFilter.h>
#include <itkBinaryMorphologicalClosingImageFilter.h>
#include <itkConnectedComponentImageFilter.h>
#include <itkConstantPadImageFilter.h>
#include <itkImage.h>
#include <itkRegionOfInterestImageFilter.h>
#include <itkRelabelComponentImageFilter.h>

#include <string>

#include "mesh/errors.h"

namespace mrsnake {

namespace {

using Mask = itk::Image<unsigned char, 3>;

// 1 on the voxels of `label`, 0 elsewhere, on the labels' index grid.
Mask::Pointer label_mask_image(const Volume& labels, int label) {
  auto mask = Mask::New();
  Mask::RegionType region;
  for (int d = 0; d < 3; ++d) region.SetSize(d, labels.size[d]);
  mask->SetRegions(region);
  mask->Allocate();
  const auto target = static_cast<float>(label);
  unsigned char* m = mask->GetBufferPointer();
  for (std::size_t i = 0; i < labels.num_voxels(); ++i) m[i] = labels.data[i] == target ? 1 : 0;
  return mask;
}

}  // namespace

Volume close_label(const Volume& labels, int label, int radius_voxels) {
  const Mask::Pointer mask = label_mask_image(labels, label);

  Mask::Pointer result = mask;
  if (radius_voxels > 0) {
    // Pad so that the closing is not clipped by the volume's border, then crop back.
    Mask::SizeType pad;
    pad.Fill(static_cast<Mask::SizeValueType>(radius_voxels + 1));
    auto padder = itk::ConstantPadImageFilter<Mask, Mask>::New();
    padder->SetInput(mask);
    padder->SetPadLowerBound(pad);
    padder->SetPadUpperBound(pad);
    padder->SetConstant(0);
    using Ball = itk::BinaryBallStructuringElement<unsigned char, 3>;
    Ball ball;
    ball.SetRadius(static_cast<Ball::SizeValueType>(radius_voxels));
    ball.CreateStructuringElement();
    auto closing = itk::BinaryMorphologicalClosingImageFilter<Mask, Mask, Ball>::New();
    closing->SetInput(padder->GetOutput());
    closing->SetKernel(ball);
    closing->SetForegroundValue(1);
    auto crop = itk::RegionOfInterestImageFilter<Mask, Mask>::New();
    crop->SetInput(closing->GetOutput());
    crop->SetRegionOfInterest(mask->GetLargestPossibleRegion());
    crop->Update();
    result = crop->GetOutput();
  }
  auto fill = itk::BinaryFillholeImageFilter<Mask>::New();
  fill->SetInput(result);
  fill->SetForegroundValue(1);
  fill->SetFullyConnected(true);
  fill->Update();

  Volume out = labels;
  const unsigned char* r = fill->GetOutput()->GetBufferPointer();
  for (std::size_t i = 0; i < out.num_voxels(); ++i) out.data[i] = r[i];
  return out;
}

Volume keep_label_part(const Volume& labels, int label, int rank) {
  using Parts = itk::Image<unsigned int, 3>;
  const Mask::Pointer mask = label_mask_image(labels, label);
  const unsigned char* m = mask->GetBufferPointer();

  auto components = itk::ConnectedComponentImageFilter<Mask, Parts>::New();
  components->SetInput(mask);
  components->SetFullyConnected(false);
  // Renumbered by size, largest first (ties keep the scan order of their first voxel).
  auto by_size = itk::RelabelComponentImageFilter<Parts, Parts>::New();
  by_size->SetInput(components->GetOutput());
  by_size->SetSortByObjectSize(true);
  by_size->Update();
  const auto parts = static_cast<int>(by_size->GetNumberOfObjects());
  if (parts == 0) throw InputError("label " + std::to_string(label) + " has no voxel", Remedy::choose_label);
  if (rank > parts)
    throw InputError("label " + std::to_string(label) + " has " + std::to_string(parts) + " connected part" +
                         (parts == 1 ? "" : "s") + ", so there is no part " + std::to_string(rank),
                     Remedy::choose_component, parts);

  Volume out = labels;
  const unsigned int* p = by_size->GetOutput()->GetBufferPointer();
  for (std::size_t i = 0; i < out.num_voxels(); ++i)
    if (m[i] != 0 && p[i] != static_cast<unsigned int>(rank)) out.data[i] = 0.0f;
  return out;
}

}  // namespace mrsnake
