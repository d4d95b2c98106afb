#include "remesh/feature_snap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "mesh/distance.h"
#include "mesh/parallel.h"
#include "remesh/lift.h"
#include "remesh/surface_moves.h"

namespace mrsnake {

namespace {

// Where the input vertices stand against the level before any snap: each one's level face
// and its distance, and per level face the input vertices on it (so that a snap can be judged
// on the input around it). The face is the nearest one in 3D, or the one over the input
// vertex in D; the distance is then an upper bound (`exact` false).
struct InputAgainstLevel {
  std::vector<int> level_face;
  std::vector<double> distance;
  std::vector<int> under_offset, under;  ///< face f's input vertices: under[under_offset[f] ..]
  double largest = 0;
  bool exact = true;
};

// p's distance to level face f of (X, F).
double distance_to_face(const Eigen::Vector3d& p, const RowMatrixX3d& X, const RowMatrixX3i& F, int f) {
  return point_triangle_distance(p, X.row(F(f, 0)).transpose(), X.row(F(f, 1)).transpose(), X.row(F(f, 2)).transpose());
}

// Whether `faces` gives every input vertex a face of F (else the tree measures the input).
bool one_face_per_input_vertex(const std::vector<int>& faces, const RowMatrixX3i& F, Eigen::Index input_vertices) {
  return static_cast<Eigen::Index>(faces.size()) == input_vertices &&
         std::all_of(faces.begin(), faces.end(), [&](int f) { return f >= 0 && f < F.rows(); });
}

// Each input vertex's distance to its face in D, or (faces_in_domain not one level face per
// input vertex, as when empty) its nearest face and distance by a closest-point tree.
void measure_distances(const RowMatrixX3d& X, const RowMatrixX3i& F, const RowMatrixX3d& surface_V,
                       std::vector<int> faces_in_domain, InputAgainstLevel& input) {
  const int input_vertices = static_cast<int>(surface_V.rows());
  input.distance.resize(input_vertices);
  input.exact = !one_face_per_input_vertex(faces_in_domain, F, surface_V.rows());
  if (!input.exact) {
    input.level_face = std::move(faces_in_domain);
    parallel_ranges(static_cast<std::size_t>(input_vertices), [&](std::size_t begin, std::size_t end) {
      for (auto s = static_cast<int>(begin); s < static_cast<int>(end); ++s)
        input.distance[s] = distance_to_face(surface_V.row(s).transpose(), X, F, input.level_face[s]);
    });
    return;
  }
  input.level_face.resize(input_vertices);
  const SurfaceLocator level(TriMesh{X, F});
  // Every input vertex is queried (90k on a liver): both cores.
  parallel_ranges(static_cast<std::size_t>(input_vertices), [&](std::size_t begin, std::size_t end) {
    for (auto s = static_cast<int>(begin); s < static_cast<int>(end); ++s) {
      const SurfaceLocator::Hit hit = level.closest(surface_V.row(s).transpose());
      input.level_face[s] = hit.face;
      input.distance[s] = hit.distance;
    }
  });
}

InputAgainstLevel measure_input_against_level(const RowMatrixX3d& X, const RowMatrixX3i& F,
                                              const RowMatrixX3d& surface_V, std::vector<int> faces_in_domain) {
  const int m = static_cast<int>(F.rows());
  const int input_vertices = static_cast<int>(surface_V.rows());
  InputAgainstLevel input;
  measure_distances(X, F, surface_V, std::move(faces_in_domain), input);
  input.under_offset.assign(m + 1, 0);
  for (int s = 0; s < input_vertices; ++s) ++input.under_offset[input.level_face[s] + 1];
  for (int f = 0; f < m; ++f) input.under_offset[f + 1] += input.under_offset[f];
  input.under.resize(input.under_offset[m]);
  std::vector<int> fill(input.under_offset.begin(), input.under_offset.end() - 1);
  for (int s = 0; s < input_vertices; ++s) input.under[fill[input.level_face[s]]++] = s;
  input.largest = *std::max_element(input.distance.begin(), input.distance.end());
  return input;
}

// The input vertices to try as tips, farthest first: beyond far_threshold, on a face of the
// input, and not on its rim.
std::vector<int> far_tips(const InputAgainstLevel& input, double far_threshold, const RowMatrixX3i& input_F,
                          const std::vector<bool>& input_rim) {
  std::vector<bool> on_a_face(input.distance.size(), false);
  for (int f = 0; f < input_F.rows(); ++f)
    for (int k = 0; k < 3; ++k) on_a_face[input_F(f, k)] = true;
  std::vector<int> far;
  for (int s = 0; s < static_cast<int>(input.distance.size()); ++s)
    if (input.distance[s] > far_threshold && on_a_face[s] && !input_rim[s]) far.push_back(s);
  const std::vector<double>& d = input.distance;
  std::sort(far.begin(), far.end(), [&](int a, int b) { return d[a] > d[b] || (d[a] == d[b] && a < b); });
  return far;
}

// Smallest angle (degrees) of v's triangles with v at x.
double star_smallest_angle(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars, int v,
                           const Eigen::Vector3d& x) {
  double smallest = 180;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
    const int f = stars.faces[i];
    Eigen::Vector3d P[3] = {X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))};
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) P[k] = x;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = P[(k + 1) % 3] - P[k], b = P[(k + 2) % 3] - P[k];
      smallest = std::min(smallest, std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI);
    }
  }
  return smallest;
}

