#pragma once
/// \file model.h
/// The multiresolution shape model: the coarse mesh S_0 plus the wavelet details that
/// rebuild every finer level, as the segmentation loads it. On disk: model/model_io.h.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/subdivision.h"
#include "mesh/trimesh.h"
#include "wavelets/lifting.h"

namespace mrsnake {

/// The image grid the model was built in (a copy of the label image's geometry).
struct PhysicalFrame {
  std::array<std::size_t, 3> size{0, 0, 0};
  std::array<double, 3> spacing{1, 1, 1};
  std::array<double, 3> origin{0, 0, 0};
  std::array<double, 9> direction{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major, as in Volume
};

/// A shape model. The base faces and the number of levels fix the whole connectivity
/// (subdivide_connectivity), so only S_0 and the details carry geometry.
struct ShapeModel {
  WaveletOptions wavelet;
  RowMatrixX3i base_faces;                    ///< faces of S_0
  RowMatrixX3d base;                          ///< S_0 (n_0 rows)
  std::vector<RowMatrixX3d> details;          ///< D_1..D_L as stored (see lifting.h)
  std::vector<RowMatrixX3d> level_positions;  ///< S_0..S_L from the analysis (empty when not loaded)
  std::vector<DetailStats> detail_stats;      ///< per level 1..L

  // Provenance, written to the manifest.
  std::string source_image;  ///< the label image (empty if unknown)
  std::optional<int> source_label;
  std::optional<int> source_component;  ///< the label's k-th largest part only (build-model --component)
  std::optional<PhysicalFrame> physical_frame;
  nlohmann::json remesh_quality;  ///< mesh/quality.h keys; null if none
  /// The structure's size and every default derived from it, with the finest level's fit to
  /// its label (build-model); null if none.
  nlohmann::json scale;
  std::vector<std::pair<std::string, double>> timings;  ///< seconds per stage, in order
  /// The options it was built with, as `build-model --config` reads them; null if unknown.
  nlohmann::json build_options;
  /// Optional named binary sections (e.g. "appearance"), stored as <name>.bin and listed,
  /// with their size and checksum, in the manifest. Names: [a-z0-9_]+, not "details".
  std::map<std::string, std::vector<std::uint8_t>> sections;

  int levels() const { return static_cast<int>(details.size()); }
  /// The connectivity of levels 0..L.
  SubdivisionConnectivity connectivity() const;
};

/// Analyzes the finest level of a hierarchy into a model (base, details, every level and
/// the detail statistics). Provenance fields are left empty for the caller.
/// \pre finest has conn.vertex_counts.back() rows of finite values.
/// \throw TopologyError if conn is not the 1:4 split of its own base faces by
///        subdivide_connectivity (the model stores only the base faces and L).
ShapeModel make_model(const SubdivisionConnectivity& conn, const RowMatrixX3d& finest,
                      const WaveletOptions& options = {});

/// Synthesizes S_level (level = -1: S_L) from the model's base and details.
RowMatrixX3d synthesize(const ShapeModel& model, int level = -1);

}  // namespace mrsnake
