#include "remesh/untangle.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "mesh/distance.h"
#include "mesh/vertex_stars.h"

namespace mrsnake {
namespace {

using FacePairs = std::vector<std::pair<int, int>>;

// The movable corners of the pairs' faces, each once.
std::vector<int> vertices_of(const FacePairs& pairs, const RowMatrixX3i& F, const std::vector<bool>& fixed, int n) {
  std::vector<int> vertices;
  std::vector<bool> listed(n, false);
  for (const auto& [f, g] : pairs)
    for (const int face : {f, g})
      for (int k = 0; k < 3; ++k) {
        const int v = F(face, k);
        if (listed[v] || (!fixed.empty() && fixed[v])) continue;
        listed[v] = true;
        vertices.push_back(v);
      }
  return vertices;
}

// Each of `vertices` at the mean of its star's other corners (each neighbour of an interior
// vertex counted twice, so the plain umbrella), from the positions before the round.
RowMatrixX3d umbrella_step(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars,
                           const std::vector<int>& vertices) {
  RowMatrixX3d moved = X;
  for (int v : vertices) {
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    int count = 0;
    for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i)
      for (int k = 0; k < 3; ++k)
        if (const int u = F(stars.faces[i], k); u != v) {
          sum += X.row(u);
          ++count;
        }
    if (count > 0) moved.row(v) = sum / count;
  }
  return moved;
}

}  // namespace

UntangleStats untangle_self_intersections(const RowMatrixX3i& F, RowMatrixX3d& X, const std::vector<bool>& fixed,
                                          const UntangleOptions& options) {
  if (!fixed.empty() && static_cast<Eigen::Index>(fixed.size()) != X.rows())
    throw std::invalid_argument("untangle_self_intersections: " + std::to_string(fixed.size()) + " fixed flags for " +
                                std::to_string(X.rows()) + " vertices");
  UntangleStats stats;
  if (options.max_rounds <= 0) return stats;
  FacePairs pairs = crossing_face_pairs(TriMesh{X, F});
  stats.pairs_before = stats.pairs_after = static_cast<int>(pairs.size());
  if (pairs.empty()) return stats;
  const VertexStars stars(F, static_cast<int>(X.rows()));
  std::vector<bool> moved(X.rows(), false);
  for (int round = 0; round < options.max_rounds && !pairs.empty(); ++round) {
    const std::vector<int> vertices = vertices_of(pairs, F, fixed, static_cast<int>(X.rows()));
    if (vertices.empty()) break;
    RowMatrixX3d next = umbrella_step(X, F, stars, vertices);
    FacePairs next_pairs = crossing_face_pairs(TriMesh{next, F});
    if (next_pairs.size() >= pairs.size()) break;
    X = std::move(next);
    pairs = std::move(next_pairs);
    for (int v : vertices) moved[v] = true;
    ++stats.rounds;
  }
  stats.pairs_after = static_cast<int>(pairs.size());
  for (bool m : moved) stats.moved_vertices += m ? 1 : 0;
  return stats;
}

}  // namespace mrsnake
