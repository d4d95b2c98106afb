#include "wavelets/lifting.h"

#include <cmath>
#include <string>
#include <utility>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The ordered neighbours of a vertex on one level (its link), from the faces around it.
struct Ring {
  enum class Kind { interior, boundary, irregular } kind = Kind::irregular;
  std::vector<int> vertices;  ///< a cycle (interior) or a path whose ends are on the boundary
  int valence() const { return static_cast<int>(vertices.size()); }
};

/// Links of each vertex: for every face (x, y, z) at vertex x, the link y–z. A manifold
/// vertex's links form one cycle (interior) or one path (boundary); anything else is irregular.
std::vector<Ring> build_rings(const RowMatrixX3i& F, int n) {
  std::vector<int> offsets(n + 1, 0);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++offsets[F(f, k) + 1];
  for (int v = 0; v < n; ++v) offsets[v + 1] += offsets[v];
  std::vector<std::pair<int, int>> links(offsets[n]);
  std::vector<int> fill(offsets.begin(), offsets.end() - 1);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) links[fill[F(f, k)]++] = {F(f, (k + 1) % 3), F(f, (k + 2) % 3)};

  std::vector<Ring> rings(n);
  struct Node {
    int vertex;
    int link[2];
    int degree;
  };
  std::vector<Node> nodes;
  for (int v = 0; v < n; ++v) {
    nodes.clear();
    bool ok = true;
    auto node_of = [&](int u) -> int {
      for (std::size_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].vertex == u) return static_cast<int>(i);
      nodes.push_back({u, {-1, -1}, 0});
      return static_cast<int>(nodes.size()) - 1;
    };
    auto connect = [&](int from, int to) {
      Node& node = nodes[from];
      if (node.degree == 2) {
        ok = false;
        return;
      }
      node.link[node.degree++] = to;
    };
    for (int i = offsets[v]; i < offsets[v + 1] && ok; ++i) {
      const int x = node_of(links[i].first), y = node_of(links[i].second);
      if (x == y)
        ok = false;
      else {
        connect(x, y);
        connect(y, x);
      }
    }
    Ring& ring = rings[v];
    if (!ok || nodes.empty()) continue;  // irregular
    int ends = 0, start = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i].degree == 1) {
        if (ends++ == 0) start = static_cast<int>(i);
      }
    if (ends != 0 && ends != 2) continue;
    // Walk the cycle or the path from one of its ends.
    int previous = -1, current = start;
    for (std::size_t step = 0; step < nodes.size(); ++step) {
      ring.vertices.push_back(nodes[current].vertex);
      const Node& node = nodes[current];
      int next;
      if (node.degree == 1)
        next = node.link[0] != previous ? node.link[0] : -1;
      else
        next = node.link[0] != previous ? node.link[0] : node.link[1];
      previous = current;
      current = next;
      if (current < 0) break;
    }
    const bool closed = ends == 0 && current == start;
    const bool complete = ring.vertices.size() == nodes.size();
    if (complete && ends == 2)
      ring.kind = Ring::Kind::boundary;
    else if (complete && closed && ring.vertices.size() >= 3)
      ring.kind = Ring::Kind::interior;
    else
      ring.vertices.clear();
  }
  return rings;
}

int position_in(const std::vector<int>& ring, int vertex) {
  for (std::size_t i = 0; i < ring.size(); ++i)
    if (ring[i] == vertex) return static_cast<int>(i);
  return -1;
}

struct StencilBuilder {
  std::vector<int> indices;
  std::vector<double> weights;
  void add(int v, double w) {
    indices.push_back(v);
    weights.push_back(w);
  }
  void scale(double s) {
    for (double& w : weights) w *= s;
  }
};

/// Zorin's stencil of an extraordinary interior vertex e of valence k for its edge to `other`.
bool extraordinary_stencil(const Ring& ring, int e, int other, double factor, StencilBuilder& out) {
  const int k = ring.valence();
  const int i0 = position_in(ring.vertices, other);
  if (i0 < 0 || k < 3) return false;
  out.add(e, 0.75 * factor);
  for (int i = 0; i < k; ++i) {
    double w;
    if (k == 3)
      w = i == 0 ? 5.0 / 12.0 : -1.0 / 12.0;
    else if (k == 4)
      w = i == 0 ? 3.0 / 8.0 : (i == 2 ? -1.0 / 8.0 : 0.0);
    else
      w = (0.25 + std::cos(2.0 * kPi * i / k) + 0.5 * std::cos(4.0 * kPi * i / k)) / k;
    if (w != 0.0) out.add(ring.vertices[(i0 + i) % k], w * factor);
  }
  return true;
}

}  // namespace

