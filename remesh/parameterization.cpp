#include "remesh/parameterization.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <queue>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "mesh/errors.h"
#include "mesh/parallel.h"
#include "mesh/topology.h"
#include "mesh/vertex_stars.h"
#include "remesh/stretch_map.h"

namespace mrsnake {
namespace {

double face_area(const RowMatrixX3d& P, const RowMatrixX3i& F, int f) {
  const Eigen::Vector3d a = P.row(F(f, 0)), b = P.row(F(f, 1)), c = P.row(F(f, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

double min_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  auto angle = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
    const Eigen::Vector3d u = q - p, v = r - p;
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

// Beyond this spread of the area stretch (orders of magnitude), one chart cannot carry the
// surface: the remeshing's sizes would span more than doubles resolve.
constexpr double max_stretch_spread_log10 = 12.0;

// Spread of the area distortion, ignoring the 0.1 % most extreme faces on each side.
// \pre `sorted` is sorted and not empty.
double spread_of_sorted_log10(const std::vector<double>& sorted) {
  const std::size_t m = sorted.size();
  return std::log10(sorted[m - 1 - m / 1000] / sorted[m / 1000]);
}

// The same spread for a map of `mesh` onto `domain` (infinite for a face flat in either).
double stretch_spread_log10(const TriMesh& mesh, const RowMatrixX3d& domain) {
  std::vector<double> stretch(static_cast<std::size_t>(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) stretch[f] = face_area(mesh.V, mesh.F, f) / face_area(domain, mesh.F, f);
  std::sort(stretch.begin(), stretch.end());
  if (stretch.empty()) return 0;
  if (!(stretch.front() > 0) || !std::isfinite(stretch.back())) return std::numeric_limits<double>::infinity();
  return spread_of_sorted_log10(stretch);
}

// Shortest-path lengths along the edges from `source` to every vertex (Dijkstra).
std::vector<double> edge_path_lengths(const TriMesh& mesh, const VertexStars& stars, int source) {
  const int n = mesh.num_vertices();
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  dist[source] = 0;
  queue.emplace(0.0, source);
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i)
      for (int k = 0; k < 3; ++k) {
        const int w = mesh.F(stars.faces[i], k);
        const double dw = d + (mesh.V.row(w) - mesh.V.row(v)).norm();
        if (dw < dist[w]) {
          dist[w] = dw;
          queue.emplace(dw, w);
        }
      }
  }
  return dist;
}

// How well shaped each vertex's star is as the cap around the pole: its smallest angle, one
// radian less off valence 5..7.
std::vector<double> puncture_scores(const TriMesh& mesh) {
  const int n = mesh.num_vertices();
  std::vector<int> valence(n, 0);
  std::vector<double> worst(n, M_PI);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const double m = min_angle(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)), mesh.V.row(mesh.F(f, 2)));
    for (int k = 0; k < 3; ++k) {
      ++valence[mesh.F(f, k)];
      worst[mesh.F(f, k)] = std::min(worst[mesh.F(f, k)], m);
    }
  }
  std::vector<double> score(n);
  for (int v = 0; v < n; ++v) score[v] = worst[v] - (valence[v] >= 5 && valence[v] <= 7 ? 0.0 : 1.0);
  return score;
}

// The vertex whose star is best shaped: its star becomes the cap around the pole.
int choose_puncture_vertex(const TriMesh& mesh) {
  const std::vector<double> score = puncture_scores(mesh);
  return static_cast<int>(std::max_element(score.begin(), score.end()) - score.begin());
}

// A well-shaped vertex near the middle of the surface along its longest path. The ends of a
// double sweep (the farthest vertex from any vertex, then the farthest from that one) span the
// shape; the candidates are the vertices whose larger path length to the two ends is within
// 5 % of the ends' distance of the smallest. A map punctured at one end of a long shape
// squeezes the other end over the whole length (exponentially, as a conformal map of a tube
// does), beyond what doubles resolve; punctured in the middle, each end over half of it.
int choose_central_puncture_vertex(const TriMesh& mesh) {
  const VertexStars stars(mesh.F, mesh.num_vertices());
  const auto farthest = [](const std::vector<double>& d) {
    int best = 0;
    for (int v = 0; v < static_cast<int>(d.size()); ++v)
      if (std::isfinite(d[v]) && d[v] > d[best]) best = v;
    return best;
  };
  const int a = farthest(edge_path_lengths(mesh, stars, 0));
  const std::vector<double> from_a = edge_path_lengths(mesh, stars, a);
  const int b = farthest(from_a);
  const std::vector<double> from_b = edge_path_lengths(mesh, stars, b);
  const int n = mesh.num_vertices();
  double centre = std::numeric_limits<double>::infinity();
  for (int v = 0; v < n; ++v) centre = std::min(centre, std::max(from_a[v], from_b[v]));
  const double tolerance = 0.05 * from_a[b];
  const std::vector<double> score = puncture_scores(mesh);
  int best = -1;
  for (int v = 0; v < n; ++v)
    if (std::max(from_a[v], from_b[v]) <= centre + tolerance && (best < 0 || score[v] > score[best])) best = v;
  return best;
}

Eigen::VectorXd vertex_weights(const TriMesh& mesh) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const double a = face_area(mesh.V, mesh.F, f) / 3.0;
    for (int k = 0; k < 3; ++k) w[mesh.F(f, k)] += a;
  }
  return w;
}

