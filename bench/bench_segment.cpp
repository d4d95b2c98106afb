// Segmentation benchmark: mrsnake segment against ITK's geodesic active contour
// and threshold level sets, each started from the snake's own initial surface, on
// synthetic cases (mrsnake synth) or on real images warped by a known deformation
// (synth --from-image). One table: Dice, ASSD, HD95, seconds of compute after loading,
// load seconds, peak memory and the speed-up of the snake over the best ITK level set.
// On real data a second table sets the snake beside single-atlas elastix (bench/elastix_atlas):
// the reference image registered to the case, its truth warped onto the case's grid.
//
// Usage: bench_segment [--quick] [--real DATA_DIR] [--mrsnake BIN] [--work DIR] [--json OUT] [--keep]
//                      [--only CASE_SUBSTRING] [--gac
//                      PROPAGATION,CURVATURE,ADVECTION[,SIGMA_MM,BETA_FRACTION,ALPHA_DIVISOR]]
//                      [--elastix-atlas SCRIPT]
//   --keep also writes each level set's labels into the work folder.
//   default: synthetic cases at 128³ and 256³; --quick: 128³ only;
//   --real DATA_DIR: the liver of abdomen-ct-small and the genus-0 brain structures of MRIcrop.
//   --elastix-atlas: the bench/elastix_atlas script (default: the one beside this source file);
//     the elastix columns are skipped when elastix or transformix is not on PATH.
//
// Every mrsnake command runs as a child process (wall time and peak RSS from wait4); each
// ITK level set runs in a forked child of this driver with one thread, so its peak RSS is
// its own: load + compute, measured before scoring.
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/itk_level_sets.h"
#include "mesh/atomic_file.h"
#include "mesh/image_io.h"
#include "mesh/label_repair.h"
#include "evaluation/evaluate.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace mrsnake;

namespace {

// A segment output's labels.nii.gz as 1 inside: it holds the structure's reference value.
Volume read_structure_labels(const fs::path& path) {
  Volume labels = read_volume(path.string());
  for (float& v : labels.data) v = v != 0.0f ? 1.0f : 0.0f;
  return labels;
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct ChildResult {
  int exit_code = -1;
  double wall_seconds = 0;
  double peak_mib = 0;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string tail(const std::string& s, std::size_t n = 1500) {
  return s.size() <= n ? s : "..." + s.substr(s.size() - n);
}

/// Runs f in a forked child (its exit code is the child's); wall time and peak RSS via wait4.
ChildResult run_forked(const std::function<int()>& f) {
  std::cout.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  const auto t0 = Clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    int code = 1;
    try {
      code = f();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
    }
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(code);
  }
  int status = 0;
  rusage ru{};
  if (wait4(pid, &status, 0, &ru) < 0) throw std::runtime_error("wait4 failed");
  ChildResult r;
  r.wall_seconds = seconds_since(t0);
  r.peak_mib = ru.ru_maxrss / 1024.0;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return r;
}

/// Runs a program with stdout and stderr sent to files; throws with the stderr tail on failure.
ChildResult run_program(const std::vector<std::string>& args, const fs::path& out_file, const fs::path& err_file,
                        bool must_succeed = true) {
  const ChildResult r = run_forked([&] {
    const int out = open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0) return 127;
    dup2(out, 1);
    dup2(err, 2);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    return 127;
  });
  if (must_succeed && r.exit_code != 0) {
    std::string cmd;
    for (const std::string& a : args) cmd += a + " ";
    throw std::runtime_error("command failed (exit " + std::to_string(r.exit_code) + "): " + cmd + "\n" +
                             tail(read_text(err_file)));
  }
  return r;
}

/// One row of the table.
struct Row {
  std::string case_name, method;
  SegmentationScores scores;
  double seconds = std::numeric_limits<double>::quiet_NaN();  ///< compute after loading
  double load_seconds = std::numeric_limits<double>::quiet_NaN();
  double peak_mib = std::numeric_limits<double>::quiet_NaN();
  double wall_seconds = std::numeric_limits<double>::quiet_NaN();
  double speedup = std::numeric_limits<double>::quiet_NaN();
  json extra = json::object();
};

Row make_row(const std::string& case_name, const std::string& method) {
  Row r;
  r.case_name = case_name;
  r.method = method;
  return r;
}

/// A case to segment: the image, its truth (label 1), and the model to use.
struct Case {
  std::string name;
  fs::path image, truth, model, dir;
  int model_levels = 0;
};

/// One initialization route on one case: the Dice of its initial surface and of the result.
struct InitRow {
  std::string case_name, init, init_used;
  double initial_dice = std::numeric_limits<double>::quiet_NaN();
  double final_dice = std::numeric_limits<double>::quiet_NaN();
  double init_seconds = std::numeric_limits<double>::quiet_NaN();      ///< register + initialize stages
  double register_seconds = std::numeric_limits<double>::quiet_NaN();  ///< the registration alone
  std::string registration;  ///< "accepted", "rejected: why", or "" when not asked for
};

/// Single-atlas elastix on one real case (bench/elastix_atlas), scored against the case's truth.
struct ElastixRow {
  std::string case_name, dataset;
  SegmentationScores scores;  ///< Dice 0 and infinite distances when it failed
  double registration_seconds = std::numeric_limits<double>::quiet_NaN();  ///< elastix's wall seconds
  double transformix_seconds = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> fixed_spacing_mm, grid_spacing_mm;  ///< the case's voxels; the final B-spline grid elastix laid
  std::string error;
  json record;  ///< elastix_atlas's output
};

/// FinalGridSpacingInVoxels of elastix's B-spline stage: in voxels, so the grid follows each
/// dataset's scale (as bench/cross_subject).
constexpr int kElastixGridVoxels = 8;

/// Whether an executable of this name is on PATH.
bool on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && access((fs::path(dir) / name).c_str(), X_OK) == 0) return true;
  return false;
}

