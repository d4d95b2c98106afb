#include "snake/deformable_surface.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <deque>

#include "mesh/distance.h"

namespace mrsnake {

Eigen::VectorXd relative_normal_umbrella(const VertexRings& rings, const RowMatrixX3i& F, const RowMatrixX3d& model_V) {
  RowMatrixX3d N, U;
  Eigen::VectorXd L;
  vertex_normals(model_V, F, N);
  umbrella(rings, model_V, U);
  ring_edge_lengths(rings, model_V, L);
  Eigen::VectorXd h(model_V.rows());
  for (int v = 0; v < model_V.rows(); ++v) h[v] = L[v] > 0 ? U.row(v).dot(N.row(v)) / L[v] : 0.0;
  return h;
}

namespace {
// The tangent plane of vertex v: e1 along the ring edge to its first neighbour projected on
// the plane (any other if that one is parallel to the normal), e2 = n × e1.
void tangent_basis(const RowMatrixX3d& V, const VertexRings& rings, int v, const Eigen::Vector3d& n,
                   Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  e1 = Eigen::Vector3d::Zero();
  const Eigen::Vector3d x = V.row(v).transpose();
  for (int k = rings.offsets[v]; k < rings.offsets[v + 1] && e1.squaredNorm() < 1e-20; ++k) {
    e1 = V.row(rings.neighbors[k]).transpose() - x;
    e1 -= e1.dot(n) * n;
  }
  e1 = e1.squaredNorm() > 1e-20 ? e1.normalized() : n.unitOrthogonal();
  e2 = n.cross(e1);
}
}  // namespace

TangentialPrior tangential_prior(const VertexRings& rings, const RowMatrixX3i& F, const RowMatrixX3d& model_V) {
  RowMatrixX3d N, U;
  Eigen::VectorXd L;
  vertex_normals(model_V, F, N);
  umbrella(rings, model_V, U);
  ring_edge_lengths(rings, model_V, L);
  TangentialPrior t;
  t.umbrella.resize(model_V.rows());
  t.ring_directions.resize(rings.neighbors.size());
  for (int v = 0; v < model_V.rows(); ++v) {
    const Eigen::Vector3d n = N.row(v).transpose(), x = model_V.row(v).transpose(), u = U.row(v).transpose();
    Eigen::Vector3d e1, e2;
    tangent_basis(model_V, rings, v, n, e1, e2);
    t.umbrella[v] = L[v] > 0 ? std::complex<double>(u.dot(e1), u.dot(e2)) / L[v] : 0.0;
    for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) {
      const Eigen::Vector3d d = model_V.row(rings.neighbors[k]).transpose() - x;
      const std::complex<double> z(d.dot(e1), d.dot(e2));
      t.ring_directions[k] = std::abs(z) > 0 ? z / std::abs(z) : 0.0;
    }
  }
  return t;
}

DeformableSurface::DeformableSurface(RowMatrixX3i F, const RowMatrixX3d& model_V, SnakeOptions options)
    : F_(std::move(F)), rings_(build_vertex_rings(F_, static_cast<int>(model_V.rows()))), options_(options) {
  prior_ = relative_normal_umbrella(rings_, F_, model_V);
  tangential_ = tangential_prior(rings_, F_, model_V);
}

