// The wavelet invariants on hierarchies made by the remesher from the shared data meshes
// (a disk and closed genus-0 surfaces).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "mesh/mesh_io.h"
#include "remesh/remesh.h"
#include "tests/test_support.h"
#include "tests/wavelets/hierarchies.h"
#include "wavelets/lifting.h"

using namespace mrsnake;
using namespace mrsnake::test;

namespace {

void check_invariants(const std::string& path) {
  RemeshOptions ro;
  ro.target_faces = 2048;
  ro.compute_stats = false;
  const RemeshResult r = remesh(read_mesh(path), ro);
  const RowMatrixX3d& fine = r.levels.back().positions;
  const double diag = bounding_box_diagonal(fine);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-1.1, Eigen::Vector3d(0.3, 1, -0.4).normalized()).toRotationMatrix();
  const auto move = [&](const RowMatrixX3d& V) {
    RowMatrixX3d W = (0.6 * V * R.transpose()).rowwise() + Eigen::RowVector3d(-40, 5, 17);
    return W;
  };
  for (PredictScheme p : {PredictScheme::linear, PredictScheme::butterfly}) {
    WaveletOptions o;
    o.predict = p;
    const WaveletTransform wt(r.connectivity, o);
    const WaveletAnalysis a = wt.analyze(fine);
    EXPECT_LE(max_row_distance(wt.synthesize(a.base, a.details), fine), 1e-9 * diag) << path << " " << to_string(p);
    const RowMatrixX3d moved = move(fine);
    EXPECT_LE(max_row_distance(wt.synthesize(move(a.base), a.details), moved), 1e-9 * bounding_box_diagonal(moved))
        << path << " " << to_string(p);
    for (std::size_t j = 1; j < a.stats.size(); ++j)
      EXPECT_LT(a.stats[j].rms, a.stats[j - 1].rms) << path << " " << to_string(p) << " level " << j + 1;
  }
}

}  // namespace

TEST(WaveletsOnRemeshedData, MushroomDisk) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/mushroom.off");
  check_invariants(path);
}

TEST(WaveletsOnRemeshedData, Blobby) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/blobby.off");
  check_invariants(path);
}

TEST(WaveletsOnRemeshedData, Heart) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/heart.off");
  check_invariants(path);
}