// Möbius balancing on the sphere: the 3D-area-weighted centroid of the images goes to 0.
int balance_sphere(RowMatrixX3d& D, const Eigen::VectorXd& weights) {
  const double total = weights.sum();
  int it = 0;
  for (; it < 200; ++it) {
    const Eigen::Vector3d c = (D.transpose() * weights) / total;
    if (c.norm() < 1e-5) break;
    Eigen::Vector3d a = 0.75 * c;
    if (a.norm() > 0.9) a *= 0.9 / a.norm();
    for (int v = 0; v < D.rows(); ++v) D.row(v) = mobius_to_center(a, D.row(v).transpose()).normalized().transpose();
  }
  return it;
}

// Möbius balancing in the unit disk, z -> (z - a) / (1 - conj(a) z).
int balance_disk(RowMatrixX3d& D, const Eigen::VectorXd& weights) {
  const double total = weights.sum();
  int it = 0;
  for (; it < 200; ++it) {
    std::complex<double> c = 0;
    for (int v = 0; v < D.rows(); ++v) c += weights[v] * std::complex<double>(D(v, 0), D(v, 1));
    c /= total;
    if (std::abs(c) < 1e-5) break;
    std::complex<double> a = 0.9 * c;
    if (std::abs(a) > 0.9) a *= 0.9 / std::abs(a);
    for (int v = 0; v < D.rows(); ++v) {
      const std::complex<double> z(D(v, 0), D(v, 1));
      const std::complex<double> w = (z - a) / (1.0 - std::conj(a) * z);
      D(v, 0) = w.real();
      D(v, 1) = w.imag();
    }
  }
  return it;
}

// Some faces of a surface as a mesh of their own (a half of a closed surface cut in two, or
// the punctured surface), and where its vertices come from.
struct Piece {
  TriMesh mesh;
  std::vector<int> to_surface;  ///< piece vertex -> surface vertex
};

Piece extract_piece(const TriMesh& mesh, const std::vector<int>& faces) {
  // Vertices keep their relative order (as remove_unreferenced_vertices does).
  std::vector<int> to_piece(mesh.num_vertices(), -1);
  for (int f : faces)
    for (int k = 0; k < 3; ++k) to_piece[mesh.F(f, k)] = 0;
  Piece piece;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (to_piece[v] == 0) {
      to_piece[v] = static_cast<int>(piece.to_surface.size());
      piece.to_surface.push_back(v);
    }
  piece.mesh.V.resize(static_cast<Eigen::Index>(piece.to_surface.size()), 3);
  for (std::size_t h = 0; h < piece.to_surface.size(); ++h)
    piece.mesh.V.row(static_cast<Eigen::Index>(h)) = mesh.V.row(piece.to_surface[h]);
  piece.mesh.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) piece.mesh.F(static_cast<Eigen::Index>(i), k) = to_piece[mesh.F(faces[i], k)];
  return piece;
}