namespace {
struct InternalTerms {
  RowMatrixX3d force;
  double energy = 0;
};

InternalTerms compute_internal(const VertexRings& rings, const RowMatrixX3i& F, const Eigen::VectorXd& prior,
                               const TangentialPrior& tangential, const SnakeOptions& o, const RowMatrixX3d& V,
                               const RowMatrixX3d& N) {
  const int n = static_cast<int>(V.rows());
  RowMatrixX3d U;
  Eigen::VectorXd L;
  umbrella(rings, V, U);
  ring_edge_lengths(rings, V, L);
  (void)F;
  InternalTerms t;
  t.force.resize(n, 3);
  RowMatrixX3d residual(n, 3);
  double energy = 0;
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d nv = N.row(v), uv = U.row(v);
    const double h = uv.dot(nv);
    const double rel = h - prior[v] * L[v];
    residual.row(v) = rel * nv;
    Eigen::Vector3d tangential_force = uv - h * nv;
    if (o.tangential_weight > 0 && L[v] > 0) {
      // The model's tangential umbrella, turned into this vertex's tangent plane by the
      // rotation that best maps the model's ring directions onto the current ones.
      Eigen::Vector3d e1, e2;
      tangent_basis(V, rings, v, nv, e1, e2);
      const Eigen::Vector3d x = V.row(v).transpose();
      std::complex<double> turn = 0.0;
      for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) {  // longer edges weigh more
        const Eigen::Vector3d d = V.row(rings.neighbors[k]).transpose() - x;
        turn += std::complex<double>(d.dot(e1), d.dot(e2)) * std::conj(tangential.ring_directions[k]);
      }
      const std::complex<double> target =
          (std::abs(turn) > 0 ? turn / std::abs(turn) : 1.0) * tangential.umbrella[v] * L[v];
      tangential_force -= target.real() * e1 + target.imag() * e2;
    }
    t.force.row(v) = (o.membrane_weight * h + o.prior_weight * rel) * nv + o.tangential_weight * tangential_force;
    if (L[v] > 0) energy += 0.5 * (o.prior_weight * rel * rel + o.membrane_weight * h * h) / (L[v] * L[v]);
  }
  if (o.thin_plate_weight > 0) {
    for (int v = 0; v < n; ++v) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k)
        mean += residual.row(rings.neighbors[k]).transpose();
      const int val = rings.valence(v);
      if (val > 0) t.force.row(v) -= o.thin_plate_weight * (mean / val - residual.row(v).transpose()).transpose();
    }
  }
  t.energy = n > 0 ? energy / n : 0.0;
  return t;
}
}  // namespace

RowMatrixX3d DeformableSurface::internal_forces(const RowMatrixX3d& V) const {
  RowMatrixX3d N;
  vertex_normals(V, F_, N);
  return compute_internal(rings_, F_, prior_, tangential_, options_, V, N).force;
}

