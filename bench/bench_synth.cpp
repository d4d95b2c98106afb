// Time and peak memory of `synth` rendering (shape, partial volume, blur, noise, mesh) per
// size and shape. Usage: bench_synth [max_size]   (default 128; 256 is the benchmark size)
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "phantoms/synth.h"

int main(int argc, char** argv) {
  using namespace mrsnake;
  const int max_size = argc > 1 ? std::atoi(argv[1]) : 128;
  std::printf("%-10s %6s %10s %10s %12s %14s\n", "shape", "size", "time_s", "faces", "voxels_obj", "peak_rss_mb");
  for (int size = 64; size <= max_size; size *= 2)
    for (SynthShape shape : {SynthShape::sphere, SynthShape::blob, SynthShape::aneurysm, SynthShape::heart}) {
      SynthOptions o;
      o.shape = shape;
      o.size = {size, size, size};
      o.noise = SynthNoise::rician;
      o.random_pose = true;
      o.deform_mm = 3.0 * size / 64;
      o.bias = 0.2;
      const auto start = std::chrono::steady_clock::now();
      const SynthResult r = render_synth(draw_synth_params(o));
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::size_t object = 0;
      for (float v : r.truth.data) object += v == kTruthLabel;
      rusage usage{};
      getrusage(RUSAGE_SELF, &usage);
      std::printf("%-10s %6d %10.2f %10d %12zu %14.1f\n", to_string(shape).c_str(), size, seconds,
                  r.truth_mesh.num_faces(), object, usage.ru_maxrss / 1024.0);
    }
  return 0;
}
