// ITK translation unit: no Eigen and no CGAL here (ITK bundles its own Eigen).
#include "snake/registration_itk.h"

#include <itkBinShrinkImageFilter.h>
#include <itkCommand.h>
#include <itkImageRegistrationMethodv4.h>
#include <itkMattesMutualInformationImageToImageMetricv4.h>
#include <itkMeanSquaresImageToImageMetricv4.h>
#include <itkMultiThreaderBase.h>
#include <itkPointSet.h>
#include <itkRegularStepGradientDescentOptimizerv4.h>
#include <itkSimilarity3DTransform.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "mesh/errors.h"
#include "mesh/itk_volume.h"

namespace mrsnake {
namespace {

using FloatImage = itk_volume::FloatImage;
using Transform = itk::Similarity3DTransform<double>;
using Optimizer = itk::RegularStepGradientDescentOptimizerv4<double>;
using MetricBase = itk::ImageToImageMetricv4<FloatImage, FloatImage>;
using MattesMetric = itk::MattesMutualInformationImageToImageMetricv4<FloatImage, FloatImage>;
using MeanSquaresMetric = itk::MeanSquaresImageToImageMetricv4<FloatImage, FloatImage>;
using Registration = itk::ImageRegistrationMethodv4<FloatImage, FloatImage, Transform>;
using Clock = std::chrono::steady_clock;

MetricBase::Pointer make_metric(const RegistrationOptions& o) {
  if (o.metric == RegistrationMetric::mattes) {
    auto m = MattesMetric::New();
    m->SetNumberOfHistogramBins(static_cast<itk::SizeValueType>(std::max(8, o.histogram_bins)));
    m->SetUseMovingImageGradientFilter(false);  // gradients by central differences where sampled
    m->SetUseFixedImageGradientFilter(false);
    return m.GetPointer();
  }
  auto m = MeanSquaresMetric::New();
  m->SetUseMovingImageGradientFilter(false);
  m->SetUseFixedImageGradientFilter(false);
  return m.GetPointer();
}

// Stops the optimizer once the time budget is spent (checked every iteration).
class TimeGuard : public itk::Command {
 public:
  using Self = TimeGuard;
  using Pointer = itk::SmartPointer<Self>;
  itkNewMacro(Self) Optimizer* optimizer = nullptr;
  Clock::time_point start;
  double max_seconds = 5.0;
  int iterations = 0;
  bool timed_out = false;
  double min_relative_change = 0;
  int window = 5;
  std::vector<double> level_values;  ///< the metric at each iteration of the current level
  int converged_levels = 0;          ///< levels stopped by the metric-change test
  bool level_converged = false;      ///< the current level was
  void Execute(itk::Object* caller, const itk::EventObject& event) override {
    Execute(static_cast<const itk::Object*>(caller), event);
  }
  void Execute(const itk::Object*, const itk::EventObject& event) override {
    if (!itk::IterationEvent().CheckEvent(&event)) return;
    ++iterations;
    if (std::chrono::duration<double>(Clock::now() - start).count() > max_seconds) {
      timed_out = true;
      optimizer->StopOptimization();
      return;
    }
    if (min_relative_change > 0 && window > 0) {
      level_values.push_back(optimizer->GetValue());
      const int n = static_cast<int>(level_values.size());
      if (n > window) {
        const auto [lo, hi] = std::minmax_element(level_values.end() - (window + 1), level_values.end());
        if (*hi - *lo < min_relative_change * std::abs(level_values.back())) {
          ++converged_levels;
          level_converged = true;
          optimizer->StopOptimization();
        }
      }
    }
  }
};

// One level's image: the input averaged over blocks of f voxels per axis, and the Gaussian
// sigma (in its own voxels) of the same physical width as `sigma_fine` input voxels, applied
// on top (ITK smooths within the registration). ITK's multi-level method instead smooths both
// full-resolution images at every coarse level, which took half of the registration's time;
// here the Gaussian runs on images f³ times smaller. (Subtracting the block mean's own variance,
// (f² − 1)/12, from the Gaussian's smoothed less and ended 1.09 mm from a blob's surface
// against 0.84 mm, in tests/snake/test_registration.cpp.) ITK's recursive Gaussian hardly
// smooths below about half a voxel: the defaults give exactly 0.5 (2/4 and 1/2).
struct ReducedImage {
  FloatImage::Pointer image;
  double residual_sigma_voxels = 0;
};

ReducedImage bin_shrunk(FloatImage* input, int f, double sigma_fine) {
  ReducedImage out;
  out.image = input;
  out.residual_sigma_voxels = std::max(0.0, sigma_fine) / std::max(1, f);
  if (f <= 1) return out;
  using Shrink = itk::BinShrinkImageFilter<FloatImage, FloatImage>;
  auto shrink = Shrink::New();
  shrink->SetShrinkFactors(static_cast<unsigned>(f));
  shrink->SetInput(input);
  shrink->Update();
  out.image = shrink->GetOutput();
  out.image->DisconnectPipeline();
  return out;
}

// The largest factor <= f that leaves at least 4 voxels along every axis of both images: one
// factor for all axes and both images, so that both are smoothed alike.
int level_factor(int f, const FloatImage* a, const FloatImage* b) {
  itk::SizeValueType smallest = std::numeric_limits<itk::SizeValueType>::max();
  for (const FloatImage* image : {a, b})
    for (unsigned axis = 0; axis < 3; ++axis)
      smallest = std::min(smallest, image->GetLargestPossibleRegion().GetSize()[axis]);
  return static_cast<int>(
      std::clamp<itk::SizeValueType>(smallest / 4, 1, static_cast<itk::SizeValueType>(std::max(1, f))));
}

// A regular grid of about `count` physical points of the fixed image (voxel centres).
MetricBase::FixedSampledPointSetType::Pointer grid_points(const Volume& fixed, int count) {
  auto points = MetricBase::FixedSampledPointSetType::New();
  const double voxels = static_cast<double>(fixed.num_voxels());
  const int stride = std::max(1, static_cast<int>(std::floor(std::cbrt(voxels / std::max(1, count)))));
  itk::IdentifierType id = 0;
  for (std::size_t k = stride / 2; k < fixed.size[2]; k += stride)
    for (std::size_t j = stride / 2; j < fixed.size[1]; j += stride)
      for (std::size_t i = stride / 2; i < fixed.size[0]; i += stride) {
        const auto p = fixed.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        MetricBase::FixedSampledPointSetType::PointType q;
        for (int a = 0; a < 3; ++a) q[a] = p[a];
        points->SetPoint(id++, q);
      }
  return points;
}

// The metric at a transform, on a fixed grid of samples of the full-resolution images.
double evaluate_metric(const RegistrationOptions& o, FloatImage* fixed, FloatImage* moving, const Transform* at,
                       MetricBase::FixedSampledPointSetType* points, int* valid) {
  auto metric = make_metric(o);
  auto t = Transform::New();
  t->SetFixedParameters(at->GetFixedParameters());
  t->SetParameters(at->GetParameters());
  metric->SetFixedImage(fixed);
  metric->SetMovingImage(moving);
  metric->SetMovingTransform(t);
  metric->SetFixedSampledPointSet(points);
  metric->SetUseSampledPointSet(true);
  metric->SetMaximumNumberOfWorkUnits(static_cast<itk::ThreadIdType>(std::max(1, o.threads)));
  metric->Initialize();
  const double value = metric->GetValue();
  *valid = static_cast<int>(metric->GetNumberOfValidPoints());
  return value;
}

// The radius at which the fixed image's edges lie about `centre`: the RMS distance of the
// strongest tenth of the gradient magnitudes (central differences, every other voxel), so
// that noise spread over the whole crop does not count. Rotations and scalings move those
// edges by about this radius times the angle (the scale change), so it sets the parameter
// scales that make all steps comparable in millimetres.
double edge_radius(const Volume& v, const std::array<double, 3>& centre) {
  std::vector<std::pair<double, double>> samples;  // squared gradient, squared distance
  for (std::size_t k = 1; k + 1 < v.size[2]; k += 2)
    for (std::size_t j = 1; j + 1 < v.size[1]; j += 2)
      for (std::size_t i = 1; i + 1 < v.size[0]; i += 2) {
        const double gx = (v.at(i + 1, j, k) - v.at(i - 1, j, k)) / (2 * v.spacing[0]);
        const double gy = (v.at(i, j + 1, k) - v.at(i, j - 1, k)) / (2 * v.spacing[1]);
        const double gz = (v.at(i, j, k + 1) - v.at(i, j, k - 1)) / (2 * v.spacing[2]);
        const auto p = v.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        const double r2 = (p[0] - centre[0]) * (p[0] - centre[0]) + (p[1] - centre[1]) * (p[1] - centre[1]) +
                          (p[2] - centre[2]) * (p[2] - centre[2]);
        samples.emplace_back(gx * gx + gy * gy + gz * gz, r2);
      }
  const double min_radius = 2.0 * v.max_spacing();
  if (samples.empty()) return min_radius;
  const std::size_t top = std::max<std::size_t>(1, samples.size() / 10);
  std::nth_element(samples.begin(), samples.begin() + static_cast<long>(top), samples.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  double sum = 0;
  for (std::size_t s = 0; s < top; ++s) sum += samples[s].second;
  return std::max(min_radius, std::sqrt(sum / static_cast<double>(top)));
}

RegistrationTransform to_plain(const Transform* t) {
  RegistrationTransform r;
  const auto M = t->GetMatrix();
  const auto off = t->GetOffset();
  const auto c = t->GetCenter();
  const auto tr = t->GetTranslation();
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) r.matrix[3 * a + b] = M(a, b);
    r.offset[a] = off[a];
    r.centre[a] = c[a];
    r.translation[a] = tr[a];
  }
  const auto v = t->GetVersor();
  r.versor = {v.GetX(), v.GetY(), v.GetZ(), v.GetW()};
  r.scale = t->GetScale();
  r.angle_deg = v.GetAngle() * 180.0 / M_PI;
  if (r.angle_deg > 180.0) r.angle_deg = 360.0 - r.angle_deg;
  return r;
}

}  // namespace

