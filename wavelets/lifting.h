#pragma once
/// \file lifting.h
/// Lifting wavelet analysis and synthesis on a semi-regular hierarchy (Schröder–Sweldens
/// lifting on the 1:4 subdivision connectivity of mesh/subdivision.h).
///
/// One level, from S_{j+1} (n_{j+1} rows) to S_j (its first n_j rows are the "even" vertices,
/// the rest the "odd" ones, each the split of a parent edge of level j):
///   analysis   d = odd − P(even);  c = even + U(d);  frames from c;  D_{j+1} = local(d)
///   synthesis  frames from c;  d = global(D_{j+1});  even = c − U(d);  odd = P(even) + d
/// so synthesis undoes analysis step by step, and both compute the frames from the same c.
///
/// Predict P: `linear` (parent edge midpoint) or `butterfly` (modified butterfly of Zorin,
/// Schröder and Sweldens 1996, with the extraordinary-vertex rules; boundary rules below).
/// Update U: c_i = e_i + (3/4)·mean of the details of the new vertices next to i
/// (weight 3/(4·k_i) each, k_i the valence of i on level j; 1/8 at regular vertices). On a
/// regular closed mesh this keeps the mean of the positions from level to level, so coarse
/// levels are low-pass approximations of the finest rather than subsamples of it.
///
/// Butterfly rules for the parent edge (a, b) of level j, with k the valence:
/// - a and b interior with k = 6: the 10-point stencil (1/2, 1/2, 1/8, 1/8, −1/16 ×4);
/// - an interior endpoint with k ≠ 6 (extraordinary): its k-stencil (3/4 on it; on its ring
///   s_0 = the other endpoint, s_1... in order: k = 3: 5/12, −1/12, −1/12; k = 4: 3/8, 0,
///   −1/8, 0; k ≥ 5: (1/4 + cos(2πi/k) + cos(4πi/k)/2)/k); two extraordinary endpoints: the
///   average of both stencils;
/// - one endpoint on the boundary, the other interior with k = 6: that interior vertex's
///   k-stencil with k = 6;
/// - a boundary edge: the 4-point rule (−1/16, 9/16, 9/16, −1/16) along the boundary loop,
///   or linear on a loop of 3 vertices;
/// - an interior edge between two boundary vertices, or any edge touching a vertex whose
///   ring is not a simple fan (non-manifold): linear.
/// Every stencil's weights sum to 1 (affine invariance), which the similarity invariance needs.
#include <string>
#include <vector>

#include "mesh/subdivision.h"
#include "mesh/trimesh.h"
#include "wavelets/local_frame.h"

namespace mrsnake {

enum class PredictScheme { linear, butterfly };
enum class DetailFrame {
  global,  ///< details are plain vectors in physical coordinates (mm)
  local,   ///< details are in the parent edge's LocalFrame, divided by its length
};

struct WaveletOptions {
  PredictScheme predict = PredictScheme::butterfly;
  bool update = true;  ///< lift the coarse levels (false: plain subsampling)
  DetailFrame frame = DetailFrame::local;
  double degenerate_frame_tolerance = 1e-10;  ///< see parent_edge_frame
};

std::string to_string(PredictScheme scheme);
std::string to_string(DetailFrame frame);
/// \throw InputError for a name other than "linear" or "butterfly".
PredictScheme parse_predict_scheme(const std::string& name);

/// The size of the details of one level, measured on the global (mm) detail vectors.
struct DetailStats {
  int level = 0;              ///< j: the details D_j that rebuild S_j from S_{j-1}
  int count = 0;              ///< new vertices of level j
  double energy = 0;          ///< Σ|d|² (mm²)
  double rms = 0;             ///< sqrt(energy / count) (mm)
  double max = 0;             ///< max |d| (mm)
  int degenerate_frames = 0;  ///< frames that used the fallback of parent_edge_frame
};

/// The full analysis of a hierarchy.
struct WaveletAnalysis {
  RowMatrixX3d base;                  ///< S_0 (n_0 rows)
  std::vector<RowMatrixX3d> details;  ///< details[j-1] = D_j, n_j − n_{j-1} rows, j = 1..L (as stored)
  std::vector<RowMatrixX3d> levels;   ///< S_0..S_L (levels[L] is the input)
  std::vector<DetailStats> stats;     ///< stats[j-1] for D_j
};

/// Prediction stencil of one new vertex: P = Σ weights[i]·even[indices[i]].
struct PredictStencil {
  std::vector<int> indices;
  std::vector<double> weights;
};

/// The lifting transform of one connectivity. Builds every stencil once (construction is
/// O(faces)); each analysis or synthesis is then O(vertices).
class WaveletTransform {
 public:
  /// \pre conn is made by subdivide_connectivity (its child-face numbering is checked).
  /// \throw TopologyError if conn does not follow that numbering or has no level to analyze.
  explicit WaveletTransform(SubdivisionConnectivity conn, WaveletOptions options = {});

  const SubdivisionConnectivity& connectivity() const { return conn_; }
  const WaveletOptions& options() const { return options_; }
  int levels() const { return conn_.levels(); }

  /// Result of one analysis step.
  struct LevelAnalysis {
    RowMatrixX3d coarse;   ///< S_j (n_j rows)
    RowMatrixX3d details;  ///< D_{j+1} (n_{j+1} − n_j rows), as stored
    DetailStats stats;
  };

  /// One analysis step: S_{j+1} → (S_j, D_{j+1}).
  /// \pre 0 <= j < levels(); fine has n_{j+1} rows of finite values.
  LevelAnalysis analyze_level(int j, const RowMatrixX3d& fine) const;

  /// One synthesis step: (S_j, D_{j+1}) → S_{j+1}. The snake calls this after deforming S_j.
  /// \pre 0 <= j < levels(); coarse has n_j rows, details n_{j+1} − n_j rows.
  RowMatrixX3d synthesize_level(int j, const RowMatrixX3d& coarse, const RowMatrixX3d& details) const;

  /// Analysis of the finest level S_L down to S_0.
  /// \pre finest has n_L rows of finite values.
  WaveletAnalysis analyze(const RowMatrixX3d& finest) const;

  /// Synthesis from S_0 up to S_level (level = -1: the finest), one synthesize_level per level.
  /// \pre base has n_0 rows; details has at least `level` entries of the right sizes.
  RowMatrixX3d synthesize(const RowMatrixX3d& base, const std::vector<RowMatrixX3d>& details, int level = -1) const;

  /// The prediction stencil of new vertex v (n_j <= v < n_{j+1}) of level j+1.
  PredictStencil predict_stencil(int j, int v) const;

  /// The frames of the new vertices of level j+1, computed from S_j (n_j rows) only; the
  /// fallback's reference length is the mean edge length of S_j.
  std::vector<LocalFrame> frames(int j, const RowMatrixX3d& coarse) const;

 private:
  struct Level {
    int n_coarse = 0, n_fine = 0;
    std::vector<int> stencil_offsets;  ///< CSR over new vertices
    std::vector<int> stencil_indices;
    std::vector<double> stencil_weights;
    std::vector<double> update_weights;  ///< per coarse vertex: 3/(4·valence)
    std::vector<int> edge_faces;         ///< 2 per new vertex: level-j faces on its parent edge (-1: none)
  };
  void build_level(int j);
  RowMatrixX3d predict(int j, const RowMatrixX3d& even) const;
  void update(int j, RowMatrixX3d& even, const RowMatrixX3d& d, double sign) const;

  SubdivisionConnectivity conn_;
  WaveletOptions options_;
  std::vector<Level> levels_;
};

}  // namespace mrsnake