// The least part of the way to a tip that a snap moves a vertex: less cannot lower the tip's
// distance by the quarter that the default min_gain asks.
constexpr double kLeastFraction = 0.25;

// What a snap of a level vertex onto a tip comes to.
enum class SnapVerdict { take, refuse, tip_already_close };

// The corners of a level face, nearest to p first.
std::array<int, 3> corners_nearest_first(const RowMatrixX3d& X, const RowMatrixX3i& F, int face,
                                         const Eigen::Vector3d& p) {
  std::array<int, 3> corners = {F(face, 0), F(face, 1), F(face, 2)};
  std::array<double, 3> distance;
  for (int k = 0; k < 3; ++k) distance[k] = (X.row(corners[k]).transpose() - p).squaredNorm();
  std::array<int, 3> order = {0, 1, 2};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return distance[a] < distance[b]; });
  return {corners[order[0]], corners[order[1]], corners[order[2]]};
}

// The faces of v's star and of its neighbours' stars: the triangles a move of v can change the
// nearest point on, for the input near v. Reads X as it is when asked (earlier snaps included).
class SnapRegion {
 public:
  SnapRegion(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars, const InputAgainstLevel& input,
             const RowMatrixX3d& surface_V)
      : X_(X), F_(F), stars_(stars), input_(input), surface_V_(surface_V), mark_(F.rows(), -1) {}

  void collect(int v) {
    faces_.clear();
    ++stamp_;
    for (int i = stars_.offset[v]; i < stars_.offset[v + 1]; ++i)
      for (int k = 0; k < 3; ++k) {
        const int w = F_(stars_.faces[i], k);
        for (int j = stars_.offset[w]; j < stars_.offset[w + 1]; ++j) {
          const int f = stars_.faces[j];
          if (mark_[f] == stamp_) continue;
          mark_[f] = stamp_;
          faces_.push_back(f);
        }
      }
  }

  // Distance from p to the region's triangles with v at x.
  double distance(const Eigen::Vector3d& p, int v, const Eigen::Vector3d& x) const {
    double d = std::numeric_limits<double>::infinity();
    for (int f : faces_) {
      Eigen::Vector3d P[3] = {X_.row(F_(f, 0)), X_.row(F_(f, 1)), X_.row(F_(f, 2))};
      for (int k = 0; k < 3; ++k)
        if (F_(f, k) == v) P[k] = x;
      d = std::min(d, point_triangle_distance(p, P[0], P[1], P[2]));
    }
    return d;
  }

  // The largest distance from the input vertices under the region to its triangles, v at x.
  double error(int v, const Eigen::Vector3d& x) const {
    double error = 0;
    for (int f : faces_)
      for (int i = input_.under_offset[f]; i < input_.under_offset[f + 1]; ++i)
        error = std::max(error, distance(surface_V_.row(input_.under[i]).transpose(), v, x));
    return error;
  }

 private:
  const RowMatrixX3d& X_;
  const RowMatrixX3i& F_;
  const VertexStars& stars_;
  const InputAgainstLevel& input_;
  const RowMatrixX3d& surface_V_;
  std::vector<int> faces_, mark_;
  int stamp_ = 0;
};