std::string to_string(PredictScheme scheme) { return scheme == PredictScheme::linear ? "linear" : "butterfly"; }
std::string to_string(DetailFrame frame) { return frame == DetailFrame::global ? "global" : "local"; }

PredictScheme parse_predict_scheme(const std::string& name) {
  if (name == "linear") return PredictScheme::linear;
  if (name == "butterfly") return PredictScheme::butterfly;
  throw InputError("unknown wavelet predict scheme '" + name + "'; use 'linear' or 'butterfly'");
}

WaveletTransform::WaveletTransform(SubdivisionConnectivity conn, WaveletOptions options)
    : conn_(std::move(conn)), options_(options) {
  if (conn_.faces.empty() || conn_.vertex_counts.size() != conn_.faces.size())
    throw TopologyError(
        "the mesh hierarchy is empty or its level counts disagree; rebuild it with subdivide_connectivity");
  levels_.resize(conn_.levels());
  for (int j = 0; j < conn_.levels(); ++j) build_level(j);
}

void WaveletTransform::build_level(int j) {
  const RowMatrixX3i& F = conn_.faces[j];
  const RowMatrixX3i& children = conn_.faces[j + 1];
  Level& level = levels_[j];
  level.n_coarse = conn_.vertex_counts[j];
  level.n_fine = conn_.vertex_counts[j + 1];
  const int nc = level.n_coarse, m = level.n_fine - level.n_coarse;
  const auto bad = [j](const std::string& why) {
    return TopologyError("level " + std::to_string(j + 1) + " of the mesh hierarchy is not a 1:4 split of level " +
                         std::to_string(j) + " (" + why + "); build it with subdivide_connectivity");
  };
  if (children.rows() != 4 * F.rows()) throw bad("face count is not 4 times the coarser one");
  if (m <= 0 || conn_.parent_edges.rows() < level.n_fine - conn_.vertex_counts[0]) throw bad("no new vertices");

  // Faces on each parent edge, through the middle child (ab, bc, ca) of each face.
  level.edge_faces.assign(2 * static_cast<std::size_t>(m), -1);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int mid = children(4 * f + 3, k), a = F(f, k), b = F(f, (k + 1) % 3);
      if (mid < nc || mid >= level.n_fine) throw bad("a middle child face has an old vertex");
      const Eigen::Vector2i p = conn_.parents(mid);
      if (!((p[0] == a && p[1] == b) || (p[0] == b && p[1] == a))) throw bad("a new vertex is not on its parent edge");
      int* slot = &level.edge_faces[2 * static_cast<std::size_t>(mid - nc)];
      if (slot[0] < 0)
        slot[0] = f;
      else if (slot[1] < 0)
        slot[1] = f;
      else
        throw bad("an edge has more than two faces");
    }
  std::vector<int> valence(nc, 0);
  for (int i = 0; i < m; ++i) {
    if (level.edge_faces[2 * static_cast<std::size_t>(i)] < 0) throw bad("a new vertex lies on no face");
    const Eigen::Vector2i p = conn_.parents(nc + i);
    ++valence[p[0]];
    ++valence[p[1]];
  }
  level.update_weights.resize(nc);
  for (int v = 0; v < nc; ++v) level.update_weights[v] = valence[v] > 0 ? 0.75 / valence[v] : 0.0;

  // Prediction stencils.
  std::vector<Ring> rings;
  if (options_.predict == PredictScheme::butterfly) rings = build_rings(F, nc);
  level.stencil_offsets.assign(1, 0);
  level.stencil_offsets.reserve(m + 1);
  StencilBuilder s;
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2i p = conn_.parents(nc + i);
    const int a = p[0], b = p[1];
    s.indices.clear();
    s.weights.clear();
    bool done = false;
    if (options_.predict == PredictScheme::butterfly) {
      const Ring& ra = rings[a];
      const Ring& rb = rings[b];
      using K = Ring::Kind;
      const bool boundary_edge = level.edge_faces[2 * static_cast<std::size_t>(i) + 1] < 0;
      if (boundary_edge) {
        if (ra.kind == K::boundary && rb.kind == K::boundary) {
          const int pa =
              ra.vertices.front() == b ? ra.vertices.back() : (ra.vertices.back() == b ? ra.vertices.front() : -1);
          const int qb =
              rb.vertices.front() == a ? rb.vertices.back() : (rb.vertices.back() == a ? rb.vertices.front() : -1);
          if (pa >= 0 && qb >= 0 && pa != qb && pa != b && qb != a) {
            s.add(pa, -1.0 / 16.0);
            s.add(a, 9.0 / 16.0);
            s.add(b, 9.0 / 16.0);
            s.add(qb, -1.0 / 16.0);
            done = true;
          }
        }
      } else if (ra.kind != K::irregular && rb.kind != K::irregular) {
        const bool a_in = ra.kind == K::interior, b_in = rb.kind == K::interior;
        const bool a_ex = a_in && ra.valence() != 6, b_ex = b_in && rb.valence() != 6;
        if (a_in && b_in && !a_ex && !b_ex) {
          const int ia = position_in(ra.vertices, b), ib = position_in(rb.vertices, a);
          if (ia >= 0 && ib >= 0) {
            s.add(a, 0.5);
            s.add(b, 0.5);
            s.add(ra.vertices[(ia + 1) % 6], 0.125);
            s.add(ra.vertices[(ia + 5) % 6], 0.125);
            for (int w : {ra.vertices[(ia + 2) % 6], ra.vertices[(ia + 4) % 6], rb.vertices[(ib + 2) % 6],
                          rb.vertices[(ib + 4) % 6]})
              s.add(w, -1.0 / 16.0);
            done = true;
          }
        } else if (a_ex && b_ex) {
          done = extraordinary_stencil(ra, a, b, 0.5, s) && extraordinary_stencil(rb, b, a, 0.5, s);
        } else if (a_ex || (a_in && !b_in)) {
          done = extraordinary_stencil(ra, a, b, 1.0, s);
        } else if (b_ex || (b_in && !a_in)) {
          done = extraordinary_stencil(rb, b, a, 1.0, s);
        }
      }
      if (!done) {
        s.indices.clear();
        s.weights.clear();
      }
    }
    if (!done) {
      s.add(a, 0.5);
      s.add(b, 0.5);
    }
    level.stencil_indices.insert(level.stencil_indices.end(), s.indices.begin(), s.indices.end());
    level.stencil_weights.insert(level.stencil_weights.end(), s.weights.begin(), s.weights.end());
    level.stencil_offsets.push_back(static_cast<int>(level.stencil_indices.size()));
  }
}