RegistrationMetric parse_registration_metric(const std::string& name) {
  if (name == "mattes") return RegistrationMetric::mattes;
  if (name == "mean_squares") return RegistrationMetric::mean_squares;
  throw InputError("unknown registration metric '" + name + "'; use mattes or mean_squares");
}

std::string to_string(RegistrationMetric metric) {
  return metric == RegistrationMetric::mattes ? "mattes" : "mean_squares";
}

std::array<double, 3> RegistrationTransform::apply(const std::array<double, 3>& x) const {
  std::array<double, 3> y{};
  for (int a = 0; a < 3; ++a)
    y[a] = matrix[3 * a] * x[0] + matrix[3 * a + 1] * x[1] + matrix[3 * a + 2] * x[2] + offset[a];
  return y;
}

bool index_box_of_points(const Volume& image, const std::vector<std::array<double, 3>>& points, double margin_fraction,
                         double margin_mm, std::array<long, 3>& lo, std::array<long, 3>& hi) {
  std::array<double, 3> mn{}, mx{};
  mn.fill(std::numeric_limits<double>::max());
  mx.fill(std::numeric_limits<double>::lowest());
  for (const auto& p : points) {
    const auto idx = image.physical_to_index(p);
    for (int a = 0; a < 3; ++a) {
      mn[a] = std::min(mn[a], idx[a]);
      mx[a] = std::max(mx[a], idx[a]);
    }
  }
  for (int a = 0; a < 3; ++a) {
    const double grow = margin_fraction * (mx[a] - mn[a]) + margin_mm / image.spacing[a];
    const long last = static_cast<long>(image.size[a]) - 1;
    const double l = std::floor(mn[a] - grow), h = std::ceil(mx[a] + grow);
    if (!(h >= 0 && l <= last)) return false;  // also false on NaN
    // Clamp in double first: a far-off point must not overflow the cast to long.
    lo[a] = static_cast<long>(std::clamp(l, 0.0, static_cast<double>(last)));
    hi[a] = static_cast<long>(std::clamp(h, 0.0, static_cast<double>(last)));
  }
  return true;
}