// Cleans up the cut between the faces of side 0 and side 1 (the side of each face, changed in
// place), whose vertices all go to the equator of the sphere:
// - spikes, where one side's 3D angle at a cut vertex is below 0.6π (the disk map opens it to
//   π) and below the other side's, move to the other side, in up to 8 sweeps (a move can make
//   a spike next to it; moving only when the spikes around get fewer kept more of them and
//   gave worse triangles on the liver);
// - ears, faces with three corners on the cut and two or three edges on it (degenerate on the
//   equator), move to the other side, one at a time; each move shortens the cut, so this ends.
// Returns the cut's 3D length, or -1 if a chord is left (an edge inside one side with both
// ends on the cut).
// The 3D angle of each face at each of its corners.
RowMatrixX3d corner_angles(const TriMesh& mesh) {
  RowMatrixX3d corner(mesh.num_faces(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = mesh.V.row(mesh.F(f, k)), a = mesh.V.row(mesh.F(f, (k + 1) % 3)),
                            b = mesh.V.row(mesh.F(f, (k + 2) % 3));
      corner(f, k) = std::atan2((a - p).cross(b - p).norm(), (a - p).dot(b - p));
    }
  return corner;
}

// `corner` holds corner_angles(mesh).
double smooth_cut(const TriMesh& mesh, const VertexStars& stars, const RowMatrixX3d& corner, std::vector<int>& side) {
  const int n = mesh.num_vertices(), m = mesh.num_faces();
  // The face across the edge from corner k to corner k+1 of f (-1 if none).
  const auto across = [&](int f, int k) {
    return face_with_directed_edge(stars, mesh.F, mesh.F(f, (k + 1) % 3), mesh.F(f, k));
  };
  std::vector<std::array<int, 2>> count(n, {0, 0});  // faces of each side around each vertex
  for (int f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) ++count[mesh.F(f, k)][side[f]];
  const auto on_cut = [&](int v) { return count[v][0] > 0 && count[v][1] > 0; };
  // The 3D angle each side makes at each vertex. The disk maps open every cut vertex's side
  // to a straight angle: a narrow spike of one side (a plane cut zigzags along mesh edges)
  // would be stretched several times over. Spikes move to the other side.
  std::vector<std::array<double, 2>> angle(n, {0.0, 0.0});
  for (int f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) angle[mesh.F(f, k)][side[f]] += corner(f, k);
  const auto move = [&](int f) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.F(f, k);
      --count[v][side[f]];
      ++count[v][side[f] ^ 1];
      angle[v][side[f]] -= corner(f, k);
      angle[v][side[f] ^ 1] += corner(f, k);
    }
    side[f] ^= 1;
  };
  for (int sweep = 0; sweep < 8; ++sweep) {
    bool moved = false;
    for (int v = 0; v < n; ++v) {
      if (!on_cut(v)) continue;
      for (int s = 0; s < 2; ++s)
        if (angle[v][s] < 0.6 * M_PI && angle[v][s ^ 1] > angle[v][s]) {
          for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i)
            if (side[stars.faces[i]] == s) move(stars.faces[i]);
          moved = true;
          break;
        }
    }
    if (!moved) break;
  }
  for (bool moved = true; moved;) {
    moved = false;
    for (int f = 0; f < m; ++f) {
      if (!(on_cut(mesh.F(f, 0)) && on_cut(mesh.F(f, 1)) && on_cut(mesh.F(f, 2)))) continue;
      int cut_edges = 0;
      for (int k = 0; k < 3; ++k) {
        const int g = across(f, k);
        cut_edges += g >= 0 && side[g] != side[f];
      }
      if (cut_edges < 2) continue;
      move(f);
      moved = true;
    }
  }
  // A chord, an edge inside one side whose two ends are on the cut, has both ends on the
  // equator and its two faces in one hemisphere: one of them would flip on the sphere. (A face
  // with three corners on the cut has such an edge.)
  double length = 0;
  for (int f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = across(f, k);
      if (g < f) continue;  // each interior edge once (and boundary edges, which a closed surface has none of)
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      if (side[g] != side[f])
        length += (mesh.V.row(a) - mesh.V.row(b)).norm();
      else if (on_cut(a) && on_cut(b))
        return -1;
    }
  return length;
}

