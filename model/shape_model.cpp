#include "model/shape_model.h"

#include "mesh/errors.h"

namespace mrsnake {

SubdivisionConnectivity ShapeModel::connectivity() const {
  return subdivide_connectivity(base_faces, static_cast<int>(base.rows()), levels());
}

ShapeModel make_model(const SubdivisionConnectivity& conn, const RowMatrixX3d& finest, const WaveletOptions& options) {
  if (conn.faces.empty()) throw TopologyError("the mesh hierarchy has no levels");
  const SubdivisionConnectivity rebuilt = subdivide_connectivity(conn.faces[0], conn.vertex_counts[0], conn.levels());
  bool same = rebuilt.vertex_counts == conn.vertex_counts && rebuilt.parent_edges.rows() == conn.parent_edges.rows() &&
              rebuilt.parent_edges == conn.parent_edges;
  for (int j = 0; same && j <= conn.levels(); ++j) same = rebuilt.faces[j] == conn.faces[j];
  if (!same)
    throw TopologyError(
        "the mesh hierarchy's numbering differs from subdivide_connectivity's; a model can only store "
        "hierarchies built by it");
  if (finest.rows() != conn.vertex_counts.back())
    throw std::invalid_argument("make_model: the finest level needs " + std::to_string(conn.vertex_counts.back()) +
                                " positions, got " + std::to_string(finest.rows()));
  const WaveletTransform wt(conn, options);
  WaveletAnalysis a = wt.analyze(finest);
  ShapeModel model;
  model.wavelet = options;
  model.base_faces = conn.faces[0];
  model.base = std::move(a.base);
  model.details = std::move(a.details);
  model.level_positions = std::move(a.levels);
  model.detail_stats = std::move(a.stats);
  return model;
}

RowMatrixX3d synthesize(const ShapeModel& model, int level) {
  const WaveletTransform wt(model.connectivity(), model.wavelet);
  return wt.synthesize(model.base, model.details, level);
}

}  // namespace mrsnake
