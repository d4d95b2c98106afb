#include "apps/report/slices.h"

#include <algorithm>
#include <cmath>

namespace mrsnake::reports {
namespace {

std::pair<float, float> percentile_window(const Volume& image) {
  // A strided sample is enough for a display window and keeps big volumes cheap.
  std::vector<float> sample;
  const std::size_t stride = std::max<std::size_t>(1, image.data.size() / 200000);
  for (std::size_t i = 0; i < image.data.size(); i += stride)
    if (std::isfinite(image.data[i])) sample.push_back(image.data[i]);
  if (sample.empty()) return {0.f, 1.f};
  const auto at = [&](double q) {
    auto it = sample.begin() + static_cast<std::ptrdiff_t>(q * (sample.size() - 1));
    std::nth_element(sample.begin(), it, sample.end());
    return *it;
  };
  const float lo = at(0.01), hi = at(0.99);
  return {lo, hi > lo ? hi : lo + 1.f};
}

}  // namespace

std::array<double, 3> mesh_centre_index(const Volume& image, const TriMesh& mesh) {
  const Eigen::RowVector3d c = mesh.V.colwise().mean();
  return image.physical_to_index({c[0], c[1], c[2]});
}

Canvas slice_with_contours(const Volume& image, int axis, double position, const std::vector<MeshContour>& meshes,
                           const std::vector<LabelContour>& labels, int max_pixels) {
  const int u = axis == 0 ? 1 : 0;  // in-plane axes: u to the right, v upwards
  const int v = axis == 2 ? 1 : 2;
  const double extent_u = image.size[u] * image.spacing[u];
  const double extent_v = image.size[v] * image.spacing[v];
  const double mm_per_pixel = std::max(extent_u, extent_v) / max_pixels;
  const int width = std::max(1, static_cast<int>(std::lround(extent_u / mm_per_pixel)));
  const int height = std::max(1, static_cast<int>(std::lround(extent_v / mm_per_pixel)));
  const long slice = std::clamp(std::lround(position), 0L, static_cast<long>(image.size[axis]) - 1);

  // Pixel (x, y) shows voxel (iu, iv); y = 0 is the top row, so v grows upwards.
  const auto voxel_of = [&](int x, int y, std::size_t idx[3]) {
    const double cu = (x + 0.5) * mm_per_pixel / image.spacing[u] - 0.5;
    const double cv = (height - 1 - y + 0.5) * mm_per_pixel / image.spacing[v] - 0.5;
    idx[axis] = static_cast<std::size_t>(slice);
    idx[u] = static_cast<std::size_t>(std::clamp(std::lround(cu), 0L, static_cast<long>(image.size[u]) - 1));
    idx[v] = static_cast<std::size_t>(std::clamp(std::lround(cv), 0L, static_cast<long>(image.size[v]) - 1));
  };
  const auto [lo, hi] = percentile_window(image);
  Canvas canvas(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      std::size_t idx[3];
      voxel_of(x, y, idx);
      const float value = image.at(idx[0], idx[1], idx[2]);
      const auto g = static_cast<std::uint8_t>(std::clamp((value - lo) / (hi - lo), 0.f, 1.f) * 255.f);
      canvas.set(x, y, {g, g, g});
    }

  for (const LabelContour& lc : labels) {
    if (!lc.labels || lc.labels->size != image.size) continue;
    std::vector<char> inside(static_cast<std::size_t>(width) * height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        std::size_t idx[3];
        voxel_of(x, y, idx);
        inside[static_cast<std::size_t>(y) * width + x] = lc.labels->at(idx[0], idx[1], idx[2]) == lc.value;
      }
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        if (!inside[static_cast<std::size_t>(y) * width + x]) continue;
        const bool edge = x == 0 || y == 0 || x == width - 1 || y == height - 1 ||
                          !inside[static_cast<std::size_t>(y) * width + x - 1] ||
                          !inside[static_cast<std::size_t>(y) * width + x + 1] ||
                          !inside[static_cast<std::size_t>(y - 1) * width + x] ||
                          !inside[static_cast<std::size_t>(y + 1) * width + x];
        if (edge) canvas.set(x, y, lc.color);
      }
  }

  for (const MeshContour& mc : meshes) {
    if (!mc.mesh) continue;
    const TriMesh& m = *mc.mesh;
    std::vector<std::array<double, 3>> idx(m.num_vertices());
    for (int i = 0; i < m.num_vertices(); ++i) idx[i] = image.physical_to_index({m.V(i, 0), m.V(i, 1), m.V(i, 2)});
    const auto to_pixel = [&](const std::array<double, 3>& p) {
      const double x = (p[u] + 0.5) * image.spacing[u] / mm_per_pixel - 0.5;
      const double y = height - 1 - ((p[v] + 0.5) * image.spacing[v] / mm_per_pixel - 0.5);
      return std::pair<double, double>{x, y};
    };
    const double plane = static_cast<double>(slice);
    for (int f = 0; f < m.num_faces(); ++f) {
      std::array<double, 3> crossing[2];
      int found = 0;
      for (int e = 0; e < 3 && found < 2; ++e) {
        const auto& a = idx[m.F(f, e)];
        const auto& b = idx[m.F(f, (e + 1) % 3)];
        const double da = a[axis] - plane, db = b[axis] - plane;
        // Half-open test so that a vertex exactly on the plane is counted once.
        if ((da < 0) == (db < 0)) continue;
        const double t = da / (da - db);
        for (int c = 0; c < 3; ++c) crossing[found][c] = a[c] + t * (b[c] - a[c]);
        ++found;
      }
      if (found == 2) {
        const auto [x0, y0] = to_pixel(crossing[0]);
        const auto [x1, y1] = to_pixel(crossing[1]);
        canvas.line(x0, y0, x1, y1, mc.color, 2);
      }
    }
  }
  return canvas;
}

}  // namespace mrsnake::reports