// Cuts a closed genus-0 surface into two topological disks of equal area: the faces on each
// side of a plane through the area centroid across one of its principal axes (a smooth level
// set, so the cut is one loop on most organs), cleaned up by smooth_cut. The three axes' cuts
// are tried shortest first: a short cut distorts the two maps least. Returns false when none
// gives two disks.
bool split_into_two_disks(const TriMesh& mesh, std::array<Piece, 2>& halves, int& axis_used) {
  const int m = mesh.num_faces();
  RowMatrixX3d centroid(m, 3);
  Eigen::VectorXd area(m);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int f = 0; f < m; ++f) {
    centroid.row(f) = (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))) / 3.0;
    area[f] = face_area(mesh.V, mesh.F, f);
    mean += area[f] * centroid.row(f).transpose();
  }
  const double total = area.sum();
  if (!(total > 0)) return false;
  mean /= total;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int f = 0; f < m; ++f) {
    const Eigen::Vector3d d = centroid.row(f).transpose() - mean;
    covariance += area[f] * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(covariance);
  const VertexStars stars(mesh.F, mesh.num_vertices());
  const RowMatrixX3d corner = corner_angles(mesh);  // the same for every axis's cut
  std::vector<std::pair<double, std::vector<int>>> cuts;
  std::vector<int> axes;
  for (int axis_index = 0; axis_index < 3; ++axis_index) {
    const Eigen::Vector3d axis = principal.eigenvectors().col(2 - axis_index);  // eigenvalues ascend
    const Eigen::VectorXd height = (centroid.rowwise() - mean.transpose()) * axis;
    // The area-weighted median height: equal areas, so the two solves take about as long.
    std::vector<int> order(m);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return height[a] < height[b]; });
    double below = 0;
    int split = 0;
    while (split < m && below + area[order[split]] <= 0.5 * total) below += area[order[split++]];
    if (split == 0 || split == m) continue;
    std::vector<int> side(m, 1);
    for (int i = 0; i < split; ++i) side[order[i]] = 0;
    const double length = smooth_cut(mesh, stars, corner, side);
    if (length <= 0) continue;
    cuts.emplace_back(length, std::move(side));
    axes.push_back(axis_index);
  }
  std::vector<int> by_length(cuts.size());
  std::iota(by_length.begin(), by_length.end(), 0);
  std::sort(by_length.begin(), by_length.end(), [&](int a, int b) { return cuts[a].first < cuts[b].first; });
  for (int c : by_length) {
    const std::vector<int>& side = cuts[c].second;
    std::array<std::vector<int>, 2> faces;
    for (int f = 0; f < m; ++f) faces[side[f]].push_back(f);
    std::array<bool, 2> disk{};
    const auto extract = [&](int i) {
      halves[i] = extract_piece(mesh, faces[i]);
      disk[i] = topology_report(halves[i].mesh).is_disk();
    };
    run_both_in_parallel([&] { extract(0); }, [&] { extract(1); });
    if (disk[0] && disk[1]) {
      axis_used = axes[c];
      return true;
    }
  }
  return false;
}

// Signed area of the disk map's triangles (positive when counter-clockwise).
double signed_area(const Eigen::MatrixX2d& xy, const RowMatrixX3i& F) {
  double sum = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector2d a = xy.row(F(f, 0)), b = xy.row(F(f, 1)), c = xy.row(F(f, 2));
    sum += (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  }
  return 0.5 * sum;
}