Volume crop_volume(const Volume& image, const std::array<long, 3>& lo, const std::array<long, 3>& hi) {
  Volume out;
  for (int a = 0; a < 3; ++a) out.size[a] = static_cast<std::size_t>(hi[a] - lo[a] + 1);
  out.spacing = image.spacing;
  out.direction = image.direction;
  out.origin =
      image.index_to_physical(static_cast<double>(lo[0]), static_cast<double>(lo[1]), static_cast<double>(lo[2]));
  out.data.resize(out.num_voxels());
  std::size_t n = 0;
  for (long k = lo[2]; k <= hi[2]; ++k)
    for (long j = lo[1]; j <= hi[1]; ++j) {
      const float* row = &image.data[image.index(static_cast<std::size_t>(lo[0]), static_cast<std::size_t>(j),
                                                 static_cast<std::size_t>(k))];
      std::copy(row, row + out.size[0], out.data.begin() + static_cast<long>(n));
      n += out.size[0];
    }
  return out;
}

RegistrationResult register_similarity(const Volume& fixed, const Volume& moving, const RegistrationOptions& o) {
  const auto t0 = Clock::now();
  const std::clock_t cpu0 = std::clock();
  if (fixed.data.size() != fixed.num_voxels() || moving.data.size() != moving.num_voxels())
    throw Error("internal: image buffer does not match its size");
  for (int a = 0; a < 3; ++a)
    if (fixed.size[a] < 8)
      throw InputError("the reference image is too small to register (fewer than 8 voxels along an axis)");
  const std::size_t levels = o.shrink_factors.size();
  if (levels == 0 || o.smoothing_voxels.size() != levels)
    throw InputError("registration: give one smoothing value per shrink factor");

  // The centre of the fixed image: the rotation and the scale act about it.
  const auto centre =
      fixed.index_to_physical(0.5 * (fixed.size[0] - 1.0), 0.5 * (fixed.size[1] - 1.0), 0.5 * (fixed.size[2] - 1.0));
  // The part of the moving image the fixed image can reach from the start.
  std::vector<std::array<double, 3>> corners;
  for (int c = 0; c < 8; ++c) {
    auto q = fixed.index_to_physical((c & 1) ? fixed.size[0] - 1.0 : 0.0, (c & 2) ? fixed.size[1] - 1.0 : 0.0,
                                     (c & 4) ? fixed.size[2] - 1.0 : 0.0);
    for (int a = 0; a < 3; ++a) q[a] += o.initial_translation[a];
    corners.push_back(q);
  }
  std::array<long, 3> lo{}, hi{};
  if (!index_box_of_points(moving, corners, o.moving_margin_fraction, o.moving_margin_voxels * fixed.max_spacing(), lo,
                           hi))
    throw InputError("the model's reference image does not overlap the image", Remedy::other_initialization);
  for (int a = 0; a < 3; ++a)
    if (hi[a] - lo[a] < 3)
      throw InputError("the model's reference image barely overlaps the image", Remedy::other_initialization);
  Volume moving_crop = crop_volume(moving, lo, hi);
  if (o.moving_intensity_scale != 1.0 || o.moving_intensity_offset != 0.0)
    for (float& v : moving_crop.data) v = static_cast<float>(o.moving_intensity_scale * v + o.moving_intensity_offset);

  RegistrationResult result;
  result.moving_crop_size = moving_crop.size;
  result.metric = to_string(o.metric);
  // Everything ITK does, setup included, is inside: its exceptions become AlgorithmError,
  // which segment answers with its fallback route instead of an internal error.
  try {
    const auto fixed_image = itk_volume::to_itk(fixed);
    const auto moving_image = itk_volume::to_itk(moving_crop);

    auto transform = Transform::New();
    Transform::InputPointType c;
    for (int a = 0; a < 3; ++a) c[a] = centre[a];
    transform->SetCenter(c);
    transform->SetIdentity();
    transform->SetCenter(c);
    Transform::OutputVectorType start;
    for (int a = 0; a < 3; ++a) start[a] = o.initial_translation[a];
    transform->SetTranslation(start);

    const auto eval_points = grid_points(fixed, std::max(64, o.evaluation_samples));
    // ITK's own filters inside the registration (smoothing, shrinking, the metric's helpers)
    // take the global default thread count: o.threads for the span of the registration, so
    // that it runs on one thread and repeats bit for bit.
    struct GlobalThreads {
      itk::ThreadIdType saved = itk::MultiThreaderBase::GetGlobalDefaultNumberOfThreads();
      explicit GlobalThreads(int n) {
        itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(static_cast<itk::ThreadIdType>(n));
      }
      ~GlobalThreads() { itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(saved); }
    } threads(std::max(1, o.threads));
    const auto t_eval = Clock::now();
    result.initial_metric =
        evaluate_metric(o, fixed_image, moving_image, transform, eval_points, &result.valid_points_initial);
    result.evaluation_seconds = std::chrono::duration<double>(Clock::now() - t_eval).count();
    result.setup_seconds = std::chrono::duration<double>(t_eval - t0).count();
    const auto t_opt = Clock::now();

    // Parameter scales from physical shifts at the edges' radius: versor components and
    // scale move edges by radius × change, translations by the change (regular step descent
    // divides the gradient by the scales, so each step is then about learning-rate mm).
    const double radius = o.rotation_radius_mm > 0 ? o.rotation_radius_mm : edge_radius(fixed, centre);
    result.edge_radius_mm = radius;
    Optimizer::ScalesType scales(transform->GetNumberOfParameters());
    for (unsigned p = 0; p < scales.Size(); ++p) scales[p] = (p < 3 || p == 6) ? radius * radius : 1.0;

    auto guard = TimeGuard::New();
    guard->start = t0;
    guard->max_seconds = o.max_seconds;
    guard->min_relative_change = o.min_relative_change;
    guard->window = o.convergence_window;
    // Coarse to fine, one ITK run per level on images reduced beforehand, the transform
    // carried over. ITK's own multi-level method would smooth both full-resolution images
    // at every coarse level (half of the registration's time); averaging blocks of f voxels
    // first leaves only a small smoothing of the small images (see bin_shrunk).
    Optimizer::Pointer optimizer;
    for (std::size_t l = 0; l < levels && !guard->timed_out; ++l) {
      const int f = level_factor(o.shrink_factors[l], fixed_image, moving_image);
      const ReducedImage fixed_level = bin_shrunk(fixed_image, f, o.smoothing_voxels[l]);
      const ReducedImage moving_level = bin_shrunk(moving_image, f, o.smoothing_voxels[l]);

      auto metric = make_metric(o);
      // o.threads work units (1 by default: sums in one order, so that a run repeats bit for bit).
      metric->SetMaximumNumberOfWorkUnits(static_cast<itk::ThreadIdType>(std::max(1, o.threads)));
      optimizer = Optimizer::New();
      // Each finer level starts from the coarser one's result: shorter first steps.
      optimizer->SetLearningRate(o.initial_step_voxels * fixed.max_spacing() *
                                 std::pow(o.step_factor_per_level, static_cast<double>(l)));
      optimizer->SetMinimumStepLength(o.min_step_voxels * fixed.max_spacing());
      optimizer->SetRelaxationFactor(o.relaxation);
      optimizer->SetNumberOfIterations(static_cast<itk::SizeValueType>(std::max(1, o.iterations_per_level)));
      optimizer->SetReturnBestParametersAndValue(true);
      optimizer->SetNumberOfWorkUnits(static_cast<itk::ThreadIdType>(std::max(1, o.threads)));
      optimizer->SetGradientMagnitudeTolerance(1e-12);
      optimizer->SetScales(scales);

      auto registration = Registration::New();
      registration->SetFixedImage(fixed_level.image);
      registration->SetMovingImage(moving_level.image);
      registration->SetMetric(metric);
      registration->SetOptimizer(optimizer);
      registration->SetInitialTransform(transform);
      registration->InPlaceOn();  // the transform object itself moves, level after level
      registration->SetNumberOfWorkUnits(static_cast<itk::ThreadIdType>(std::max(1, o.threads)));
      registration->SetNumberOfLevels(1);
      Registration::ShrinkFactorsArrayType shrink(1);
      shrink[0] = 1;
      Registration::SmoothingSigmasArrayType sigmas(1);
      sigmas[0] = fixed_level.residual_sigma_voxels;  // the moving image's is the same (same f)
      const double voxels = static_cast<double>(fixed_level.image->GetLargestPossibleRegion().GetNumberOfPixels());
      Registration::MetricSamplingPercentageArrayType percentages(1);
      percentages[0] = std::clamp(o.samples_per_level / voxels, 0.01, 1.0);
      registration->SetShrinkFactorsPerLevel(shrink);
      registration->SetSmoothingSigmasPerLevel(sigmas);
      registration->SmoothingSigmasAreSpecifiedInPhysicalUnitsOff();
      registration->SetMetricSamplingStrategy(Registration::MetricSamplingStrategyType::REGULAR);
      registration->SetMetricSamplingPercentagePerLevel(percentages);
      registration->MetricSamplingReinitializeSeed(20261122 + static_cast<int>(l));

      guard->optimizer = optimizer;
      guard->level_values.clear();
      guard->level_converged = false;
      const int at_start = guard->iterations;
      optimizer->AddObserver(itk::IterationEvent(), guard);
      registration->Update();
      result.iterations.push_back(guard->iterations - at_start);
    }
    result.iterations.resize(levels, 0);  // the levels a spent time budget skipped
    result.stop_condition = guard->timed_out         ? "time budget spent"
                            : guard->level_converged ? "metric change below min_relative_change"
                                                     : optimizer->GetStopConditionDescription();
    result.converged_levels = guard->converged_levels;

    result.optimization_seconds = std::chrono::duration<double>(Clock::now() - t_opt).count();
    const Transform* final_transform = transform.GetPointer();
    result.transform = to_plain(final_transform);
    const auto t_eval2 = Clock::now();
    result.final_metric =
        evaluate_metric(o, fixed_image, moving_image, final_transform, eval_points, &result.valid_points_final);
    result.evaluation_seconds += std::chrono::duration<double>(Clock::now() - t_eval2).count();
  } catch (const itk::ExceptionObject& e) {
    throw AlgorithmError(std::string("image registration failed: ") + e.GetDescription());
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  result.cpu_seconds = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  return result;
}

}  // namespace mrsnake
