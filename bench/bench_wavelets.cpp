// Benchmark of the wavelet transform and the model files on semi-regular hierarchies of
// about 32k and 131k faces (an octahedron split 6 and 7 times, on a smooth bumpy surface).
// Prints a table of times (best of several runs) and the peak memory, then the detail
// statistics per level and the reconstruction error.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "mesh/subdivision.h"
#include "wavelets/lifting.h"
#include "model/model_io.h"

using namespace mrsnake;
namespace fs = std::filesystem;

namespace {

double best_of(int runs, const std::function<void()>& f) {
  double best = 1e300;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

struct Case {
  SubdivisionConnectivity conn;
  RowMatrixX3d finest;
};

Case octahedron_case(int levels) {
  RowMatrixX3d V0(6, 3);
  V0 << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  RowMatrixX3i F0(8, 3);
  F0 << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  Case c{subdivide_connectivity(F0, 6, levels), {}};
  RowMatrixX3d V = V0;
  for (int j = 0; j < levels; ++j) {
    V = midpoint_refine(c.conn, j, V);
    V.rowwise().normalize();
  }
  c.finest.resize(V.rows(), 3);
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::RowVector3d u = V.row(v);
    const double r = 60.0 * (1.0 + 0.15 * u.x() * u.y() + 0.1 * std::sin(3.0 * u.z()) + 0.08 * u.x() * u.x());
    c.finest.row(v) = r * u.cwiseProduct(Eigen::RowVector3d(1.2, 1.0, 0.7));
  }
  return c;
}

}  // namespace

int main() {
  const fs::path dir = fs::temp_directory_path() / ("mrsnake-bench-wavelets-" + std::to_string(getpid()));
  std::printf("%-10s %-10s %8s %8s | %9s %9s %9s %11s %9s %9s %9s | %8s %8s\n", "faces", "predict", "levels",
              "vertices", "plan_ms", "anal_ms", "synth_ms", "lastlvl_ms", "save_ms", "load_ms", "model_MB", "err/diag",
              "peak_MB");
  for (int levels : {6, 7}) {
    const Case c = octahedron_case(levels);
    for (PredictScheme p : {PredictScheme::linear, PredictScheme::butterfly}) {
      WaveletOptions o;
      o.predict = p;
      const int runs = levels == 6 ? 5 : 3;
      const double t_plan = best_of(runs, [&] { WaveletTransform wt(c.conn, o); });
      const WaveletTransform wt(c.conn, o);
      WaveletAnalysis a;
      const double t_anal = best_of(runs, [&] { a = wt.analyze(c.finest); });
      RowMatrixX3d S;
      const double t_synth = best_of(runs, [&] { S = wt.synthesize(a.base, a.details); });
      RowMatrixX3d last;
      const double t_last =
          best_of(runs, [&] { last = wt.synthesize_level(levels - 1, a.levels[levels - 1], a.details[levels - 1]); });
      const double err = (S - c.finest).rowwise().norm().maxCoeff() / bounding_box_diagonal(c.finest);
      const ShapeModel model = make_model(c.conn, c.finest, o);
      const double t_save = best_of(runs, [&] { save_model(dir.string(), model); });
      double bytes = 0;
      for (const auto& e : fs::directory_iterator(dir)) bytes += static_cast<double>(fs::file_size(e.path()));
      const double t_load = best_of(runs, [&] { ShapeModel m = load_model(dir.string()); });
      std::printf("%-10ld %-10s %8d %8ld | %9.2f %9.2f %9.2f %11.2f %9.1f %9.1f %9.2f | %8.1e %8.0f\n",
                  static_cast<long>(c.conn.faces.back().rows()), to_string(p).c_str(), levels,
                  static_cast<long>(c.finest.rows()), t_plan * 1e3, t_anal * 1e3, t_synth * 1e3, t_last * 1e3,
                  t_save * 1e3, t_load * 1e3, bytes / 1e6, err, peak_mb());
      if (levels == 7) {
        std::printf("    detail rms per level (mm):");
        for (const DetailStats& s : a.stats) std::printf(" %.2e", s.rms);
        std::printf("\n    detail energy per level (mm^2):");
        for (const DetailStats& s : a.stats) std::printf(" %.2e", s.energy);
        std::printf("\n    normal part of the local details, rms (fraction of the parent edge):");
        for (const RowMatrixX3d& D : a.details) std::printf(" %.2e", std::sqrt(D.col(2).squaredNorm() / D.rows()));
        std::printf("\n    tangential part of the local details, rms (fraction of the parent edge):");
        for (const RowMatrixX3d& D : a.details) std::printf(" %.2e", std::sqrt(D.leftCols(2).squaredNorm() / D.rows()));
        std::printf("\n");
      }
    }
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
  std::printf(
      "plan = stencils and checks (WaveletTransform), anal = full analysis S_L -> S_0 + details,\n"
      "synth = full synthesis, lastlvl = one synthesis step to the finest level, save/load = the model folder\n"
      "(load validates every checksum, without reading the .vtp meshes); best of 3-5 runs.\n");
  return 0;
}