// The two halves' disk maps glued into one map onto the sphere: half 0 onto the northern
// hemisphere, half 1 onto the southern, each by inverse stereographic projection, the cut on
// the equator. Both disks put the cut on the unit circle by arc length, so they agree there
// up to a rotation and a reflection, which are undone here. Returns false if they do not agree.
bool glue_hemispheres(const TriMesh& mesh, const std::array<Piece, 2>& halves, std::array<Eigen::MatrixX2d, 2> xy,
                      RowMatrixX3d& domain) {
  // Half 0 counter-clockwise (outward on the north), half 1 clockwise (outward on the south).
  for (int i = 0; i < 2; ++i)
    if ((signed_area(xy[i], halves[i].mesh.F) < 0) == (i == 0)) xy[i].col(1) *= -1.0;
  std::vector<int> cut_position(mesh.num_vertices(), -1);  // surface vertex -> row of half 0
  for (std::size_t h = 0; h < halves[0].to_surface.size(); ++h)
    cut_position[halves[0].to_surface[h]] = static_cast<int>(h);
  // The rotation taking half 1's circle onto half 0's, from one shared vertex.
  double rotation = 0;
  bool found = false;
  for (std::size_t h = 0; h < halves[1].to_surface.size() && !found; ++h) {
    const int in0 = cut_position[halves[1].to_surface[h]];
    if (in0 < 0) continue;
    rotation = std::atan2(xy[0](in0, 1), xy[0](in0, 0)) - std::atan2(xy[1](h, 1), xy[1](h, 0));
    found = true;
  }
  if (!found) return false;
  const Eigen::Matrix2d turn = Eigen::Rotation2Dd(rotation).toRotationMatrix();
  xy[1] = (xy[1] * turn.transpose()).eval();
  for (std::size_t h = 0; h < halves[1].to_surface.size(); ++h) {
    const int in0 = cut_position[halves[1].to_surface[h]];
    if (in0 < 0) continue;
    if ((xy[1].row(h) - xy[0].row(in0)).norm() > 1e-6) return false;
    xy[1].row(h) = xy[0].row(in0);  // exactly the same point on the equator
  }
  domain.resize(mesh.num_vertices(), 3);
  for (int i = 0; i < 2; ++i)
    for (std::size_t h = 0; h < halves[i].to_surface.size(); ++h) {
      const double x = xy[i](h, 0), y = xy[i](h, 1), s = x * x + y * y;
      const double z = (1 - s) / (1 + s);
      domain.row(halves[i].to_surface[h]) << 2 * x / (1 + s), 2 * y / (1 + s), i == 0 ? z : -z;
    }
  return true;
}

// The punctured map: the star of one well-shaped vertex removed, the rest mapped to the unit
// disk and lifted onto the sphere by inverse stereographic projection from that vertex, which
// goes to the pole (0, 0, 1). Returns the pole vertex.
void punctured_sphere_map(const TriMesh& mesh, int pole, RowMatrixX3d& domain) {
  const int n = mesh.num_vertices();
  std::vector<int> keep;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (mesh.F(f, 0) != pole && mesh.F(f, 1) != pole && mesh.F(f, 2) != pole) keep.push_back(f);
  const Piece disk = extract_piece(mesh, keep);
  const Eigen::MatrixX2d uv = mean_value_disk_map(disk.mesh);
  domain.resize(n, 3);
  for (std::size_t i = 0; i < disk.to_surface.size(); ++i) {
    // The disk's rim goes to the equator.
    const double x = 2 * uv(i, 0) - 1, y = 2 * uv(i, 1) - 1, s = x * x + y * y;
    domain.row(disk.to_surface[i]) << 2 * x / (1 + s), 2 * y / (1 + s), (s - 1) / (1 + s);
  }
  domain.row(pole) << 0, 0, 1;
}