// Exact distances from a few input points to the level (X, F), for the decisions that need
// them: whether a point is beyond a bound. The faces around a point's level face are tried
// first, and settle most points; the others are measured against every face, and past
// kMaxFullScans of those against a closest-point tree (its build costs more than a few scans).
class FewPointDistances {
 public:
  FewPointDistances(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars)
      : X_(X), F_(F), stars_(stars) {}

  // p's distance to the level if it is beyond `floor`, else a distance at most `floor` (a
  // face that near); `face` is a level face near p.
  double distance_beyond(const Eigen::Vector3d& p, int face, double floor) {
    for (int k = 0; k < 3; ++k) {
      const int w = F_(face, k);
      for (int i = stars_.offset[w]; i < stars_.offset[w + 1]; ++i) {
        const double d = distance_to_face(p, X_, F_, stars_.faces[i]);
        if (d <= floor) return d;
      }
    }
    return distance(p);
  }

 private:
  static constexpr int kMaxFullScans = 32;

  double distance(const Eigen::Vector3d& p) {
    if (full_scans_ >= kMaxFullScans) {
      if (!tree_) tree_.emplace(TriMesh{X_, F_});
      return tree_->closest(p).distance;
    }
    ++full_scans_;
    double d = std::numeric_limits<double>::infinity();
    for (int f = 0; f < F_.rows(); ++f) d = std::min(d, distance_to_face(p, X_, F_, f));
    return d;
  }

  const RowMatrixX3d& X_;
  const RowMatrixX3i& F_;
  const VertexStars& stars_;
  int full_scans_ = 0;
  std::optional<SurfaceLocator> tree_;
};

// The largest input-to-level distance of (X, F), exactly. From upper bounds: the vertex of the
// largest bound is measured, and then only those whose bound exceeds the largest distance
// found so far, farthest first: a few, where the faces in D are the nearest ones or close to
// them (so only those few are sorted, not the whole input).
double exact_largest_distance(const InputAgainstLevel& input, const RowMatrixX3d& X, const RowMatrixX3i& F,
                              const VertexStars& stars, const RowMatrixX3d& surface_V) {
  if (input.exact) return input.largest;
  const std::vector<double>& bound = input.distance;
  FewPointDistances level(X, F, stars);
  const auto measure = [&](int s, double floor) {
    return level.distance_beyond(surface_V.row(s).transpose(), input.level_face[s], floor);
  };
  const auto farthest = static_cast<int>(std::max_element(bound.begin(), bound.end()) - bound.begin());
  double largest = measure(farthest, 0);
  std::vector<int> above;
  for (int s = 0; s < static_cast<int>(bound.size()); ++s)
    if (bound[s] > largest && s != farthest) above.push_back(s);
  std::sort(above.begin(), above.end(), [&](int a, int b) { return bound[a] > bound[b]; });
  for (int s : above) {
    if (bound[s] <= largest) break;
    largest = std::max(largest, measure(s, largest));
  }
  return largest;
}

// Whether the largest input-to-level distance, with the `moved` vertices snapped, is at most
// `limit`: the same decision as measuring the whole input, up to rounding, without measuring
// it all again. An input vertex whose level face did not change is at most as far as before
// (that face is still there), so only those on a changed face and those that were already
// beyond the limit can be beyond it now.
bool largest_distance_within(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars,
                             const std::vector<bool>& moved, const InputAgainstLevel& input,
                             const RowMatrixX3d& surface_V, double limit) {
  std::vector<bool> changed(F.rows(), false);
  for (int v = 0; v < static_cast<int>(moved.size()); ++v)
    if (moved[v])
      for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) changed[stars.faces[i]] = true;
  FewPointDistances level(X, F, stars);
  for (int s = 0; s < static_cast<int>(input.distance.size()); ++s)
    if ((changed[input.level_face[s]] || input.distance[s] > limit) &&
        level.distance_beyond(surface_V.row(s).transpose(), input.level_face[s], limit) > limit)
      return false;
  return true;
}

