#include "mesh/label_spurs.h"

#include <cstdint>

namespace mrsnake {
namespace {

// The voxel indices of the face neighbours of voxel v inside the volume.
template <class Visit>
void for_each_face_neighbour(const Volume& volume, std::size_t v, Visit&& visit) {
  const std::size_t nx = volume.size[0], ny = volume.size[1], nz = volume.size[2];
  const std::size_t i = v % nx, j = (v / nx) % ny, k = v / (nx * ny);
  if (i > 0) visit(v - 1);
  if (i + 1 < nx) visit(v + 1);
  if (j > 0) visit(v - nx);
  if (j + 1 < ny) visit(v + nx);
  if (k > 0) visit(v - nx * ny);
  if (k + 1 < nz) visit(v + nx * ny);
}

}  // namespace

std::vector<std::size_t> label_spurs(const Volume& labels, int label) {
  const auto target = static_cast<float>(label);
  if (target == 0.0f) return {};  // the background has no spurs to set to background
  // Per voxel: its face neighbours still in the label, or kGone outside the label and once removed.
  constexpr std::uint8_t kGone = 255;
  const std::size_t n = labels.num_voxels();
  std::vector<std::uint8_t> neighbours(n, kGone);
  std::size_t label_voxels = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (labels.data[v] == target) {
      neighbours[v] = 0;
      ++label_voxels;
    }
  std::vector<std::size_t> queue;  // the voxels with at most one neighbour, removed in turn
  for (std::size_t v = 0; v < n; ++v) {
    if (neighbours[v] == kGone) continue;
    for_each_face_neighbour(labels, v, [&](std::size_t u) { neighbours[v] += neighbours[u] != kGone; });
    if (neighbours[v] <= 1) queue.push_back(v);
  }
  // Removing a spur can leave its holder hanging by one face in turn: it joins the queue.
  for (std::size_t next = 0; next < queue.size(); ++next) {
    const std::size_t v = queue[next];
    neighbours[v] = kGone;
    for_each_face_neighbour(labels, v, [&](std::size_t u) {
      if (neighbours[u] != kGone && neighbours[u]-- == 2) queue.push_back(u);
    });
  }
  if (queue.size() == label_voxels) return {};
  return queue;
}

int remove_label_spurs(Volume& labels, int label) {
  const std::vector<std::size_t> spurs = label_spurs(labels, label);
  for (std::size_t v : spurs) labels.data[v] = 0;
  return static_cast<int>(spurs.size());
}

}  // namespace mrsnake
