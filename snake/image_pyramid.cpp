#include "snake/image_pyramid.h"

#include <algorithm>
#include <cmath>

#include "mesh/errors.h"

namespace mrsnake {

IntensityWindow normalize_intensities(Volume& volume, double low_percentile, double high_percentile,
                                      std::size_t max_samples) {
  const IntensityWindow w = robust_intensity_window(volume, low_percentile, high_percentile, max_samples);
  apply_intensity_window(volume, w);
  return w;
}

void apply_intensity_window(Volume& volume, const IntensityWindow& w) {
  const double scale = 1.0 / (w.high - w.low);
  for (float& v : volume.data) v = std::isfinite(v) ? static_cast<float>((v - w.low) * scale) : 0.0f;
}

IntensityWindow robust_intensity_window(const Volume& volume, double low_percentile, double high_percentile,
                                        std::size_t max_samples) {
  const std::size_t n = volume.data.size();
  if (n == 0) throw InputError("the image is empty; give a 3D image with voxels");
  // A 3D lattice with the same step on every axis, centred in its cells: a stride along the
  // flat index would fall on a few x planes whenever it divides the row length.
  const double ratio = static_cast<double>(n) / static_cast<double>(std::max<std::size_t>(1, max_samples));
  const std::size_t step = ratio > 1 ? static_cast<std::size_t>(std::max(1.0, std::floor(std::cbrt(ratio)))) : 1;
  std::vector<float> samples;
  samples.reserve(n / (step * step * step) + 1);
  for (std::size_t k = (std::min(step, volume.size[2]) - 1) / 2; k < volume.size[2]; k += step)
    for (std::size_t j = (std::min(step, volume.size[1]) - 1) / 2; j < volume.size[1]; j += step)
      for (std::size_t i = (std::min(step, volume.size[0]) - 1) / 2; i < volume.size[0]; i += step) {
        const float value = volume.at(i, j, k);
        if (std::isfinite(value)) samples.push_back(value);
      }
  if (samples.empty()) throw InputError("the image has no finite intensity");
  const auto percentile = [&](double pct) {
    const std::size_t k = static_cast<std::size_t>(std::llround(pct / 100.0 * static_cast<double>(samples.size() - 1)));
    std::nth_element(samples.begin(), samples.begin() + static_cast<long>(k), samples.end());
    return static_cast<double>(samples[k]);
  };
  IntensityWindow w;
  w.low = percentile(low_percentile);
  w.high = percentile(high_percentile);
  if (!(w.high > w.low)) {
    // Mostly constant image (e.g. a small object on a flat background): widen to min/max.
    const auto [mn, mx] = std::minmax_element(samples.begin(), samples.end());
    w.low = *mn;
    w.high = *mx;
  }
  if (!(w.high > w.low)) throw InputError("the image is constant; there is nothing to segment");
  return w;
}

Volume downsample_by_two(const Volume& in) {
  Volume out;
  std::array<std::size_t, 3> f{};
  for (int a = 0; a < 3; ++a) {
    f[a] = in.size[a] > 1 ? 2 : 1;
    out.size[a] = (in.size[a] + f[a] - 1) / f[a];
    out.spacing[a] = in.spacing[a] * static_cast<double>(f[a]);
  }
  out.direction = in.direction;
  // The centre of block (0,0,0) is at index ((f-1)/2) of the input.
  out.origin = in.index_to_physical((f[0] - 1) * 0.5, (f[1] - 1) * 0.5, (f[2] - 1) * 0.5);
  out.data.assign(out.num_voxels(), 0.0f);
  const std::size_t sx = 1, sy = in.size[0], sz = in.size[0] * in.size[1];
  const bool all_two = f[0] == 2 && f[1] == 2 && f[2] == 2;
  for (std::size_t k = 0; k < out.size[2]; ++k) {
    const std::size_t k0 = k * f[2], k1 = std::min(k0 + f[2], in.size[2]);
    for (std::size_t j = 0; j < out.size[1]; ++j) {
      const std::size_t j0 = j * f[1], j1 = std::min(j0 + f[1], in.size[1]);
      float* dst = &out.data[out.index(0, j, k)];
      const bool full_jk = all_two && j1 - j0 == 2 && k1 - k0 == 2;
      for (std::size_t i = 0; i < out.size[0]; ++i) {
        const std::size_t i0 = i * f[0], i1 = std::min(i0 + f[0], in.size[0]);
        if (full_jk && i1 - i0 == 2) {  // the common case: a whole 2×2×2 block
          const float* p = &in.data[i0 * sx + j0 * sy + k0 * sz];
          dst[i] = 0.125f * ((p[0] + p[1]) + (p[sy] + p[sy + 1]) + (p[sz] + p[sz + 1]) + (p[sz + sy] + p[sz + sy + 1]));
          continue;
        }
        double sum = 0;
        int count = 0;
        for (std::size_t kk = k0; kk < k1; ++kk)
          for (std::size_t jj = j0; jj < j1; ++jj) {
            const float* src = &in.data[in.index(0, jj, kk)];
            for (std::size_t ii = i0; ii < i1; ++ii, ++count) sum += src[ii];
          }
        dst[i] = static_cast<float>(sum / count);
      }
    }
  }
  return out;
}

std::vector<Volume> build_pyramid(const Volume& volume, int levels, std::size_t min_size) {
  std::vector<Volume> pyramid;
  pyramid.push_back(volume);
  while (static_cast<int>(pyramid.size()) < levels) {
    const Volume& last = pyramid.back();
    bool ok = true;
    for (int a = 0; a < 3; ++a)
      if (last.size[a] > 1 && (last.size[a] + 1) / 2 < min_size) ok = false;
    if (!ok) break;
    pyramid.push_back(downsample_by_two(last));
  }
  return pyramid;
}

NormalizedPyramid::NormalizedPyramid(const Volume& image, const IntensityWindow& w) : window(w) {
  level0_scale = 1.0 / (window.high - window.low);
  level0_offset = -window.low * level0_scale;
  owned_.reserve(8);
  levels.push_back(&image);
  while (levels.size() < 8) {
    bool ok = true;
    for (int a = 0; a < 3; ++a)
      if (levels.back()->size[a] > 1 && (levels.back()->size[a] + 1) / 2 < 16) ok = false;
    if (!ok) break;
    owned_.push_back(downsample_by_two(*levels.back()));
    if (levels.size() == 1) apply_intensity_window(owned_.back(), window);
    levels.push_back(&owned_.back());
  }
  if (levels.size() == 1) {  // a tiny image: normalize a copy
    owned_.push_back(image);
    apply_intensity_window(owned_.back(), window);
    levels[0] = &owned_.back();
  }
  level0_raw = levels[0] == &image;
  for (const Volume* v : levels) spacings.push_back(v->max_spacing());
  samplers.reserve(levels.size());
  for (std::size_t k = 0; k < levels.size(); ++k)
    samplers.emplace_back(*levels[k], k == 0 && level0_raw ? level0_scale : 1.0,
                          k == 0 && level0_raw ? level0_offset : 0.0);
}

}  // namespace mrsnake