// The two-halves map: the surface cut into two disks, each mapped to the unit disk on its own
// core, then glued along the cut onto the sphere. Returns false (and leaves `domain`
// unspecified, `summary["sphere_map_fallback"]` saying why) when no principal plane cuts the
// surface into two disks, a half's solve fails, or a triangle flips or goes flat.
bool two_halves_sphere_map(const TriMesh& mesh, RowMatrixX3d& domain, std::vector<int>& cut, nlohmann::json& summary) {
  std::array<Piece, 2> halves;
  int axis = -1;
  if (!split_into_two_disks(mesh, halves, axis)) {
    summary["sphere_map_fallback"] = "no principal plane cuts the surface into two disks";
    return false;
  }
  std::array<Eigen::MatrixX2d, 2> xy;
  try {
    run_both_in_parallel([&] { xy[0] = mean_value_disk_map(halves[0].mesh); },
                         [&] { xy[1] = mean_value_disk_map(halves[1].mesh); });
  } catch (const AlgorithmError& e) {
    summary["sphere_map_fallback"] = std::string("a half's map failed: ") + e.what();
    return false;
  }
  for (auto& uv : xy) uv = (2.0 * uv.array() - 1.0).matrix();
  if (!glue_hemispheres(mesh, halves, xy, domain)) {
    summary["sphere_map_fallback"] = "the two halves' maps disagree on the cut";
    return false;
  }
  // Every triangle turned the same way (parameterize() settles which for both maps), none flat.
  int positive = 0, negative = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const double o = domain_orientation(domain.row(mesh.F(f, 0)), domain.row(mesh.F(f, 1)), domain.row(mesh.F(f, 2)));
    positive += o > 0;
    negative += o < 0;
  }
  const int bad = mesh.num_faces() - std::max(positive, negative);
  if (bad > 0) {
    summary["sphere_map_fallback"] = std::to_string(bad) + " triangles flipped or flat on the sphere";
    return false;
  }
  std::vector<bool> in_first(mesh.num_vertices(), false);
  for (int v : halves[0].to_surface) in_first[v] = true;
  cut.clear();
  for (int v : halves[1].to_surface)
    if (in_first[v]) cut.push_back(v);
  summary["cut_axis"] = axis;
  summary["cut_vertices"] = static_cast<int>(cut.size());
  return true;
}

}  // namespace

double detail::smooth_cut(const TriMesh& mesh, std::vector<int>& side) {
  return mrsnake::smooth_cut(mesh, VertexStars(mesh.F, mesh.num_vertices()), corner_angles(mesh), side);
}

Eigen::Vector3d mobius_to_center(const Eigen::Vector3d& a, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - a;
  return (1.0 - a.squaredNorm()) * d / d.squaredNorm() - a;
}

bool OneChartFailure::squeezed() const { return !(stretch_spread_log10 <= max_stretch_spread_log10); }

std::string OneChartFailure::reason() const {
  const std::string flips = "flipped " + std::to_string(flipped) + " triangles";
  const std::string squeeze =
      std::isfinite(stretch_spread_log10)
          ? "area stretch spans " + std::to_string(static_cast<int>(stretch_spread_log10)) + " orders of magnitude"
          : "area stretch spans more orders of magnitude than doubles measure";
  if (!squeezed()) return "the one-chart map " + flips;
  if (flipped == 0) return "the one-chart map's " + squeeze;
  return "the one-chart map " + flips + ", and its " + squeeze;
}