double number_or_nan(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<double>()
                                                                : std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> numbers(const json& j, const char* key) {
  std::vector<double> out;
  if (j.is_object() && j.contains(key) && j[key].is_array())
    for (const json& v : j[key]) out.push_back(v.get<double>());
  return out;
}

/// A table cell: "–" for NaN, "inf", or the number in printf format f.
std::string cell(double v, const char* f) {
  if (std::isnan(v)) return "–";
  if (std::isinf(v)) return "inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// A mean over the cases of a table column: its finite values, and how many were not.
struct ColumnMean {
  double sum = 0;
  int finite = 0, left_out = 0;
  void add(double v) {
    if (std::isfinite(v)) {
      sum += v;
      ++finite;
    } else if (!std::isnan(v)) {
      ++left_out;
    }
  }
  std::string text(const char* f) const {
    std::string t = cell(finite > 0 ? sum / finite : std::numeric_limits<double>::quiet_NaN(), f);
    return left_out > 0 ? t + " (" + std::to_string(left_out) + " inf)" : t;
  }
};

/// "3 mm" for isotropic spacings, else "0.6×0.6×1.3 mm".
std::string spacing_text(const std::vector<double>& mm) {
  if (mm.size() != 3) return "? mm";
  if (std::abs(mm[0] - mm[1]) < 1e-6 && std::abs(mm[0] - mm[2]) < 1e-6) return cell(mm[0], "%g") + " mm";
  return cell(mm[0], "%.3g") + "×" + cell(mm[1], "%.3g") + "×" + cell(mm[2], "%.3g") + " mm";
}

/// The initialization columns of a segment report.
void fill_init_row(InitRow& row, const json& rep) {
  row.init_used = rep.value("init_used", std::string());
  const json& st = rep["stage_seconds"];
  row.init_seconds = st.value("initialize", 0.0) + st.value("register", 0.0);
  if (st.contains("register")) row.register_seconds = st["register"].get<double>();
  if (rep.contains("registration")) {
    const json& g = rep["registration"];
    row.registration = g["accepted"].get<bool>() ? "accepted" : "rejected: " + g.value("rejection", std::string());
  }
}

struct Bench {
  std::string mrsnake;
  fs::path work;
  bool model_takes_image = false;
  bool keep_labels = false;
  std::string primary_init;              ///< --init of the snake whose start the level sets share (empty: default)
  std::vector<std::string> extra_inits;  ///< also run the snake with these --init modes
  std::string only;                      ///< run only the cases whose name contains this
  std::string elastix_atlas;             ///< the bench/elastix_atlas script; empty: no elastix column
  std::string elastix_skipped;           ///< why there is no elastix column (empty: it runs, or no real data)
  bench::LevelSetOptions itk_options;
  std::vector<Row> rows;
  std::vector<InitRow> init_rows;
  std::vector<ElastixRow> elastix_rows;
  json cases = json::array();

  ChildResult mrsnake_cmd(const std::vector<std::string>& args, const fs::path& dir, const std::string& tag,
                          bool must_succeed = true) {
    std::vector<std::string> full{mrsnake, "-q"};
    full.insert(full.end(), args.begin(), args.end());
    return run_program(full, dir / (tag + ".out"), dir / (tag + ".err"), must_succeed);
  }

  /// Builds a model from labels (and the image, for the appearance, if build-model takes it).
  int build_model(const fs::path& labels, int label, const fs::path& image, const fs::path& model,
                  const std::vector<std::string>& extra) {
    std::vector<std::string> args{"build-model",         "--labels", labels.string(), "--label",
                                  std::to_string(label), "-o",       model.string(),  "--json"};
    if (model_takes_image) {
      args.push_back("--image");
      args.push_back(image.string());
    }
    args.insert(args.end(), extra.begin(), extra.end());
    const fs::path dir = model.parent_path();
    const ChildResult r = mrsnake_cmd(args, dir, model.filename().string() + "-build");
    const json summary = json::parse(read_text(dir / (model.filename().string() + "-build.out")));
    std::printf("  model %s: %d levels, %d faces, built in %.1f s (peak %.0f MiB)\n",
                (model.parent_path().filename() / model.filename()).c_str(), summary["levels"].get<int>(),
                summary["faces"].get<int>(), r.wall_seconds, r.peak_mib);
    return summary["levels"].get<int>();
  }

  SegmentationScores score_in_child(const fs::path& labels, const fs::path& truth, const fs::path& out) {
    const ChildResult r = run_forked([&] {
      json j;
      to_json(j, evaluate_segmentation(read_structure_labels(labels), read_volume(truth.string())));
      std::ofstream(out) << j.dump();
      return 0;
    });
    if (r.exit_code != 0) throw std::runtime_error("scoring " + labels.string() + " failed");
    return scores_from(json::parse(read_text(out)));
  }

  static SegmentationScores scores_from(const json& j) {
    SegmentationScores s;
    const auto num = [&](const char* k) { return j[k].is_null() ? INFINITY : j[k].get<double>(); };
    s.dice = num("dice");
    s.jaccard = num("jaccard");
    s.assd_mm = num("assd_mm");
    s.hd95_mm = num("hd95_mm");
    s.hausdorff_mm = num("hausdorff_mm");
    s.volume_difference_pct = num("volume_difference_pct");
    return s;
  }

  std::string primary_method() const { return primary_init.empty() ? "mrsnake" : "mrsnake --init " + primary_init; }
  /// The run set against elastix: segment's default route for a model with a reference image.
  std::string elastix_rival = "mrsnake --init register+fit";

  /// The reference side of a real case's truth: 1 where `labels` hold `label` (on its
  /// `component`-th largest part only when component > 0), the mask synth --from-image warps
  /// into the case's truth. In a forked child, so that no ITK threads start in this driver.
  static void write_reference_truth(const fs::path& labels, int label, int component, const fs::path& out) {
    const ChildResult r = run_forked([&] {
      Volume v = read_volume(labels.string());
      if (component > 0) v = keep_label_part(v, label, component);
      for (float& x : v.data) x = std::lround(x) == label ? 1.0f : 0.0f;
      write_volume(out.string(), v, VoxelType::uint8);
      return 0;
    });
    if (r.exit_code != 0) throw std::runtime_error("writing the reference truth " + out.string() + " failed");
  }

  /// Single-atlas elastix: bench/elastix_atlas registers the reference image (moving) to the
  /// case's image (fixed) and warps the reference truth onto the case's grid (nearest
  /// neighbour); `mrsnake evaluate` scores it against the case's truth.
  void run_elastix(const Case& c, const std::string& dataset, const fs::path& reference_image,
                   const fs::path& reference_truth) {
    if (elastix_atlas.empty() || (!only.empty() && c.name.find(only) == std::string::npos)) return;
    std::printf("  %s: elastix", c.name.c_str());
    std::fflush(stdout);
    ElastixRow row;
    row.case_name = c.name;
    row.dataset = dataset;
    row.scores.dice = 0;
    row.scores.assd_mm = row.scores.hd95_mm = INFINITY;
    const ChildResult r = run_program({elastix_atlas, "--fixed", c.image.string(), "--moving", reference_image.string(),
                                       "--labels", reference_truth.string(), "--out", (c.dir / "elastix").string(),
                                       "--grid-voxels", std::to_string(kElastixGridVoxels)},
                                      c.dir / "elastix_atlas.out", c.dir / "elastix_atlas.err", false);
    try {
      row.record = json::parse(read_text(c.dir / "elastix_atlas.out"));
    } catch (const json::exception&) {
      row.record = json::object();
    }
    row.registration_seconds = number_or_nan(row.record, "registration_seconds");
    row.transformix_seconds = number_or_nan(row.record, "transformix_seconds");
    row.fixed_spacing_mm = numbers(row.record, "fixed_spacing_mm");
    row.grid_spacing_mm = numbers(row.record, "bspline_grid_spacing_mm");
    if (r.exit_code != 0) {
      row.error = row.record.value("error", tail(read_text(c.dir / "elastix_atlas.err"), 300));
    } else {
      // The synth truth holds the structure (or its modelled part) as label 1.
      const std::string warped = row.record.value("warped_labels", std::string());
      const ChildResult e =
          mrsnake_cmd({"evaluate", "--seg", warped, "--truth", c.truth.string(), "--label", "1", "--json"}, c.dir,
                      "evaluate-elastix", false);
      if (e.exit_code == 0)
        row.scores = scores_from(json::parse(read_text(c.dir / "evaluate-elastix.out")));
      else
        row.error = "evaluate: " + tail(read_text(c.dir / "evaluate-elastix.err"), 300);
    }
    if (row.error.empty())
      std::printf(": Dice %.4f, registration %.1f s\n", row.scores.dice, row.registration_seconds);
    else
      std::printf(" FAILED: %s\n", row.error.c_str());
    elastix_rows.push_back(row);
  }

  /// The snake, its initial surface, and both ITK level sets from that surface.
  void run_case(const Case& c) {
    if (!only.empty() && c.name.find(only) == std::string::npos) return;
    std::printf("  %s: segment", c.name.c_str());
    std::fflush(stdout);
    const fs::path seg = c.dir / "seg", init = c.dir / "init";
    std::vector<std::string> init_args;
    if (!primary_init.empty()) init_args = {"--init", primary_init};
    std::vector<std::string> seg_args{"segment",        "--image", c.image.string(), "--model",
                                      c.model.string(), "-o",      seg.string(),     "--json"};
    seg_args.insert(seg_args.end(), init_args.begin(), init_args.end());
    const ChildResult r = mrsnake_cmd(seg_args, c.dir, "segment", false);
    json report;
    Row snake = make_row(c.name, primary_method());
    if (r.exit_code == 0) {
      report = json::parse(read_text(seg / "report.json"));
      snake.seconds = report["compute_seconds"].get<double>();
      snake.load_seconds = report["stage_seconds"]["load"].get<double>();
      snake.peak_mib = r.peak_mib;
      snake.wall_seconds = r.wall_seconds;
      snake.scores = score_in_child(seg / "labels.nii.gz", c.truth, c.dir / "score-snake.json");
      snake.extra = {{"model_levels", static_cast<int>(report["levels"].size()) - 1},
                     {"vertices", report["vertices"]},
                     {"force", report["force"]},
                     {"converged", report["converged"]},
                     {"self_intersections", report["self_intersections"]},
                     {"stage_seconds", report["stage_seconds"]},
                     {"initial_pose", report["initial_pose"]}};
    } else {
      snake.scores.dice = 0;
      snake.scores.assd_mm = snake.scores.hd95_mm = INFINITY;
      snake.extra = {{"error", tail(read_text(c.dir / "segment.err"), 400)}};
      std::printf(" FAILED (exit %d): %s", r.exit_code, tail(read_text(c.dir / "segment.err"), 300).c_str());
    }

    // The snake's initial surface: the same run with no iteration (synthesis from the
    // initially posed S_0 follows the similarity, so the finest level is the posed S_L).
    std::printf(", initial surface");
    std::fflush(stdout);
    std::vector<std::string> start_args{"segment", "--image",     c.image.string(),   "--model", c.model.string(),
                                        "-o",      init.string(), "--max-iterations", "0",       "--json"};
    start_args.insert(start_args.end(), init_args.begin(), init_args.end());
    const ChildResult ri = mrsnake_cmd(start_args, c.dir, "init", false);
    if (ri.exit_code != 0) {
      std::printf(" FAILED; no level set comparison\n");
      rows.push_back(snake);
      return;
    }
    const json init_report = json::parse(read_text(init / "report.json"));
    if (r.exit_code == 0 && init_report["initial_pose"] != report["initial_pose"])
      std::printf(" (warning: initial pose differs from the full run's)");
    Row init_row = make_row(c.name, "initial surface");
    init_row.scores = score_in_child(init / "labels.nii.gz", c.truth, c.dir / "score-init.json");
    rows.push_back(init_row);
    rows.push_back(snake);
    {
      InitRow ir;
      ir.case_name = c.name;
      ir.init = primary_init.empty() ? "(default)" : primary_init;
      fill_init_row(ir, init_report);
      ir.initial_dice = init_row.scores.dice;
      ir.final_dice = snake.scores.dice;
      init_rows.push_back(ir);
    }

    // Other initializations of the snake, for comparison (the level sets keep the default's start).
    for (const std::string& mode : extra_inits) {
      const fs::path dir = c.dir / ("seg-init-" + mode);
      std::printf(", segment --init %s", mode.c_str());
      std::fflush(stdout);
      const ChildResult rx = mrsnake_cmd({"segment", "--image", c.image.string(), "--model", c.model.string(), "-o",
                                          dir.string(), "--init", mode, "--json"},
                                         c.dir, "segment-init-" + mode, false);
      Row row = make_row(c.name, "mrsnake --init " + mode);
      if (rx.exit_code != 0) {
        row.scores.dice = 0;
        row.scores.assd_mm = row.scores.hd95_mm = INFINITY;
      } else {
        const json rep = json::parse(read_text(dir / "report.json"));
        row.seconds = rep["compute_seconds"].get<double>();
        row.load_seconds = rep["stage_seconds"]["load"].get<double>();
        row.peak_mib = rx.peak_mib;
        row.wall_seconds = rx.wall_seconds;
        row.scores = score_in_child(dir / "labels.nii.gz", c.truth, c.dir / ("score-init-" + mode + ".json"));
        row.extra = {{"initial_pose", rep["initial_pose"]}, {"stage_seconds", rep["stage_seconds"]}};
        if (rep.contains("registration")) row.extra["registration"] = rep["registration"];
      }
      rows.push_back(row);
      // Its initial surface (no iteration), for the initialization table.
      InitRow ir;
      ir.case_name = c.name;
      ir.init = mode;
      ir.final_dice = row.scores.dice;
      const fs::path start_dir = c.dir / ("init-" + mode);
      const ChildResult rs = mrsnake_cmd({"segment", "--image", c.image.string(), "--model", c.model.string(), "-o",
                                          start_dir.string(), "--init", mode, "--max-iterations", "0", "--json"},
                                         c.dir, "init-" + mode, false);
      if (rs.exit_code == 0) {
        fill_init_row(ir, json::parse(read_text(start_dir / "report.json")));
        ir.initial_dice =
            score_in_child(start_dir / "labels.nii.gz", c.truth, c.dir / ("score-start-" + mode + ".json")).dice;
      }
      init_rows.push_back(ir);
    }

    Row best;
    best.scores.dice = -1;
    for (const std::string method : {"itk_gac", "itk_threshold"}) {
      std::printf(", %s", method.c_str());
      std::fflush(stdout);
      const fs::path out = c.dir / (method + ".json");
      const ChildResult rl = run_forked([&] {
        bench::set_itk_threads(1);
        const auto t0 = Clock::now();
        const Volume image = read_volume(c.image.string());
        const Volume start = read_structure_labels(init / "labels.nii.gz");
        const double load = seconds_since(t0);
        const bench::LevelSetRun run = method == "itk_gac" ? bench::geodesic_active_contour(image, start, itk_options)
                                                           : bench::threshold_level_set(image, start, itk_options);
        rusage ru{};
        getrusage(RUSAGE_SELF, &ru);
        json j{{"seconds", run.seconds},
               {"evolution_seconds", run.evolution_seconds},
               {"load_seconds", load},
               {"peak_mib", ru.ru_maxrss / 1024.0},
               {"iterations", run.iterations},
               {"rms_change", run.rms_change},
               {"parameters", json::parse(run.parameters_json)}};
        json s;
        to_json(s, evaluate_segmentation(run.labels, read_volume(c.truth.string())));
        j["scores"] = s;
        std::ofstream(out) << j.dump();
        if (keep_labels) write_volume((c.dir / (method + "-labels.nii.gz")).string(), run.labels, VoxelType::uint8);
        return 0;
      });
      Row row = make_row(c.name, method);
      if (rl.exit_code != 0) {
        std::printf(" FAILED");
        row.scores.dice = 0;
        row.scores.assd_mm = row.scores.hd95_mm = INFINITY;
      } else {
        const json j = json::parse(read_text(out));
        row.scores = scores_from(j["scores"]);
        row.seconds = j["seconds"];
        row.load_seconds = j["load_seconds"];
        row.peak_mib = j["peak_mib"];
        row.wall_seconds = rl.wall_seconds;
        row.extra = {{"iterations", j["iterations"]},
                     {"rms_change", j["rms_change"]},
                     {"evolution_seconds", j["evolution_seconds"]},
                     {"parameters", j["parameters"]}};
        if (row.scores.dice > best.scores.dice) best = row;
      }
      rows.push_back(row);
    }
    std::printf("\n");
    if (best.scores.dice >= 0 && r.exit_code == 0) {
      for (Row& row : rows)
        if (row.case_name == c.name && row.method.rfind("mrsnake", 0) == 0) {
          row.speedup = best.seconds / row.seconds;
          row.extra["best_itk"] = best.method;
          row.extra["best_itk_dice"] = best.scores.dice;
        }
    }
    cases.push_back({{"case", c.name}, {"model_levels", c.model_levels}});
  }

  void print_table() const {
    std::printf(
        "\n| case | method | Dice | ASSD mm | HD95 mm | seconds (compute) | load s | peak MiB | speed-up vs best ITK "
        "|\n");
    std::printf("|---|---|---|---|---|---|---|---|---|\n");
    const auto num = [](double v, const char* f) {
      if (std::isnan(v)) return std::string("–");
      if (std::isinf(v)) return std::string("inf");
      char buf[32];
      std::snprintf(buf, sizeof buf, f, v);
      return std::string(buf);
    };
    for (const Row& r : rows)
      std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r.case_name.c_str(), r.method.c_str(),
                  num(r.scores.dice, "%.4f").c_str(), num(r.scores.assd_mm, "%.3f").c_str(),
                  num(r.scores.hd95_mm, "%.3f").c_str(), num(r.seconds, "%.3f").c_str(),
                  num(r.load_seconds, "%.3f").c_str(), num(r.peak_mib, "%.0f").c_str(),
                  std::isnan(r.speedup) ? "" : num(r.speedup, "%.1f×").c_str());
    if (init_rows.empty()) return;
    std::printf(
        "\nInitialization routes (initial surface: the same run with --max-iterations 0):\n\n"
        "| case | --init | route taken | initial Dice | final Dice | init s | registration s | registration |\n"
        "|---|---|---|---|---|---|---|---|\n");
    for (const InitRow& r : init_rows)
      std::printf("| %s | %s | %s | %s | %s | %s | %s | %s |\n", r.case_name.c_str(), r.init.c_str(),
                  r.init_used.c_str(), num(r.initial_dice, "%.4f").c_str(), num(r.final_dice, "%.4f").c_str(),
                  num(r.init_seconds, "%.3f").c_str(), num(r.register_seconds, "%.3f").c_str(), r.registration.c_str());
  }

  /// Real data: the snake's primary run beside single-atlas elastix, per case and on average.
  void print_elastix_table() const {
    std::printf("\nmrsnake (%s, the default) against single-atlas elastix:\n", elastix_rival.c_str());
    if (!elastix_skipped.empty()) std::printf("  elastix column skipped: %s\n", elastix_skipped.c_str());
    if (!elastix_rows.empty()) {
      std::printf(
          "  elastix: the reference image (the one the model was built from; moving) registered to the case's image\n"
          "  (fixed), affine then B-spline, Mattes mutual information, 4 resolutions, 250 / 500 iterations per\n"
          "  resolution, 2048 random samples, one thread (bench/elastix_atlas: the parameters of "
          "bench/cross_subject);\n"
          "  the B-spline grid is FinalGridSpacingInVoxels %d:",
          kElastixGridVoxels);
      std::map<std::string, std::vector<const ElastixRow*>> by_dataset;
      for (const ElastixRow& e : elastix_rows) by_dataset[e.dataset].push_back(&e);
      bool first = true;
      for (const auto& [dataset, list] : by_dataset) {
        const std::vector<double>& mm = list.front()->fixed_spacing_mm;
        std::vector<double> grid(3, 0.0);
        int laid = 0;
        for (const ElastixRow* e : list)
          if (e->grid_spacing_mm.size() == 3) {
            for (int d = 0; d < 3; ++d) grid[d] += e->grid_spacing_mm[d];
            ++laid;
          }
        std::vector<double> nominal;
        for (double v : mm) nominal.push_back(kElastixGridVoxels * v);
        std::printf("%s %s at %s's %s voxels", first ? "" : ";", spacing_text(nominal).c_str(), dataset.c_str(),
                    spacing_text(mm).c_str());
        if (laid > 0)
          std::printf(" (as elastix laid it on the box after the affine: mean %s×%s×%s mm)",
                      cell(grid[0] / laid, "%.1f").c_str(), cell(grid[1] / laid, "%.1f").c_str(),
                      cell(grid[2] / laid, "%.1f").c_str());
        first = false;
      }
      std::printf(
          ".\n  transformix warps the reference truth (the structure's label; for a two-part label only the modelled\n"
          "  part, as synth takes it) with nearest neighbour; `mrsnake evaluate` scores it against the case's truth.\n"
          "  elastix s: the registration's wall seconds (transformix not included); mrsnake compute s: after\n"
          "  loading (report.json); wall s: the whole segment process. Distances in mm.\n");
    }
    std::printf(
        "\n| case | mrsnake Dice | ASSD | HD95 | compute s | wall s | elastix Dice | ASSD | HD95 | elastix s |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n");
    std::map<std::string, const ElastixRow*> elastix_of;
    for (const ElastixRow& e : elastix_rows) elastix_of[e.case_name] = &e;
    ColumnMean m_dice, m_assd, m_hd95, m_compute, m_wall, e_dice, e_assd, e_hd95, e_seconds;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    int n = 0;
    for (const Row& r : rows) {
      if (r.method != elastix_rival) continue;
      const ElastixRow* e = elastix_of.count(r.case_name) ? elastix_of.at(r.case_name) : nullptr;
      const double ed = e ? e->scores.dice : nan, ea = e ? e->scores.assd_mm : nan, eh = e ? e->scores.hd95_mm : nan;
      const double es = e ? e->registration_seconds : nan;
      std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r.case_name.c_str(),
                  cell(r.scores.dice, "%.4f").c_str(), cell(r.scores.assd_mm, "%.3f").c_str(),
                  cell(r.scores.hd95_mm, "%.3f").c_str(), cell(r.seconds, "%.3f").c_str(),
                  cell(r.wall_seconds, "%.2f").c_str(), cell(ed, "%.4f").c_str(), cell(ea, "%.3f").c_str(),
                  cell(eh, "%.3f").c_str(), cell(es, "%.1f").c_str());
      m_dice.add(r.scores.dice);
      m_assd.add(r.scores.assd_mm);
      m_hd95.add(r.scores.hd95_mm);
      m_compute.add(r.seconds);
      m_wall.add(r.wall_seconds);
      e_dice.add(ed);
      e_assd.add(ea);
      e_hd95.add(eh);
      e_seconds.add(es);
      ++n;
    }
    std::printf("| mean of %d | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", n, m_dice.text("%.4f").c_str(),
                m_assd.text("%.3f").c_str(), m_hd95.text("%.3f").c_str(), m_compute.text("%.3f").c_str(),
                m_wall.text("%.2f").c_str(), e_dice.text("%.4f").c_str(), e_assd.text("%.3f").c_str(),
                e_hd95.text("%.3f").c_str(), e_seconds.text("%.1f").c_str());
    for (const ElastixRow& e : elastix_rows)
      if (!e.error.empty())
        std::printf("elastix failed on %s (scored Dice 0): %s\n", e.case_name.c_str(), e.error.c_str());
  }

  json elastix_rows_json() const {
    json out = json::array();
    const auto val = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    for (const ElastixRow& e : elastix_rows) {
      json s;
      to_json(s, e.scores);
      out.push_back({{"case", e.case_name},
                     {"dataset", e.dataset},
                     {"dice", val(e.scores.dice)},
                     {"assd_mm", val(e.scores.assd_mm)},
                     {"hd95_mm", val(e.scores.hd95_mm)},
                     {"registration_seconds", val(e.registration_seconds)},
                     {"transformix_seconds", val(e.transformix_seconds)},
                     {"grid_voxels", kElastixGridVoxels},
                     {"error", e.error.empty() ? json(nullptr) : json(e.error)},
                     {"scores", s},
                     {"elastix_atlas", e.record}});
    }
    return out;
  }

  json init_rows_json() const {
    json out = json::array();
    const auto val = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    for (const InitRow& r : init_rows)
      out.push_back({{"case", r.case_name},
                     {"init", r.init},
                     {"init_used", r.init_used},
                     {"initial_dice", val(r.initial_dice)},
                     {"final_dice", val(r.final_dice)},
                     {"init_seconds", val(r.init_seconds)},
                     {"register_seconds", val(r.register_seconds)},
                     {"registration", r.registration}});
    return out;
  }

  /// Targets per case: Dice ≥ best ITK, speed-up ≥ 20, and (256³) compute ≤ 1 s with ≥ 5 levels.
  json targets() const {
    json out = json::array();
    std::printf("\nTargets (mrsnake vs the best ITK level set of the case):\n");
    for (const Row& r : rows) {
      if (r.method.rfind("mrsnake", 0) != 0) continue;
      const bool has_best = r.extra.contains("best_itk_dice");
      double best_dice = -1;
      for (const Row& o : rows)
        if (o.case_name == r.case_name && o.method.rfind("itk_", 0) == 0)
          best_dice = std::max(best_dice, o.scores.dice);
      const bool dice_ok = r.scores.dice >= best_dice;
      const bool speed_ok = has_best && r.speedup >= 20;
      json t{{"case", r.case_name}, {"dice_at_least_best_itk", dice_ok}, {"speedup_at_least_20", speed_ok}};
      std::string line = "  " + r.case_name + " (" + r.method + "): Dice ≥ best ITK " + (dice_ok ? "met" : "NOT met") +
                         ", 20× " + (speed_ok ? "met" : "NOT met");
      t["method"] = r.method;
      if (r.case_name.find("liver") != std::string::npos) {
        t["liver_dice_at_least_0_9"] = r.scores.dice >= 0.9;
        line += std::string(", liver Dice ≥ 0.9 ") + (r.scores.dice >= 0.9 ? "met" : "NOT met");
      }
      if (r.case_name.find("256") != std::string::npos) {
        const int levels = r.extra.value("model_levels", 0);
        const bool fast = r.seconds <= 1.0 && levels >= 5;
        t["compute_at_most_1s_with_5_levels"] = fast;
        char buf[96];
        std::snprintf(buf, sizeof buf, ", ≤ 1 s at 256³ with L = %d (%.3f s) %s", levels, r.seconds,
                      fast ? "met" : "NOT met");
        line += buf;
      }
      std::printf("%s\n", line.c_str());
      out.push_back(t);
    }
    return out;
  }

  json to_json_rows() const {
    json out = json::array();
    for (const Row& r : rows) {
      json s;
      to_json(s, r.scores);
      const auto val = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
      out.push_back({{"case", r.case_name},
                     {"method", r.method},
                     {"dice", val(r.scores.dice)},
                     {"assd_mm", val(r.scores.assd_mm)},
                     {"hd95_mm", val(r.scores.hd95_mm)},
                     {"seconds", val(r.seconds)},
                     {"load_seconds", val(r.load_seconds)},
                     {"peak_mib", val(r.peak_mib)},
                     {"wall_seconds", val(r.wall_seconds)},
                     {"speedup_vs_best_itk", val(r.speedup)},
                     {"details", r.extra}});
    }
    return out;
  }
};