PredictStencil WaveletTransform::predict_stencil(int j, int v) const {
  const Level& level = levels_.at(j);
  const int i = v - level.n_coarse;
  if (i < 0 || v >= level.n_fine) throw std::out_of_range("predict_stencil: vertex is not new on that level");
  PredictStencil s;
  for (int k = level.stencil_offsets[i]; k < level.stencil_offsets[i + 1]; ++k) {
    s.indices.push_back(level.stencil_indices[k]);
    s.weights.push_back(level.stencil_weights[k]);
  }
  return s;
}

RowMatrixX3d WaveletTransform::predict(int j, const RowMatrixX3d& even) const {
  const Level& level = levels_[j];
  const int m = level.n_fine - level.n_coarse;
  RowMatrixX3d P(m, 3);
  for (int i = 0; i < m; ++i) {
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    for (int k = level.stencil_offsets[i]; k < level.stencil_offsets[i + 1]; ++k)
      sum += level.stencil_weights[k] * even.row(level.stencil_indices[k]);
    P.row(i) = sum;
  }
  return P;
}

void WaveletTransform::update(int j, RowMatrixX3d& even, const RowMatrixX3d& d, double sign) const {
  const Level& level = levels_[j];
  const int m = level.n_fine - level.n_coarse;
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2i p = conn_.parents(level.n_coarse + i);
    even.row(p[0]) += (sign * level.update_weights[p[0]]) * d.row(i);
    even.row(p[1]) += (sign * level.update_weights[p[1]]) * d.row(i);
  }
}