// Each input vertex's level face in D: a walk in the level's triangulation of D from a face
// of a level vertex that lies in one of the input vertex's faces (hints: each level vertex's
// input face), else from the face found for the input vertex before it, so that most walks
// take a step or two.
template <class PointOfInput>
std::vector<int> locate_input_in_level(const RowMatrixX3d& U, const RowMatrixX3i& F, const VertexStars& stars,
                                       const RowMatrixX3i& input_F, int input_vertices, const std::vector<int>& hints,
                                       const PointOfInput& point_of) {
  std::vector<int> start_of_input_face(input_F.rows(), -1);
  for (int v = 0; v < static_cast<int>(hints.size()); ++v)
    if (hints[v] >= 0 && hints[v] < input_F.rows() && stars.offset[v] < stars.offset[v + 1])
      start_of_input_face[hints[v]] = stars.faces[stars.offset[v]];
  std::vector<int> start(input_vertices, -1);
  for (int f = 0; f < input_F.rows(); ++f)
    if (start_of_input_face[f] >= 0)
      for (int k = 0; k < 3; ++k) start[input_F(f, k)] = start_of_input_face[f];
  const DomainMesh level(U, F);
  std::vector<int> face(input_vertices);
  parallel_ranges(static_cast<std::size_t>(input_vertices), [&](std::size_t begin, std::size_t end) {
    int previous = 0;
    for (auto s = static_cast<int>(begin); s < static_cast<int>(end); ++s)
      previous = face[s] = level.locate(point_of(s), start[s] >= 0 ? start[s] : previous).face;
  });
  return face;
}

}  // namespace

int snap_level_to_input_tips(const RowMatrixX3i& F, RowMatrixX3d& X, const RowMatrixX3d& surface_V,
                             const RowMatrixX3i& input_F, const std::vector<bool>& rim,
                             const std::vector<bool>& input_rim, const SnapInDomain& domain,
                             const FeatureSnapOptions& options, std::vector<bool>* snapped) {
  const int n = static_cast<int>(X.rows());
  if (snapped) snapped->assign(n, false);
  if (F.rows() == 0 || surface_V.rows() == 0 || options.max_snaps <= 0) return 0;
  const VertexStars stars(F, n);
  const double threshold = options.min_distance * mean_edge_length(X, F);
  const InputAgainstLevel input =
      measure_input_against_level(X, F, surface_V, domain.input_faces ? domain.input_faces() : std::vector<int>{});
  // Exact, so that an overstated bound hides no tip and loosens no decision.
  const double largest = exact_largest_distance(input, X, F, stars, surface_V);
  const double far_threshold = std::max(threshold, options.min_share_of_largest * largest);

  SnapRegion region(X, F, stars, input, surface_V);
  std::vector<bool> moved(n, false);
  const RowMatrixX3d X_before = X;
  int snaps = 0, judged = 0;
  const int max_judged = 8 * options.max_snaps;  // the region error is the costly part
  // Where v goes, the fraction t of the way to input vertex s, if it may move there: in D, and
  // with its triangles within the bounds.
  const auto within_bounds = [&](int v, int s, double t) -> std::optional<Eigen::Vector3d> {
    if (moved[v] || rim[v]) return std::nullopt;
    const std::optional<Eigen::Vector3d> to = domain.toward(v, s, t);
    if (!to || star_quality(X, F, stars, v, *to) < options.min_quality ||
        star_smallest_angle(X, F, stars, v, *to) < options.min_angle_deg)
      return std::nullopt;
    return to;
  };
  // The largest fraction of the way to s, from 1/4, that v can go within the bounds (to 1/40
  // of the way, by bisection; the bounds tighten as v goes), or 0 if not even 1/4.
  const auto farthest_within_bounds = [&](int v, int s) {
    if (!within_bounds(v, s, kLeastFraction)) return 0.0;
    double within = kLeastFraction, beyond = 1.0;
    while (beyond - within > 0.025) {
      const double t = 0.5 * (within + beyond);
      (within_bounds(v, s, t) ? within : beyond) = t;
    }
    return within;
  };
  // Whether moving v the fraction t of the way to input vertex s (at x) is worth it, and where to.
  struct Verdict {
    SnapVerdict verdict;
    Eigen::Vector3d position;
  };
  const auto judge_snap = [&](int v, int s, const Eigen::Vector3d& x, double t) -> Verdict {
    const Verdict refuse{SnapVerdict::refuse, Eigen::Vector3d::Zero()};
    if (moved[v] || rim[v]) return refuse;
    const Eigen::Vector3d x_old = X.row(v).transpose();
    region.collect(v);
    // An earlier snap nearby may have fixed this tip already: its distance now, not before.
    if (!(region.distance(x, v, x_old) > threshold)) return {SnapVerdict::tip_already_close, x_old};
    const std::optional<Eigen::Vector3d> to = within_bounds(v, s, t);
    if (!to) return refuse;
    // Worth it only if the input around v ends up really closer to the level: moving v onto s
    // also moves its triangles away from the input v stood on.
    ++judged;
    if (!(region.error(v, *to) <= (1 - options.min_gain) * region.error(v, x_old))) return refuse;
    return {SnapVerdict::take, *to};
  };
  for (int s : far_tips(input, far_threshold, input_F, input_rim)) {
    if (snaps >= options.max_snaps || judged >= max_judged) break;
    const Eigen::Vector3d x = surface_V.row(s).transpose();
    // The nearest corner of the tip's level face that can take it (the nearest may be held by
    // its triangles' quality where the next one is not) the whole way, else the nearest that
    // can go part of the way, as far as the bounds allow.
    const std::array<int, 3> corners = corners_nearest_first(X, F, input.level_face[s], x);
    bool done = false;
    for (int phase = 0; phase < 2; ++phase)
      for (int k = 0; k < 3 && !done && judged < max_judged; ++k) {
        const double t = phase == 0 ? 1.0 : farthest_within_bounds(corners[k], s);
        if (!(t > 0)) continue;
        const Verdict verdict = judge_snap(corners[k], s, x, t);
        done = verdict.verdict != SnapVerdict::refuse;
        if (verdict.verdict != SnapVerdict::take) continue;
        domain.apply(corners[k], s, t);
        X.row(corners[k]) = verdict.position.transpose();
        moved[corners[k]] = true;
        ++snaps;
      }
  }
  // The snaps cost triangle quality: keep them only if they really bring the input closer
  // overall (the largest distance drops), not only around each snapped vertex.
  if (snaps > 0 && !largest_distance_within(X, F, stars, moved, input, surface_V, (1 - options.min_gain) * largest)) {
    X = X_before;
    domain.undo();
    return 0;
  }
  if (snapped) *snapped = moved;
  return snaps;
}