void synthetic_cases(Bench& b, bool quick) {
  struct Variant {
    double snr;
    bool posed;
  };
  struct Size {
    int voxels, levels;
    std::vector<Variant> variants;
  };
  // Modest counts: a full run fits in ~20 minutes on two cores (ITK's level sets dominate).
  std::vector<Size> sizes{{128, 4, {{8, false}, {8, true}, {4, false}, {4, true}, {2, true}}}};
  if (!quick) sizes.push_back({256, 5, {{8, false}, {4, true}}});
  for (const Size& size : sizes)
    for (const std::string shape : {"blob", "heart"}) {
      const std::string deform = std::to_string(size.voxels / 32);  // mm: 4 at 128³, 8 at 256³
      const std::string tag = shape + "-" + std::to_string(size.voxels);
      const auto case_name = [&](double snr, bool posed) {
        char name[96];
        std::snprintf(name, sizeof name, "%s %d³ SNR %g %s", shape.c_str(), size.voxels, snr,
                      posed ? "posed" : "centred");
        return std::string(name);
      };
      bool wanted = b.only.empty();
      for (const Variant& v : size.variants)
        wanted = wanted || case_name(v.snr, v.posed).find(b.only) != std::string::npos;
      if (!wanted) continue;
      const fs::path mdir = b.work / ("model-" + tag);
      fs::create_directories(mdir);
      // The model: another instance of the shape (its own seed, no pose, its own deformation).
      b.mrsnake_cmd({"synth", "--shape", shape, "--size", std::to_string(size.voxels), "--snr", "8", "--deform", deform,
                     "--seed", std::to_string(1000 + size.voxels), "-o", (mdir / "case").string()},
                    mdir, "synth");
      const fs::path model = mdir / "model";
      const fs::path levels_config = mdir / "levels.json";
      std::ofstream(levels_config) << "{\"levels\": " << size.levels << "}\n";
      const int levels = b.build_model(mdir / "case" / "truth.nii.gz", 1, mdir / "case" / "image.nii.gz", model,
                                       {"--config", levels_config.string()});
      for (std::size_t vi = 0; vi < size.variants.size(); ++vi) {
        const double snr = size.variants[vi].snr;
        const bool posed = size.variants[vi].posed;
        // The same case whatever --only selects.
        const int case_seed = size.voxels * 100 + (shape == "blob" ? 0 : 50) + static_cast<int>(vi);
        Case c;
        c.name = case_name(snr, posed);
        if (!b.only.empty() && c.name.find(b.only) == std::string::npos) continue;
        c.dir = b.work / (tag + "-snr" + std::to_string(static_cast<int>(snr)) + (posed ? "-posed" : "-centred"));
        fs::create_directories(c.dir);
        std::vector<std::string> args{"synth",
                                      "--shape",
                                      shape,
                                      "--size",
                                      std::to_string(size.voxels),
                                      "--snr",
                                      std::to_string(snr),
                                      "--deform",
                                      deform,
                                      "--seed",
                                      std::to_string(case_seed),
                                      "-o",
                                      (c.dir / "case").string()};
        if (posed) {
          args.push_back("--pose");
          args.push_back("random");
        }
        b.mrsnake_cmd(args, c.dir, "synth");
        c.image = c.dir / "case" / "image.nii.gz";
        c.truth = c.dir / "case" / "truth.nii.gz";
        c.model = model;
        c.model_levels = levels;
        b.run_case(c);
      }
    }
}