std::vector<LocalFrame> WaveletTransform::frames(int j, const RowMatrixX3d& coarse) const {
  const Level& level = levels_.at(j);
  const RowMatrixX3i& F = conn_.faces[j];
  const int m = level.n_fine - level.n_coarse;
  RowMatrixX3d face_normals(F.rows(), 3);
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d q0 = coarse.row(F(f, 0)).transpose();
    face_normals.row(f) =
        (coarse.row(F(f, 1)).transpose() - q0).cross(coarse.row(F(f, 2)).transpose() - q0).transpose();
  }
  double total_length = 0.0;
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2i p = conn_.parents(level.n_coarse + i);
    total_length += (coarse.row(p[1]) - coarse.row(p[0])).norm();
  }
  const double reference_length = total_length / m;
  std::vector<LocalFrame> result(m);
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2i p = conn_.parents(level.n_coarse + i);
    const int f0 = level.edge_faces[2 * static_cast<std::size_t>(i)],
              f1 = level.edge_faces[2 * static_cast<std::size_t>(i) + 1];
    Eigen::Vector3d n = face_normals.row(f0).transpose();
    if (f1 >= 0) n += face_normals.row(f1).transpose();
    result[i] = parent_edge_frame(coarse.row(p[0]).transpose(), coarse.row(p[1]).transpose(), n, reference_length,
                                  options_.degenerate_frame_tolerance);
  }
  return result;
}

WaveletTransform::LevelAnalysis WaveletTransform::analyze_level(int j, const RowMatrixX3d& fine) const {
  const Level& level = levels_.at(j);
  const int m = level.n_fine - level.n_coarse;
  if (fine.rows() != level.n_fine)
    throw std::invalid_argument("analyze_level: level " + std::to_string(j + 1) + " needs " +
                                std::to_string(level.n_fine) + " positions, got " + std::to_string(fine.rows()));
  LevelAnalysis r;
  r.coarse = fine.topRows(level.n_coarse);
  r.details = fine.bottomRows(m) - predict(j, r.coarse);
  if (options_.update) update(j, r.coarse, r.details, +1.0);
  r.stats.level = j + 1;
  r.stats.count = m;
  for (int i = 0; i < m; ++i) {
    const double sq = r.details.row(i).squaredNorm();
    r.stats.energy += sq;
    r.stats.max = std::max(r.stats.max, std::sqrt(sq));
  }
  r.stats.rms = std::sqrt(r.stats.energy / m);
  if (options_.frame == DetailFrame::local) {
    const std::vector<LocalFrame> f = frames(j, r.coarse);
    for (int i = 0; i < m; ++i) {
      r.details.row(i) = to_local(f[i], r.details.row(i).transpose()).transpose();
      r.stats.degenerate_frames += f[i].degenerate ? 1 : 0;
    }
  }
  return r;
}

RowMatrixX3d WaveletTransform::synthesize_level(int j, const RowMatrixX3d& coarse, const RowMatrixX3d& details) const {
  const Level& level = levels_.at(j);
  const int m = level.n_fine - level.n_coarse;
  if (coarse.rows() != level.n_coarse || details.rows() != m)
    throw std::invalid_argument("synthesize_level: level " + std::to_string(j) + " needs " +
                                std::to_string(level.n_coarse) + " positions and " + std::to_string(m) + " details");
  RowMatrixX3d d = details;
  if (options_.frame == DetailFrame::local) {
    const std::vector<LocalFrame> f = frames(j, coarse);
    for (int i = 0; i < m; ++i) d.row(i) = to_global(f[i], details.row(i).transpose()).transpose();
  }
  RowMatrixX3d fine(level.n_fine, 3);
  RowMatrixX3d even = coarse;
  if (options_.update) update(j, even, d, -1.0);
  fine.topRows(level.n_coarse) = even;
  fine.bottomRows(m) = predict(j, even) + d;
  return fine;
}

WaveletAnalysis WaveletTransform::analyze(const RowMatrixX3d& finest) const {
  const int L = levels();
  WaveletAnalysis a;
  a.levels.resize(L + 1);
  a.details.resize(L);
  a.stats.resize(L);
  a.levels[L] = finest;
  for (int j = L - 1; j >= 0; --j) {
    LevelAnalysis step = analyze_level(j, a.levels[j + 1]);
    a.levels[j] = std::move(step.coarse);
    a.details[j] = std::move(step.details);
    a.stats[j] = step.stats;
  }
  a.base = a.levels[0];
  return a;
}

RowMatrixX3d WaveletTransform::synthesize(const RowMatrixX3d& base, const std::vector<RowMatrixX3d>& details,
                                          int level) const {
  const int target = level < 0 ? levels() : level;
  if (target > levels() || static_cast<int>(details.size()) < target)
    throw std::invalid_argument("synthesize: not enough levels of details");
  RowMatrixX3d S = base;
  for (int j = 0; j < target; ++j) S = synthesize_level(j, S, details[j]);
  return S;
}

}  // namespace mrsnake
