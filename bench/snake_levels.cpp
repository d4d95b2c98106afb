// Per-level diagnosis of a segmentation: runs segment() on an image with a model and scores
// the initial surface and every level's deformed surface against a truth (Dice, ASSD) with
// its self-intersection count. Snake options can be overridden to compare settings.
// Usage: bench_snake_levels IMAGE MODEL_DIR TRUTH [--truth-label L] [--init fit] [key=value ...]
//   keys: membrane, thin_plate, prior, tangential, external, time_step, max_step, smoothing,
//         max_iterations, min_iterations, patience, range_fraction, min_range_voxels, max_profile_cost,
//         distance_penalty (profile), edge_distance_penalty, min_gain, reg_schedule (shrink factors as digits: 421, 42,
//         21), reg_iterations, reg_samples, reg_change, reg_window, reg_min_step, reg_step, reg_eval
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "mesh/distance.h"
#include "mesh/image_io.h"
#include "evaluation/evaluate.h"
#include "model/snake_adapter.h"
#include "snake/rasterize.h"
#include "snake/segment.h"
#include "model/model_io.h"

using namespace mrsnake;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr,
                 "usage: bench_snake_levels IMAGE MODEL_DIR TRUTH [--truth-label L] [--init MODE] [--force MODE] "
                 "[key=value ...]\n");
    return 2;
  }
  const Volume image = read_volume(argv[1]);
  const SnakeModel model = snake_model_from(load_model(argv[2]));
  const Volume truth = read_volume(argv[3]);
  int truth_label = 1;
  SegmentOptions o;
  o.init = InitMode::fit;
  for (int i = 4; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--truth-label" && i + 1 < argc) {
      truth_label = std::atoi(argv[++i]);
      continue;
    }
    if (a == "--init" && i + 1 < argc) {
      o.init = parse_init_mode(argv[++i]);
      continue;
    }
    if (a == "--force" && i + 1 < argc) {
      o.force = parse_force_mode(argv[++i]);
      continue;
    }
    const auto eq = a.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
    const std::string key = a.substr(0, eq);
    const double v = std::atof(a.c_str() + eq + 1);
    std::map<std::string, double*> keys{{"membrane", &o.snake.membrane_weight},
                                        {"thin_plate", &o.snake.thin_plate_weight},
                                        {"prior", &o.snake.prior_weight},
                                        {"tangential", &o.snake.tangential_weight},
                                        {"external", &o.snake.external_weight},
                                        {"time_step", &o.snake.time_step},
                                        {"max_step", &o.snake.max_step_fraction},
                                        {"range_fraction", &o.range_edge_fraction},
                                        {"min_range_voxels", &o.min_range_voxels},
                                        {"max_profile_cost", &o.max_profile_cost},
                                        {"profile_step", &o.profile_step_fraction},
                                        {"max_range_voxels", &o.max_range_voxels},
                                        {"min_edge_voxels", &o.min_edge_voxels},
                                        {"fine_smoothing", &o.fine.offset_smoothing_voxels},
                                        {"distance_penalty", &o.profile_distance_penalty},
                                        {"edge_distance_penalty", &o.edge_distance_penalty},
                                        {"min_gain", &o.search_min_gain},
                                        {"ring", &o.cost_ring_weight},
                                        {"ring_cost", &o.cost_ring_full_weight_cost}};
    RegistrationOptions& reg = o.registration.itk;
    if (key == "reg_schedule") {  // shrink factors as digits, e.g. 421 (the default), 42, 21
      reg.shrink_factors.clear();
      reg.smoothing_voxels.clear();
      for (const char c : a.substr(eq + 1)) {
        if (c < '1' || c > '9') {
          std::fprintf(stderr, "reg_schedule takes shrink factors as digits 1-9, e.g. 421; got '%c'\n", c);
          return 2;
        }
        reg.shrink_factors.push_back(c - '0');
        reg.smoothing_voxels.push_back(0.5 * (c - '0') >= 1 ? 0.5 * (c - '0') : 0.0);
      }
    } else if (key == "reg_iterations")
      reg.iterations_per_level = static_cast<int>(v);
    else if (key == "reg_samples")
      reg.samples_per_level = static_cast<int>(v);
    else if (key == "reg_eval")
      reg.evaluation_samples = static_cast<int>(v);
    else if (key == "reg_change")
      reg.min_relative_change = v;
    else if (key == "reg_window")
      reg.convergence_window = static_cast<int>(v);
    else if (key == "reg_min_step")
      reg.min_step_voxels = v;
    else if (key == "reg_step")
      reg.initial_step_voxels = v;
    else if (key == "smoothing")
      o.snake.offset_smoothing = static_cast<int>(v);
    else if (key == "fine_deform")
      o.fine.deform_edge_centred = v != 0;
    else if (key == "fine_min_iterations")
      o.fine.min_iterations = static_cast<int>(v);
    else if (key == "fine_patience")
      o.fine.patience = static_cast<int>(v);
    else if (key == "fine_step")
      o.fine.profile_step_fraction = v;
    else if (key == "median")
      o.snake.offset_median = static_cast<int>(v);
    else if (key == "undo")
      o.undo_self_intersections = v != 0;
    else if (key == "max_iterations")
      o.snake.max_iterations = static_cast<int>(v);
    else if (key == "min_iterations")
      o.snake.min_iterations = static_cast<int>(v);
    else if (key == "patience")
      o.snake.patience = static_cast<int>(v);
    else if (keys.count(key))
      *keys[key] = v;
    else {
      std::fprintf(stderr, "unknown key %s\n", key.c_str());
      return 2;
    }
  }
  const auto score = [&](const TriMesh& m) {
    return evaluate_segmentation(rasterize_mesh(m, truth), truth, 1, truth_label);
  };
  SegmentOptions o0 = o;
  o0.snake.max_iterations = 0;
  const SegmentResult r0 = segment(image, model, o0);
  timespec c0{}, c1{};  // thread CPU time: steadier than wall time on a shared machine
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
  const SegmentResult r = segment(image, model, o);
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
  const double sec = (c1.tv_sec - c0.tv_sec) + 1e-9 * (c1.tv_nsec - c0.tv_nsec);
  std::printf(
      "| level | vertices | pyramid | voxel mm | range mm | iterations | |offset| mm | rejected | start Dice | Dice | "
      "ASSD mm | self-int |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (std::size_t j = 0; j < r.levels.size(); ++j) {
    const LevelOutcome& l = r.levels[j];
    const SegmentationScores s0 = score(r0.levels[j].surface);
    const SegmentationScores s = score(l.surface);
    std::printf("| %d | %d | %d | %.2f | %.2f | %d | %.3f | %d | %.4f | %.4f | %.3f | %d |\n", l.level, l.vertices,
                l.pyramid_level, l.voxel_mm, l.range_mm, l.snake.iterations, l.snake.mean_abs_offset_mm,
                l.snake.rejected_steps, s0.dice, s.dice, s.assd_mm, count_self_intersections(l.surface));
  }
  std::printf("| stage | seconds |\n|---|---|\n");
  for (const auto& [name, sec] : r.stage_seconds) std::printf("| %s | %.3f |\n", name.c_str(), sec);
  for (const LevelOutcome& l : r.levels)
    std::printf("| level %d%s | %.3f |\n", l.level, l.deformed ? "" : " (synthesized)", l.seconds);
  if (r.registration && r.registration->ran) {
    const RegistrationResult& g = r.registration->result;
    std::printf("registration %s: %.3f s (setup %.3f, evaluation %.3f, optimization %.3f), iterations",
                r.registration->accepted ? "accepted" : "rejected", r.registration->seconds, g.setup_seconds,
                g.evaluation_seconds, g.optimization_seconds);
    for (const int it : g.iterations) std::printf(" %d", it);
    std::printf(", metric %.4f -> %.4f, scale %.4f, rotation %.2f deg, stop: %s\n", g.initial_metric, g.final_metric,
                g.transform.scale, g.transform.angle_deg, g.stop_condition.c_str());
  }
  std::printf("init %s, compute %.3f s\n", to_string(r.init).c_str(), r.compute_seconds);
  const SegmentationScores s0 = score(r0.surface), s = score(r.surface);
  std::printf(
      "start Dice %.4f ASSD %.3f | final Dice %.4f ASSD %.3f | self-intersections %d | %.3f s CPU (segment() with the "
      "final count)\n",
      s0.dice, s0.assd_mm, s.dice, s.assd_mm, r.self_intersections, sec);
  return 0;
}