void real_cases(Bench& b, const fs::path& data) {
  struct Structure {
    std::string name, image, labels;
    int label;
    std::vector<std::string> model_options;
    std::string deform_mm;
    int component = 0;  ///< the label's part by size (build-model and synth --component); 0 = all of it
  };
  const fs::path v = data / "volumes";
  const std::vector<Structure> structures{
      {"liver (abdomen-ct-small, label 5)",
       "abdomen-ct-small.nii.gz",
       "abdomen-ct-small-seg.nii.gz",
       5,
       {"--close-tunnels", "3"},
       "6"},
      {"fourth ventricle (MRIcrop, label 3)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 3, {}, "2"},
      {"right hippocampus (MRIcrop, label 4)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 4, {}, "2"},
      {"left hippocampus (MRIcrop, label 5)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 5, {}, "2"},
      // Its five specks (8-60 faces) are dropped by the model and stay in the truth.
      {"corpus callosum (MRIcrop, label 8)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 8, {}, "2"},
      // Two organs under one label each (left and right): one model and one truth per part.
      {"caudate, larger part (MRIcrop, label 7)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 7, {}, "2", 1},
      {"caudate, smaller part (MRIcrop, label 7)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 7, {}, "2", 2},
      {"temporal horn, larger part (MRIcrop, label 6)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 6, {}, "2", 1},
      {"temporal horn, smaller part (MRIcrop, label 6)", "MRIcrop-orig.gipl.gz", "MRIcrop-seg.gipl.gz", 6, {}, "2", 2},
  };
  int seed = 7;
  for (const Structure& s : structures) {
    if (!fs::exists(v / s.image) || !fs::exists(v / s.labels)) {
      std::printf("  skipped %s: %s not found\n", s.name.c_str(), (v / s.image).c_str());
      continue;
    }
    Case c;
    c.name = s.name;
    c.dir = b.work / ("real-" + std::to_string(seed));
    fs::create_directories(c.dir);
    c.model = c.dir / "model";
    std::printf("  %s:\n", s.name.c_str());
    std::vector<std::string> model_options = s.model_options, part;
    if (s.component > 0) part = {"--component", std::to_string(s.component)};
    model_options.insert(model_options.end(), part.begin(), part.end());
    c.model_levels = b.build_model(v / s.labels, s.label, v / s.image, c.model, model_options);
    // A new case: the same image and label, warped by a known random pose and deformation.
    std::vector<std::string> synth{"synth",
                                   "--from-image",
                                   (v / s.image).string(),
                                   "--from-labels",
                                   (v / s.labels).string(),
                                   "--label",
                                   std::to_string(s.label),
                                   "--pose",
                                   "random",
                                   "--deform",
                                   s.deform_mm,
                                   "--seed",
                                   std::to_string(seed++),
                                   "-o",
                                   (c.dir / "case").string()};
    synth.insert(synth.end(), part.begin(), part.end());
    b.mrsnake_cmd(synth, c.dir, "synth");
    c.image = c.dir / "case" / "image.nii.gz";
    c.truth = c.dir / "case" / "truth.nii.gz";
    b.run_case(c);
    if (!b.elastix_atlas.empty() && (b.only.empty() || c.name.find(b.only) != std::string::npos)) {
      const fs::path reference_truth = c.dir / "reference-truth.nii.gz";
      Bench::write_reference_truth(v / s.labels, s.label, s.component, reference_truth);
      b.run_elastix(c, s.image.substr(0, s.image.find('.')), v / s.image, reference_truth);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, keep = false;
  std::string real, work, json_out = "bench_segment.json", only, gac, elastix_atlas;
  std::string mrsnake_bin;
  if (const char* env = std::getenv("MRSNAKE_BIN")) mrsnake_bin = env;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--quick")
      quick = true;
    else if (a == "--keep")
      keep = true;
    else if (a == "--real")
      real = value();
    else if (a == "--mrsnake")
      mrsnake_bin = value();
    else if (a == "--work")
      work = value();
    else if (a == "--json")
      json_out = value();
    else if (a == "--only")
      only = value();
    else if (a == "--gac")
      gac = value();
    else if (a == "--elastix-atlas")
      elastix_atlas = value();
    else {
      std::fprintf(
          stderr,
          "usage: bench_segment [--quick] [--real DATA_DIR] [--mrsnake BIN] [--work DIR] [--json OUT] [--keep]\n"
          "                     [--only CASE_SUBSTRING] [--gac "
          "PROPAGATION,CURVATURE,ADVECTION[,SIGMA_MM,BETA_FRACTION,ALPHA_DIVISOR]]\n"
          "                     [--elastix-atlas SCRIPT]\n");
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  if (mrsnake_bin.empty()) {
    // Next to this binary's build tree: build/bench/bench_segment → build/apps/mrsnake.
    mrsnake_bin = (fs::canonical("/proc/self/exe").parent_path().parent_path() / "apps" / "mrsnake").string();
  }
  if (!fs::exists(mrsnake_bin)) {
    std::fprintf(stderr, "mrsnake binary not found at %s; build it or pass --mrsnake\n", mrsnake_bin.c_str());
    return 2;
  }
  Bench b;
  b.mrsnake = fs::absolute(mrsnake_bin).string();
  b.keep_labels = keep;
  b.only = only;
  if (!gac.empty()) {  // PROPAGATION,CURVATURE,ADVECTION[,SIGMA_MM,BETA_FRACTION,ALPHA_DIVISOR]
    auto& o = b.itk_options;
    double* fields[] = {&o.gac_propagation, &o.gac_curvature,     &o.gac_advection,
                        &o.gac_sigma_mm,    &o.gac_beta_fraction, &o.gac_alpha_divisor};
    std::stringstream ss(gac);
    std::string item;
    for (int k = 0; k < 6 && std::getline(ss, item, ','); ++k) *fields[k] = std::stod(item);
  }
  const bool temp_work = work.empty();
  b.work = temp_work ? fs::temp_directory_path() / ("bench_segment." + std::to_string(getpid())) : fs::path(work);
  fs::create_directories(b.work);
  {
    const ChildResult h = b.mrsnake_cmd({"build-model", "--help"}, b.work, "build-model-help", false);
    b.model_takes_image =
        h.exit_code == 0 && read_text(b.work / "build-model-help.out").find("--image") != std::string::npos;
  }
  std::printf("bench_segment: %s, work folder %s; models %s an appearance (build-model --image)\n",
              real.empty() ? (quick ? "synthetic 128³ (quick)" : "synthetic 128³ and 256³") : "real data",
              b.work.c_str(), b.model_takes_image ? "with" : "without");
  if (!real.empty()) {
    // Single-atlas elastix beside the snake: bench/elastix_atlas (next to this source file
    // unless given), which needs elastix and transformix.
    if (elastix_atlas.empty()) elastix_atlas = (fs::path(__FILE__).parent_path() / "elastix_atlas").string();
    if (!on_path("elastix") || !on_path("transformix"))
      b.elastix_skipped = "elastix or transformix is not on PATH (apt-get install elastix)";
    else if (access(elastix_atlas.c_str(), X_OK) != 0)
      b.elastix_skipped = "no executable " + elastix_atlas + " (give --elastix-atlas)";
    else
      b.elastix_atlas = fs::absolute(elastix_atlas).string();
    if (!b.elastix_skipped.empty()) std::printf("elastix column skipped: %s\n", b.elastix_skipped.c_str());
  }
  const auto t0 = Clock::now();
  try {
    if (real.empty()) {
      synthetic_cases(b, quick);
    } else {
      // The model's own pose + the similarity fit: the moments of a threshold mislead on these
      // images (neighbouring tissue of similar intensity); the default is shown for comparison.
      b.primary_init = "fit";
      b.extra_inits = {"moments+fit", "register", "register+fit"};
      real_cases(b, real);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_segment: %s\n", e.what());
    b.print_table();
    if (!real.empty()) b.print_elastix_table();
    return 1;
  }
  b.print_table();
  if (!real.empty()) b.print_elastix_table();
  const json targets = b.targets();
  std::printf("\ntotal %.0f s\n", seconds_since(t0));
  json out{{"benchmark", real.empty() ? "synthetic" : "real"},
           {"mrsnake", b.mrsnake},
           {"model_appearance", b.model_takes_image},
           {"threads", 1},
           {"rows", b.to_json_rows()},
           {"initializations", b.init_rows_json()},
           {"elastix", b.elastix_rows_json()},
           {"elastix_skipped", b.elastix_skipped.empty() ? json(nullptr) : json(b.elastix_skipped)},
           {"targets", targets},
           {"total_seconds", seconds_since(t0)}};
  write_text_file_atomically(json_out, out.dump(2) + "\n");
  std::printf("wrote %s\n", json_out.c_str());
  if (temp_work && !keep) fs::remove_all(b.work);
  return 0;
}