int snap_to_input_tips(DomainKind kind, const RowMatrixX3i& F, const DomainMesh& param, const RowMatrixX3d& surface_V,
                       RowMatrixX3d& U, RowMatrixX3d& X, std::vector<int>& hints, const FeatureSnapOptions& options,
                       std::vector<bool>* snapped) {
  const int n = static_cast<int>(U.rows());
  const VertexStars stars(F, n);
  const auto& PF = param.faces();
  const auto& PD = param.positions();
  const bool disk = kind == DomainKind::disk;
  std::vector<int> face_of(PD.rows(), -1);
  for (int f = 0; f < PF.rows(); ++f)
    for (int k = 0; k < 3; ++k) face_of[PF(f, k)] = f;
  const RowMatrixX3d U_before = U;
  const std::vector<int> hints_before = hints;
  const auto point_of = [&](int s) { return project_to_domain(kind, PD.row(s).transpose(), false); };
  // v the fraction t of the way to input vertex s's point of D (exactly that point at t = 1).
  const auto point_toward = [&](int v, int s, double t) -> Eigen::Vector3d {
    return t == 1 ? point_of(s) : project_to_domain(kind, (1 - t) * U.row(v).transpose() + t * point_of(s), false);
  };
  const auto toward = [&](int v, int s, double t) -> std::optional<Eigen::Vector3d> {
    const Eigen::Vector3d u = point_toward(v, s, t);
    if (!star_unflipped_in_domain(U, F, stars, v, u)) return std::nullopt;
    if (t == 1) return Eigen::Vector3d(surface_V.row(s).transpose());
    int hint = hints[v];
    return lift_location(surface_V, PF, param.locate(u, hint));
  };
  const auto apply = [&](int v, int s, double t) {
    const Eigen::Vector3d u = point_toward(v, s, t);
    hints[v] = t == 1 ? face_of[s] : param.locate(u, hints[v]).face;
    U.row(v) = u.transpose();
  };
  const SnapInDomain domain{
      toward, apply,
      [&] {
        U = U_before;
        hints = hints_before;
      },
      [&] { return locate_input_in_level(U, F, stars, PF, static_cast<int>(PD.rows()), hints, point_of); }};
  return snap_level_to_input_tips(
      F, X, surface_V, PF, disk ? boundary_vertices(F, stars) : std::vector<bool>(n, false),
      disk ? boundary_vertices(PF, static_cast<int>(PD.rows())) : std::vector<bool>(PD.rows(), false), domain, options,
      snapped);
}

}  // namespace mrsnake
