// ITK translation unit: no Eigen and no CGAL here (ITK bundles its own Eigen).
#include "mesh/label_repair.h"

#include <itkBinaryBallStructuringElement.h>
#include <itkBinaryFillholeImageFilter.h>
#include <itkBinaryMorphologicalClosingImageFilter.h>
#include <itkConstantPadImageFilter.h>
#include <itkImage.h>
#include <itkRegionOfInterestImageFilter.h>

namespace mrsnake {

Volume close_label(const Volume& labels, int label, int radius_voxels) {
  using Mask = itk::Image<unsigned char, 3>;
  auto mask = Mask::New();
  Mask::RegionType region;
  for (int d = 0; d < 3; ++d) region.SetSize(d, labels.size[d]);
  mask->SetRegions(region);
  mask->Allocate();
  const auto target = static_cast<float>(label);
  unsigned char* m = mask->GetBufferPointer();
  for (std::size_t i = 0; i < labels.num_voxels(); ++i) m[i] = labels.data[i] == target ? 1 : 0;

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

}  // namespace mrsnake