SnakeLevelReport DeformableSurface::run(RowMatrixX3d& V, const ExternalSearch& search, double search_step_mm,
                                        double max_displacement_mm) const {
  const SnakeOptions& o = options_;
  const int n = static_cast<int>(V.rows());
  SnakeLevelReport report;
  RowMatrixX3d N, FN_start, FN_old, FN_new, step(n, 3);
  Eigen::VectorXd L;
  face_normals(V, F_, FN_start);
  const RowMatrixX3d V_start = V;
  std::deque<double> offset_history, energy_history;
  std::vector<char> flagged(static_cast<std::size_t>(n));
  for (int it = 0; it < o.max_iterations; ++it) {
    vertex_normals(V, F_, N);
    ring_edge_lengths(rings_, V, L);
    SearchResult found = search(V, N);
    Eigen::VectorXd offsets = found.offsets;
    median_on_rings(rings_, offsets, o.offset_median);
    smooth_on_rings(rings_, offsets, o.offset_smoothing);
    const InternalTerms internal = compute_internal(rings_, F_, prior_, tangential_, o, V, N);
    report.external_energy = found.costs.size() ? found.costs.mean() : 0.0;
    report.internal_energy = internal.energy;
    report.energy = report.external_energy + report.internal_energy;
    report.mean_abs_offset_mm = offsets.size() ? offsets.cwiseAbs().mean() : 0.0;
    report.iterations = it;
    report.history.push_back(
        {report.energy, report.external_energy, report.internal_energy, report.mean_abs_offset_mm});

    // Convergence on the matched offsets and the energy, not on raw vertex motion.
    offset_history.push_back(report.mean_abs_offset_mm);
    energy_history.push_back(report.energy);
    if (static_cast<int>(offset_history.size()) > o.patience + 1) {
      offset_history.pop_front();
      energy_history.pop_front();
    }
    if (it >= o.min_iterations && static_cast<int>(offset_history.size()) == o.patience + 1) {
      const auto [omin, omax] = std::minmax_element(offset_history.begin(), offset_history.end());
      const auto [emin, emax] = std::minmax_element(energy_history.begin(), energy_history.end());
      const bool offsets_settled = (*omax - *omin) < o.tolerance * search_step_mm;
      const bool energy_settled = (*emax - *emin) < o.tolerance * std::max(1e-9, std::abs(*emax));
      if (offsets_settled && energy_settled) {
        report.converged = true;
        break;
      }
    }

    for (int v = 0; v < n; ++v) {
      const Eigen::Vector3d nv = N.row(v);
      Eigen::Vector3d s = o.time_step * (internal.force.row(v).transpose() + o.external_weight * offsets[v] * nv);
      // Along the normal, never move past the matched offset (plus a small slack); in all
      // directions, at most a fraction of the local edge length.
      const double cap = o.max_step_fraction * L[v];
      const double along = s.dot(nv);
      const double limit = std::abs(offsets[v]) + 0.25 * cap;
      if (std::abs(along) > limit) s -= (along - std::copysign(limit, along)) * nv;
      const double len = s.norm();
      if (len > cap && len > 0) s *= cap / len;
      // Trust region around the level's start.
      const Eigen::Vector3d start = V_start.row(v).transpose();
      const Eigen::Vector3d moved = V.row(v).transpose() + s - start;
      const double dist = moved.norm();
      if (dist > max_displacement_mm) s = start + moved * (max_displacement_mm / dist) - V.row(v).transpose();
      step.row(v) = s.transpose();
    }

    // Apply, then undo (halve, then drop) the steps of vertices whose faces would flip.
    face_normals(V, F_, FN_old);
    RowMatrixX3d V_new = V + step;
    // Halve three times, then drop steps until no face folds (the previous iterate has no
    // fold, so dropping every step terminates).
    for (int attempt = 0; attempt < 3 + n; ++attempt) {
      face_normals(V_new, F_, FN_new);
      std::fill(flagged.begin(), flagged.end(), 0);
      bool any = false;
      // A fold: a face turned against its normal at the level's start, or by more than
      // 60° in one step (a step is at most a fraction of an edge, so only a fold does that).
      for (int f = 0; f < F_.rows(); ++f)
        if ((FN_old.row(f).dot(FN_new.row(f)) < 0.5 && FN_old.row(f).squaredNorm() > 0) ||
            (FN_start.row(f).dot(FN_new.row(f)) <= 0.0 && FN_start.row(f).squaredNorm() > 0)) {
          for (int k = 0; k < 3; ++k) flagged[F_(f, k)] = 1;
          any = true;
        }
      if (!any) break;
      for (int v = 0; v < n; ++v)
        if (flagged[v]) {
          ++report.rejected_steps;
          step.row(v) *= attempt < 3 ? 0.5 : 0.0;
          V_new.row(v) = V.row(v) + step.row(v);
        }
    }
    V.swap(V_new);
    report.iterations = it + 1;
  }
  face_normals(V, F_, FN_new);
  for (int f = 0; f < F_.rows(); ++f)
    if (FN_start.row(f).dot(FN_new.row(f)) < 0) ++report.flipped_faces;
  return report;
}

UndoOutcome undo_self_intersections(RowMatrixX3d& V, const RowMatrixX3d& safe, const RowMatrixX3i& F,
                                    const VertexRings& rings, int max_rounds) {
  const int n = static_cast<int>(V.rows());
  std::vector<char> moved(static_cast<std::size_t>(n), 0), flagged(static_cast<std::size_t>(n));
  UndoOutcome out;
  for (int round = 0;; ++round) {
    const auto pairs = crossing_face_pairs(TriMesh{V, F});
    out.remaining_pairs = static_cast<int>(pairs.size());
    if (pairs.empty() || round == max_rounds) break;
    std::fill(flagged.begin(), flagged.end(), 0);
    for (const auto& [f, g] : pairs)
      for (const int face : {f, g})
        for (int c = 0; c < 3; ++c) {
          const int v = F(face, c);
          flagged[v] = 1;
          for (int k = rings.offsets[v]; k < rings.offsets[v + 1]; ++k) flagged[rings.neighbors[k]] = 1;
        }
    // Halve the displacements a few times, then take the safe positions.
    const double keep = round + 1 < max_rounds ? 0.5 : 0.0;
    for (int v = 0; v < n; ++v)
      if (flagged[v]) {
        V.row(v) = safe.row(v) + keep * (V.row(v) - safe.row(v));
        moved[v] = 1;
      }
  }
  out.moved_vertices = static_cast<int>(std::count(moved.begin(), moved.end(), 1));
  return out;
}

}  // namespace mrsnake
