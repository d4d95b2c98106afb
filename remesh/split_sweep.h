#pragma once
/// \file split_sweep.h
/// A Gauss-Seidel sweep over a level's vertices on two cores, with a result that does not
/// depend on the threads' timing.
///
/// The shape smoothing and the repair move one vertex at a time, each move reading its 1-ring
/// as the moves before left it. The vertices are split in two halves across the longest side
/// of their bounding box. A vertex whose 1-ring lies in its own half is inner: the inner
/// vertices of one half share no vertex and no face with those of the other, so the two halves
/// can be swept side by side and each sees only its own moves. The vertices along the cut (the
/// band) are swept afterwards, on one thread. Each half keeps its order, so the result is the
/// same with one core as with two.
#include <vector>

#include "mesh/parallel.h"
#include "mesh/trimesh.h"
#include "mesh/vertex_stars.h"

namespace mrsnake {

class SplitSweep {
 public:
  /// The parts: the inner vertices of each half, and the band along the cut.
  static constexpr int kParts = 3;
  static constexpr int kBand = 2;

  /// Splits the vertices of (X, F) at the median of their coordinate along the longest side of
  /// their bounding box. Below `min_parallel` vertices the parts run one after the other (the
  /// same result: a thread costs more than it saves on a coarse level).
  /// \pre `stars` are F's vertex stars over X.rows() vertices.
  /// \throw nothing beyond std::bad_alloc.
  SplitSweep(const RowMatrixX3d& X, const RowMatrixX3i& F, const VertexStars& stars, int min_parallel = 2000);

  /// 0 or 1 for an inner vertex of that half, kBand for a vertex along the cut.
  int part(int v) const { return part_[v]; }

  /// Runs visit(0) and visit(1) side by side, then visit(kBand).
  /// \pre visit(p) moves only the vertices v with part(v) == p and reads only their 1-rings and
  ///      their stars: the two halves then share only band vertices, which they only read.
  /// \throw what visit throws, after both halves ended.
  template <class Visit>
  void run(Visit&& visit) const {
    if (parallel_)
      run_both_in_parallel([&] { visit(0); }, [&] { visit(1); });
    else {
      visit(0);
      visit(1);
    }
    visit(kBand);
  }

 private:
  std::vector<int> part_;
  bool parallel_ = false;
};

}  // namespace mrsnake