namespace {

// A one-chart map that flipped triangles or squeezed a protrusion past what doubles resolve is
// replaced by the hierarchical one, which bounds the squeeze at the price of anisotropy: the
// one-chart maps stay first, being conformal, where they work.
// \throw AlgorithmError if options.on_hierarchical_fallback declines the hierarchical map.
void fall_back_to_hierarchical_map(const TriMesh& mesh, const ParameterizationOptions& options,
                                   Parameterization& param) {
  OneChartFailure failure;
  failure.flipped = count_flipped(param.domain, mesh.F);
  failure.stretch_spread_log10 = stretch_spread_log10(mesh, param.domain);
  if (failure.flipped == 0 && !failure.squeezed()) return;
  if (options.on_hierarchical_fallback && !options.on_hierarchical_fallback(failure))
    throw AlgorithmError(failure.reason() + "; the hierarchical map was declined");
  param.summary["sphere_map_fallback"] = "hierarchical: " + failure.reason();
  param.sphere_map = SphereMap::hierarchical;
  param.domain = hierarchical_sphere_map(mesh);
  param.cut.clear();
}

}  // namespace

Parameterization parameterize(const TriMesh& input, const ParameterizationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Parameterization param;
  param.surface = remove_unreferenced_vertices(input);
  const TriMesh& mesh = param.surface;
  const TopologyReport topo = topology_report(mesh);
  require_disk_or_sphere(topo, "the input surface");
  const int n = mesh.num_vertices();
  param.domain.resize(n, 3);
  int balance_iterations = 0;
  const Eigen::VectorXd weights = vertex_weights(mesh);

  if (topo.is_disk()) {
    param.kind = DomainKind::disk;
    const auto solve_start = std::chrono::steady_clock::now();
    const Eigen::MatrixX2d uv = mean_value_disk_map(mesh);
    param.summary["solver_seconds"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_start).count();
    for (int v = 0; v < n; ++v) param.domain.row(v) << 2 * uv(v, 0) - 1, 2 * uv(v, 1) - 1, 1.0;
    double signed_area = 0;
    for (int f = 0; f < mesh.num_faces(); ++f)
      signed_area += domain_orientation(param.domain.row(mesh.F(f, 0)), param.domain.row(mesh.F(f, 1)),
                                        param.domain.row(mesh.F(f, 2)));
    if (signed_area < 0) param.domain.col(1) *= -1.0;
    balance_iterations = balance_disk(param.domain, weights);
  } else {
    param.kind = DomainKind::sphere;
    const bool halves = options.sphere_map == SphereMap::two_halves ||
                        (options.sphere_map == SphereMap::automatic && mesh.num_faces() >= options.halves_from_faces);
    const auto solve_start = std::chrono::steady_clock::now();
    const bool cut = halves && two_halves_sphere_map(mesh, param.domain, param.cut, param.summary);
    param.sphere_map = cut ? SphereMap::two_halves : SphereMap::punctured;
    const auto orient_and_balance = [&] {
      int negative = 0;
      for (int f = 0; f < mesh.num_faces(); ++f)
        if (domain_orientation(param.domain.row(mesh.F(f, 0)), param.domain.row(mesh.F(f, 1)),
                               param.domain.row(mesh.F(f, 2))) < 0)
          ++negative;
      if (2 * negative > mesh.num_faces()) param.domain.col(0) *= -1.0;  // the disk maps' orientation is CGAL's
      balance_iterations = balance_sphere(param.domain, weights);
    };
    if (options.sphere_map == SphereMap::hierarchical) {
      param.sphere_map = SphereMap::hierarchical;
      param.domain = hierarchical_sphere_map(mesh);
    } else if (param.sphere_map == SphereMap::punctured) {
      int pole = choose_puncture_vertex(mesh);
      punctured_sphere_map(mesh, pole, param.domain);
      orient_and_balance();
      // Punctured near one end, a long shape can lose its other end's triangles to rounding,
      // or stretch beyond the limit: then once more from a pole near the middle, which is kept
      // if it flips fewer triangles (or as few, and stretches less).
      const int flipped_first = count_flipped(param.domain, mesh.F);
      const double spread_first = stretch_spread_log10(mesh, param.domain);
      if (flipped_first > 0 || spread_first > max_stretch_spread_log10) {
        const int central = choose_central_puncture_vertex(mesh);
        RowMatrixX3d first = param.domain;
        const int first_iterations = balance_iterations;
        punctured_sphere_map(mesh, central, param.domain);
        orient_and_balance();
        const int flipped_central = count_flipped(param.domain, mesh.F);
        if (flipped_central < flipped_first ||
            (flipped_central == flipped_first && stretch_spread_log10(mesh, param.domain) < spread_first)) {
          param.summary["pole_moved_to_the_middle"] = true;
          pole = central;
        } else {
          param.domain = std::move(first);
          balance_iterations = first_iterations;
        }
      }
      param.summary["pole_vertex"] = pole;
    } else {
      orient_and_balance();
    }
    if (options.sphere_map == SphereMap::automatic) fall_back_to_hierarchical_map(mesh, options, param);
    param.summary["sphere_map"] = param.sphere_map == SphereMap::two_halves     ? "two_halves"
                                  : param.sphere_map == SphereMap::hierarchical ? "hierarchical"
                                                                                : "punctured";
    // The sphere map's whole time: the cut search or the puncture, and the solve(s).
    param.summary["solver_seconds"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_start).count();
  }

  const int flipped = count_flipped(param.domain, mesh.F);
  if (flipped > 0)
    throw AlgorithmError("the parameterization has " + std::to_string(flipped) +
                         " flipped triangles; the surface cannot be parameterized well (repair degenerate triangles or "
                         "smooth it first)");

  // Area distortion.
  const int m = mesh.num_faces();
  param.face_stretch.resize(m);
  Eigen::VectorXd area3(n), aread(n);
  area3.setZero();
  aread.setZero();
  double total3 = 0, totald = 0;
  for (int f = 0; f < m; ++f) {
    const double a3 = face_area(mesh.V, mesh.F, f), ad = face_area(param.domain, mesh.F, f);
    param.face_stretch[f] = a3 / ad;
    total3 += a3;
    totald += ad;
    for (int k = 0; k < 3; ++k) {
      area3[mesh.F(f, k)] += a3;
      aread[mesh.F(f, k)] += ad;
    }
  }
  param.vertex_stretch = area3.cwiseQuotient(aread);
  const double mean_stretch = total3 / totald;
  std::vector<double> sorted(param.face_stretch.data(), param.face_stretch.data() + m);
  std::sort(sorted.begin(), sorted.end());
  if (!std::isfinite(param.vertex_stretch.sum()) || !(sorted.front() > 0) || !std::isfinite(sorted.back()))
    throw AlgorithmError(
        "the parameterization is degenerate (zero-area triangles in the domain); the surface cannot "
        "be parameterized well: repair degenerate triangles first");
  const double spread_log10 = spread_of_sorted_log10(sorted);
  if (spread_log10 > max_stretch_spread_log10)
    throw AlgorithmError(
        "the parameterization is too distorted (area stretch spans " + std::to_string(static_cast<int>(spread_log10)) +
        " orders of magnitude): long protrusions cannot be remeshed from one chart; simplify the shape");

  param.summary["method"] =
      param.kind == DomainKind::disk ? "mean value coordinates on the unit disk, Mobius balanced"
      : param.sphere_map == SphereMap::two_halves
          ? "mean value coordinates of two halves cut across a principal axis, one per hemisphere by inverse "
            "stereographic projection, Mobius balanced"
      : param.sphere_map == SphereMap::hierarchical
          ? "hierarchical near-conformal map (progressive mesh from a tetrahedron, MIPS energy with an area term)"
          : "mean value coordinates of the punctured sphere, inverse stereographic, Mobius balanced";
  param.summary["domain"] = param.kind == DomainKind::sphere ? "sphere" : "disk";
  param.summary["balance_iterations"] = balance_iterations;
  param.summary["l2_stretch"] = normalized_stretch(mesh, param.domain);
  param.summary["stretch_min"] = sorted.front() / mean_stretch;
  param.summary["stretch_max"] = sorted.back() / mean_stretch;
  param.summary["stretch_spread_log10"] = spread_log10;
  param.summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return param;
}

}  // namespace mrsnake
