#pragma once
/// \file deformable_surface.h
/// The snake on one level of the hierarchy: explicit steps of the discrete energy on the
/// fixed connectivity (finite differences on the 1-rings), never resampling.
///
/// Per vertex v, with n_v its unit normal, ℓ_v its mean ring edge length and
/// U_v = mean(ring) − x_v its umbrella (membrane) vector, h_v = U_v·n_v:
///  - membrane     α·h_v·n_v                      (a plain umbrella: shrinks the surface)
///  - prior        w_p·(h_v − ĥ_v·ℓ_v)·n_v         (the umbrella measured relative to the
///                 model's own, ĥ_v = h/ℓ on the model's level: zero at the model's shape,
///                 similarity invariant; this is the local-frame detail prior)
///  - thin plate   −β·(mean(r_ring) − r_v), r_v = (h_v − ĥ_v·ℓ_v)·n_v (squared umbrella of
///                 the prior residual)
///  - tangential   w_t·(U_v − h_v·n_v − T_v)       (keeps the model's sampling: T_v is the
///                 model's tangential umbrella, scaled by ℓ_v/ℓ̂_v and turned into the current
///                 tangent plane by the rotation that best maps the model's ring directions
///                 onto the current ones; zero at the model's shape in any pose, so that the
///                 wavelet details land where the model put them; a plain uniform pull
///                 would deform the coarse meshes, docs/snake.md)
///  - external     w_e·o_v·n_v, o_v the matched offset along the normal, averaged over the
///                 1-ring to resist noise
/// Each step x ← x + τ·F is capped to max_step_fraction·ℓ_v and to |o_v| + that cap along
/// the normal. Faces that would turn against their normal at the level's start, or by more
/// than 60° in one step, reject the step of their vertices (halved, then dropped). The run stops when the matched
/// offsets and the energy stop changing.
#include <complex>
#include <functional>
#include <limits>
#include <vector>

#include "mesh/trimesh.h"
#include "snake/forces.h"
#include "snake/surface_geometry.h"

namespace mrsnake {

struct SnakeOptions {
  double membrane_weight = 0.0;     ///< α
  double thin_plate_weight = 0.05;  ///< β (τ·β must stay below ~0.4)
  double prior_weight = 0.35;       ///< w_p
  double tangential_weight =
      0.35;  ///< w_t, towards the model's tangential umbrella (τ·(α + w_p + w_t) must stay below ~1.2)
  double external_weight = 0.35;   ///< w_e: fraction of the matched offset taken per step (segment.h)
  double time_step = 1.0;          ///< τ
  double max_step_fraction = 0.3;  ///< cap on a step, in local edge lengths
  int offset_median = 1;           ///< ring-median passes over the matched offsets (before the averaging)
  int offset_smoothing = 1;        ///< ring-averaging passes over the matched offsets
  int max_iterations = 40;
  int min_iterations = 4;
  /// Convergence: the mean |matched offset| and the energy both change by less than this
  /// (offsets in units of the search step, energy relatively) over `patience` iterations.
  double tolerance = 0.02;
  int patience = 3;
};

/// The external search the snake calls each iteration: offsets and costs for the current
/// vertices and unit normals.
using ExternalSearch = std::function<SearchResult(const RowMatrixX3d& V, const RowMatrixX3d& N)>;

/// What one level's run did.
struct SnakeLevelReport {
  int iterations = 0;
  bool converged = false;
  double external_energy = 0;     ///< mean matched cost at the end
  double internal_energy = 0;     ///< mean ½·(w_p·(h − ĥℓ)² + α·h² ) / ℓ² at the end (dimensionless)
  double energy = 0;              ///< external + internal
  double mean_abs_offset_mm = 0;  ///< mean |matched offset| at the end
  int rejected_steps = 0;         ///< vertex steps halved or dropped to prevent a fold
  int flipped_faces = 0;          ///< faces whose normal opposes the start's at the end
  /// The figures above at every iteration, in order (the convergence plots of report.html).
  struct Iterate {
    double energy = 0, external_energy = 0, internal_energy = 0, mean_abs_offset_mm = 0;
  };
  std::vector<Iterate> history;
};

/// The prior of one level: ĥ_v = (U_v·n_v)/ℓ_v on the model's own geometry.
/// \pre model_V has rings.num_vertices() rows.
Eigen::VectorXd relative_normal_umbrella(const VertexRings& rings, const RowMatrixX3i& F, const RowMatrixX3d& model_V);

/// The tangential part of the local-frame prior: per vertex, the model's tangential
/// umbrella in its tangent basis (e1 towards the first ring neighbour, e2 = n × e1) over ℓ̂_v,
/// as a complex number, and the unit directions of its ring edges in that basis (CSR like
/// the rings).
struct TangentialPrior {
  std::vector<std::complex<double>> umbrella;
  std::vector<std::complex<double>> ring_directions;
};

/// \pre model_V has rings.num_vertices() rows.
TangentialPrior tangential_prior(const VertexRings& rings, const RowMatrixX3i& F, const RowMatrixX3d& model_V);

/// What undo_self_intersections did.
struct UndoOutcome {
  int moved_vertices = 0;   ///< vertices moved back towards the safe positions
  int remaining_pairs = 0;  ///< crossing face pairs left (mesh/distance.h)
};

/// Undoes self-intersections: the vertices of crossing faces (faces that share no vertex and
/// intersect, mesh/distance.h's crossing_face_pairs; folds of neighbours are the snake's
/// flip test's business), and their rings, move back
/// towards `safe` (their displacement halved per round, then dropped), until no pair of
/// faces intersects or `max_rounds` rounds have run. Faces that intersect in `safe` itself
/// cannot be resolved this way and stay (counted in remaining_pairs).
/// \pre V and safe have the same rows; F references them; rings built from F.
UndoOutcome undo_self_intersections(RowMatrixX3d& V, const RowMatrixX3d& safe, const RowMatrixX3i& F,
                                    const VertexRings& rings, int max_rounds = 8);

/// The snake of one level.
class DeformableSurface {
 public:
  /// \pre F references n = model_V.rows() vertices; model_V is the model's geometry of this
  ///      level (any pose: the prior is similarity invariant).
  DeformableSurface(RowMatrixX3i F, const RowMatrixX3d& model_V, SnakeOptions options = {});

  /// Internal force per vertex (everything but the external term) at V.
  RowMatrixX3d internal_forces(const RowMatrixX3d& V) const;

  /// Deforms V in place. `search_step_mm` is the search grid, used by the convergence test.
  /// No vertex moves farther than `max_displacement_mm` from where it started (a trust
  /// region: each level corrects what its search can see, so a bad start cannot run away).
  SnakeLevelReport run(RowMatrixX3d& V, const ExternalSearch& search, double search_step_mm,
                       double max_displacement_mm = std::numeric_limits<double>::infinity()) const;

  const VertexRings& rings() const { return rings_; }
  const Eigen::VectorXd& prior() const { return prior_; }

 private:
  RowMatrixX3i F_;
  VertexRings rings_;
  Eigen::VectorXd prior_;
  TangentialPrior tangential_;
  SnakeOptions options_;
};

}  // namespace mrsnake
