// ITK translation unit: no Eigen and no CGAL here (ITK bundles its own Eigen).
#include "bench/itk_level_sets.h"

#include <itkGeodesicActiveContourLevelSetImageFilter.h>
#include <itkGradientMagnitudeRecursiveGaussianImageFilter.h>
#include <itkImage.h>
#include <itkMultiThreaderBase.h>
#include <itkSigmoidImageFilter.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>
#include <itkThresholdSegmentationLevelSetImageFilter.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "mesh/itk_volume.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"

namespace mrsnake::bench {
namespace {

using FloatImage = itk::Image<float, 3>;
using MaskImage = itk::Image<unsigned char, 3>;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

using itk_volume::allocate_like;
using itk_volume::to_itk;

double median_of(std::vector<float> values) {
  if (values.empty()) return 0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

double quantile_of(std::vector<float> values, double q) {
  if (values.empty()) return 0;
  const auto k = static_cast<std::ptrdiff_t>(std::min(values.size() - 1, static_cast<std::size_t>(q * values.size())));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[static_cast<std::size_t>(k)];
}

/// 1.4826·MAD: the standard deviation of a Gaussian sample, robust to outliers.
double robust_sigma(const std::vector<float>& values, double median) {
  std::vector<float> dev(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) dev[i] = static_cast<float>(std::abs(values[i] - median));
  return 1.4826 * median_of(std::move(dev));
}

/// The initial level set: signed distance in mm to the initial label's boundary, negative
/// inside, with the zero crossing halfway between inside and outside voxel centres.
FloatImage::Pointer initial_level_set(const Volume& init) {
  auto mask = allocate_like<MaskImage>(init);
  std::size_t inside = 0;
  unsigned char* m = mask->GetBufferPointer();
  for (std::size_t i = 0; i < init.num_voxels(); ++i) {
    m[i] = init.data[i] > 0.5f ? 1 : 0;
    inside += m[i];
  }
  if (inside == 0 || inside == init.num_voxels())
    throw InputError("the initial label of the level sets must have voxels inside and outside");
  auto distance = itk::SignedMaurerDistanceMapImageFilter<MaskImage, FloatImage>::New();
  distance->SetInput(mask);
  distance->SetInsideIsPositive(false);
  distance->SetUseImageSpacing(true);
  distance->SetSquaredDistance(false);
  distance->SetBackgroundValue(0);
  distance->Update();
  FloatImage::Pointer phi = distance->GetOutput();
  // Maurer's map is 0 on the object's own border voxels: shift by half the smallest spacing
  // so that exactly the initial label is negative.
  const double half = 0.5 * std::min({init.spacing[0], init.spacing[1], init.spacing[2]});
  float* p = phi->GetBufferPointer();
  std::size_t mismatched = 0;
  for (std::size_t i = 0; i < init.num_voxels(); ++i) {
    p[i] = static_cast<float>(p[i] - half);
    mismatched += (p[i] < 0) != (m[i] != 0);
  }
  if (mismatched != 0)
    throw Error("internal: the initial level set disagrees with the initial label on " + std::to_string(mismatched) +
                " voxels");
  phi->DisconnectPipeline();
  return phi;
}

void require_grid(const Volume& image, const Volume& init) {
  if (image.size != init.size || image.data.size() != image.num_voxels() || init.data.size() != init.num_voxels())
    throw InputError("the image and the initial label of the level sets are not on the same grid");
}

Volume labels_from(const FloatImage* phi, const Volume& like) {
  Volume out = like;
  const float* p = phi->GetBufferPointer();
  for (std::size_t i = 0; i < out.num_voxels(); ++i) out.data[i] = p[i] < 0 ? 1.0f : 0.0f;
  return out;
}

std::string fmt(const char* key, double value) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "\"%s\": %.6g", key, value);
  return buf;
}

}  // namespace

void set_itk_threads(int threads) {
  itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(threads);
  itk::MultiThreaderBase::SetGlobalMaximumNumberOfThreads(threads);
}

