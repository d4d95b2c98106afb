#include "mesh/label_spurs.h"

#include <array>
#include <cstdint>
#include <vector>

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

int remove_label_spurs(Volume& labels, int label) {
  const auto target = static_cast<float>(label);
  if (target == 0.0f) return 0;  // the background has no spurs to set to background
  const std::size_t n = labels.num_voxels();
  // Face neighbours in the label, per voxel of the label; a queue of the voxels with at most one.
  std::vector<std::uint8_t> neighbours(n, 0);
  std::vector<std::size_t> queue;
  std::size_t label_voxels = 0;
  for (std::size_t v = 0; v < n; ++v) {
    if (labels.data[v] != target) continue;
    ++label_voxels;
    for_each_face_neighbour(labels, v, [&](std::size_t u) { neighbours[v] += labels.data[u] == target; });
    if (neighbours[v] <= 1) queue.push_back(v);
  }
  // Removing a spur can leave its holder hanging by one face in turn: it joins the queue. Every
  // voxel queued is removed, so the queue ends up listing them all.
  for (std::size_t next = 0; next < queue.size(); ++next) {
    const std::size_t v = queue[next];
    labels.data[v] = 0;
    for_each_face_neighbour(labels, v, [&](std::size_t u) {
      if (labels.data[u] == target && neighbours[u]-- == 2) queue.push_back(u);
    });
  }
  if (queue.size() == label_voxels) {
    for (std::size_t v : queue) labels.data[v] = target;
    return 0;
  }
  return static_cast<int>(queue.size());
}

}  // namespace mrsnake
