// Stage timings of the segmentation on a synthetic volume (one thread, compute after the
// volume and the model are in memory). Usage: bench_snake_stages [size=256] [levels=5] [shape=blob]
// Prints one table: stage, seconds; then the per-level table and the scores.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "evaluation/evaluate.h"
#include "model/snake_adapter.h"
#include "snake/rasterize.h"
#include "snake/segment.h"
#include "tests/support/shrink_wrap.h"
#include "phantoms/synth.h"
#include "model/shape_model.h"

using namespace mrsnake;

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 256;
  const int levels = argc > 2 ? std::atoi(argv[2]) : 5;
  const int repeats = argc > 4 ? std::max(1, std::atoi(argv[4])) : 1;  // for profiling segment() alone
  const SynthShape shape = parse_synth_shape(argc > 3 ? argv[3] : "blob");
  const auto make = [&](std::uint64_t seed) {
    SynthOptions o;
    o.shape = shape;
    o.size = {size, size, size};
    o.snr = 4;
    o.random_pose = true;
    o.deform_mm = 2.0 * size / 64.0;
    o.seed = seed;
    o.supersampling = 2;
    return render_synth(draw_synth_params(o));
  };
  std::printf("preparing %d^3 %s (target seed 101, model seed 102, %d levels)...\n", size, to_string(shape).c_str(),
              levels);
  const SynthResult target = make(101), ref = make(102);
  ShrinkWrapOptions so;
  so.levels = levels;
  const ShrinkWrapResult wrap = shrink_wrap(ref.truth_mesh, so);
  ShapeModel shape_model = make_model(wrap.connectivity, wrap.finest);
  add_appearance(shape_model, ref.image);
  const SnakeModel model = snake_model_from(shape_model);

  SegmentOptions options;
  options.count_self_intersections = true;
  for (int k = 1; k < repeats; ++k) segment(target.image, model, options);
  timespec c0{}, c1{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
  const auto t0 = std::chrono::steady_clock::now();
  const SegmentResult r = segment(target.image, model, options);
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
  const double cpu = (c1.tv_sec - c0.tv_sec) + 1e-9 * (c1.tv_nsec - c0.tv_nsec);
  const auto t1 = std::chrono::steady_clock::now();
  const Volume labels = rasterize_mesh(r.surface, target.image);
  const double raster = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  const SegmentationScores s = evaluate_segmentation(labels, target.truth);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);

  std::printf("\n| stage | seconds |\n|---|---|\n");
  for (const auto& [name, sec] : r.stage_seconds) std::printf("| %s | %.3f |\n", name.c_str(), sec);
  std::printf("| rasterize labels | %.3f |\n", raster);
  std::printf("| **compute (normalize..levels)** | **%.3f** |\n| segment() incl. self-intersection count | %.3f |\n",
              r.compute_seconds, total);
  std::printf("| segment() thread CPU time (machine load does not count) | %.3f |\n", cpu);
  std::printf(
      "\n| level | vertices | pyramid | iterations | converged | synthesis s | total s "
      "|\n|---|---|---|---|---|---|---|\n");
  for (const auto& l : r.levels)
    std::printf("| %d | %d | %d | %d | %s | %.3f | %.3f |\n", l.level, l.vertices, l.pyramid_level, l.snake.iterations,
                l.snake.converged ? "yes" : "no", l.synthesis_seconds, l.seconds);
  std::printf("\nDice %.4f  ASSD %.3f mm  HD95 %.3f mm  self-intersections %d  peak RSS %.0f MB\n", s.dice, s.assd_mm,
              s.hd95_mm, r.self_intersections, ru.ru_maxrss / 1024.0);
  return 0;
}