LevelSetRun geodesic_active_contour(const Volume& image, const Volume& init, const LevelSetOptions& o) {
  require_grid(image, init);
  const auto t_start = Clock::now();
  const FloatImage::Pointer phi0 = initial_level_set(init);
  const float* phi = phi0->GetBufferPointer();

  auto gradient = itk::GradientMagnitudeRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  gradient->SetInput(to_itk(image));
  gradient->SetSigma(o.gac_sigma_mm);
  gradient->Update();
  const float* g = gradient->GetOutput()->GetBufferPointer();
  // Gradient deep inside (noise and texture) and near the initial surface (where the edge is).
  std::vector<float> deep, band, inside_all;
  for (std::size_t i = 0; i < image.num_voxels(); ++i) {
    if (phi[i] < -3.0f) deep.push_back(g[i]);
    if (phi[i] < 0) inside_all.push_back(g[i]);
    if (std::abs(phi[i]) <= 3.0f) band.push_back(g[i]);
  }
  const double flat = median_of(deep.size() >= 100 ? deep : inside_all);
  const double edge = quantile_of(band, 0.9);
  const double beta = flat + o.gac_beta_fraction * (edge - flat);
  const double alpha = -std::max(1e-6, edge - flat) / o.gac_alpha_divisor;  // negative: high gradient → speed 0
  auto sigmoid = itk::SigmoidImageFilter<FloatImage, FloatImage>::New();
  sigmoid->SetInput(gradient->GetOutput());
  sigmoid->SetAlpha(alpha);
  sigmoid->SetBeta(beta);
  sigmoid->SetOutputMinimum(0.0f);
  sigmoid->SetOutputMaximum(1.0f);
  sigmoid->Update();
  if (const char* dump = std::getenv("MRSNAKE_BENCH_DUMP_GAC")) {
    Volume f = image;
    std::copy(sigmoid->GetOutput()->GetBufferPointer(), sigmoid->GetOutput()->GetBufferPointer() + f.num_voxels(),
              f.data.begin());
    write_volume(dump, f, VoxelType::float32);
  }

  using Filter = itk::GeodesicActiveContourLevelSetImageFilter<FloatImage, FloatImage>;
  auto gac = Filter::New();
  gac->SetInput(phi0);
  gac->SetFeatureImage(sigmoid->GetOutput());
  gac->SetPropagationScaling(o.gac_propagation);
  gac->SetCurvatureScaling(o.gac_curvature);
  gac->SetAdvectionScaling(o.gac_advection);
  gac->SetMaximumRMSError(o.max_rms_change);
  gac->SetNumberOfIterations(o.max_iterations);
  const auto t_evolve = Clock::now();
  gac->Update();
  LevelSetRun run;
  run.evolution_seconds = seconds_since(t_evolve);
  run.labels = labels_from(gac->GetOutput(), image);
  run.seconds = seconds_since(t_start);
  run.iterations = static_cast<int>(gac->GetElapsedIterations());
  run.rms_change = gac->GetRMSChange();
  run.parameters_json = "{" + fmt("sigma_mm", o.gac_sigma_mm) + ", " + fmt("sigmoid_alpha", alpha) + ", " +
                        fmt("sigmoid_beta", beta) + ", " + fmt("propagation", o.gac_propagation) + ", " +
                        fmt("curvature", o.gac_curvature) + ", " + fmt("advection", o.gac_advection) + ", " +
                        fmt("max_iterations", o.max_iterations) + ", " + fmt("max_rms_change", o.max_rms_change) + "}";
  return run;
}

LevelSetRun threshold_level_set(const Volume& image, const Volume& init, const LevelSetOptions& o) {
  require_grid(image, init);
  const auto t_start = Clock::now();
  const FloatImage::Pointer phi0 = initial_level_set(init);
  const float* phi = phi0->GetBufferPointer();

  auto smooth = itk::SmoothingRecursiveGaussianImageFilter<FloatImage, FloatImage>::New();
  smooth->SetInput(to_itk(image));
  smooth->SetSigma(o.sigma_mm);
  smooth->Update();
  std::vector<float> inside, shell;
  for (std::size_t i = 0; i < image.num_voxels(); ++i) {
    if (phi[i] < 0)
      inside.push_back(image.data[i]);
    else if (phi[i] <= 3.0f)
      shell.push_back(image.data[i]);
  }
  const double median = median_of(inside), outside = median_of(shell);
  const double sigma = robust_sigma(inside, median);
  double lower = median - o.threshold_spread * sigma, upper = median + o.threshold_spread * sigma;
  const double mid = 0.5 * (median + outside);
  if (outside < median)
    lower = std::max(lower, mid);
  else
    upper = std::min(upper, mid);

  using Filter = itk::ThresholdSegmentationLevelSetImageFilter<FloatImage, FloatImage>;
  auto ls = Filter::New();
  ls->SetInput(phi0);
  ls->SetFeatureImage(smooth->GetOutput());
  ls->SetLowerThreshold(lower);
  ls->SetUpperThreshold(upper);
  ls->SetPropagationScaling(o.threshold_propagation);
  ls->SetCurvatureScaling(o.threshold_curvature);
  ls->SetMaximumRMSError(o.max_rms_change);
  ls->SetNumberOfIterations(o.max_iterations);
  const auto t_evolve = Clock::now();
  ls->Update();
  LevelSetRun run;
  run.evolution_seconds = seconds_since(t_evolve);
  run.labels = labels_from(ls->GetOutput(), image);
  run.seconds = seconds_since(t_start);
  run.iterations = static_cast<int>(ls->GetElapsedIterations());
  run.rms_change = ls->GetRMSChange();
  run.parameters_json = "{" + fmt("sigma_mm", o.sigma_mm) + ", " + fmt("lower", lower) + ", " + fmt("upper", upper) +
                        ", " + fmt("propagation", o.threshold_propagation) + ", " +
                        fmt("curvature", o.threshold_curvature) + ", " + fmt("max_iterations", o.max_iterations) +
                        ", " + fmt("max_rms_change", o.max_rms_change) + "}";
  return run;
}

}  // namespace mrsnake::bench
