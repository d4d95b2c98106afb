// mrsnake segment: the multiresolution snake on a new volume (see snake/segment.h).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "apps/cli.h"
#include "apps/report/segment_page.h"
#include "mesh/atomic_file.h"
#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/mesh_io.h"
#include "mesh/parallel.h"
#include "snake/evaluate.h"
#include "snake/model_bridge.h"
#include "snake/rasterize.h"
#include "snake/segment.h"
#include "wavelets/model_io.h"

namespace mrsnake::cli {

namespace {

// report.html: slices with the contours, a render, convergence per level, timings.
void write_segment_page(const std::filesystem::path& path, const std::string& image_path, const Volume& image,
                        const Volume* truth, int truth_label, const SegmentResult& result, const nlohmann::json& rep) {
  mrsnake::reports::SegmentPageInput page;
  page.title = "mrsnake segment " + std::filesystem::path(image_path).filename().string();
  page.image = &image;
  page.surface = &result.surface;
  if (truth) {
    page.truth = truth;
    page.truth_label = static_cast<float>(truth_label);
  }
  for (const LevelOutcome& l : result.levels) {
    mrsnake::reports::SnakeConvergence c;
    c.level = l.level;
    c.deformed = l.deformed;
    for (const auto& it : l.snake.history) {
      c.energy.push_back(it.energy);
      c.external_energy.push_back(it.external_energy);
      c.internal_energy.push_back(it.internal_energy);
      c.mean_abs_offset_mm.push_back(it.mean_abs_offset_mm);
    }
    page.convergence.push_back(std::move(c));
  }
  page.report = rep;
  mrsnake::reports::write_segment_report(path.string(), page);
}

}  // namespace

void add_segment_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("segment", "Segment a volume with a shape model: coarse-to-fine snake, labels, surfaces and a report");
  struct Args {
    std::string image, model, output, truth, init = "auto", force = "auto", register_metric = "mattes";
    int truth_label = 1, max_iterations = -1;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--image", a->image, "Volume to segment (.nii.gz .nrrd .mha ..., or a DICOM folder)")->required();
  cmd->add_option("--model", a->model, "Shape model folder (made by 'mrsnake build-model')")->required();
  cmd->add_option("-o,--output", a->output, "Output folder: surface.vtp, labels.nii.gz, levels/level_j.vtp, report.json, report.html")
      ->required();
  cmd->add_option("--init", a->init,
                  "Initial pose: auto (register+fit if the model has a reference image, else moments+fit), pose, "
                  "moments, fit, moments+fit, register, register+fit")
      ->capture_default_str();
  cmd->add_option("--register-metric", a->register_metric,
                  "Metric of --init register: mattes (mutual information) or mean_squares (normalized intensities)")
      ->capture_default_str();
  cmd->add_option("--force", a->force, "External force: auto (profiles if the model has an appearance, unless they learned a clean step), profile, edge")
      ->capture_default_str();
  cmd->add_option("--truth", a->truth, "Truth labels on the image's grid: adds the scores of 'mrsnake evaluate' to the report");
  cmd->add_option("--truth-label", a->truth_label, "Label of the object in --truth")->capture_default_str();
  cmd->add_option("--max-iterations", a->max_iterations, "Iterations per level at most (default 40)");
  cmd->add_flag("--json", a->json, "Print the report as JSON on stdout");
  cmd->footer(
      "Example:\n"
      "  mrsnake segment --image case7/image.nii.gz --model heart.model -o case7/seg --truth case7/truth.nii.gz\n"
      "Writes DIR/surface.vtp (final level), DIR/labels.nii.gz (1 inside, on the image's grid),\n"
      "DIR/levels/level_j.vtp (each level after deformation), DIR/report.json and DIR/report.html.\n"
      "With a model built by 'build-model --image', the default initialization registers the model's\n"
      "reference image to IMAGE (ITK, similarity), then fits the coarse mesh; report.json's\n"
      "'registration' holds the transform, the metric and whether it was used or why not.");
  cmd->callback([a] {
    const auto progress = terminal_progress();
    const auto t_load = std::chrono::steady_clock::now();
    SegmentOptions options;
    options.init = parse_init_mode(a->init);
    options.registration.itk.metric = parse_registration_metric(a->register_metric);
    options.force = parse_force_mode(a->force);
    if (a->max_iterations >= 0) options.snake.max_iterations = a->max_iterations;
    report(progress, "load", 0.0);
    const Volume image = read_volume(a->image);
    Volume truth;
    if (!a->truth.empty()) {
      truth = read_volume(a->truth);
      require_same_grid(image, truth, "IMAGE", "TRUTH");
    }
    const SnakeModel model = snake_model_from(load_model(a->model));
    const double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();

    // The self-intersection count runs below, beside the rasterization.
    options.count_self_intersections = false;
    SegmentResult result = segment(image, model, options, progress);
    if (result.registration && !result.registration->accepted)
      warn("the reference image registration was not used (" + result.registration->rejection + "); initialized with " +
           to_string(result.init) + " instead");
    report(progress, "rasterize", 0.0);
    Volume labels;
    double rasterize_seconds = 0, count_seconds = 0;
    run_both_in_parallel(
        [&] {
          const auto t = std::chrono::steady_clock::now();
          labels = rasterize_mesh(result.surface, image, 1.0f);
          rasterize_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        },
        [&] {
          const auto t = std::chrono::steady_clock::now();
          result.self_intersections = count_self_intersections(result.surface);
          count_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        });
    result.stage_seconds.emplace_back("self_intersections", count_seconds);

    nlohmann::json rep = segment_report(result);
    rep["image"] = a->image;
    rep["model"] = a->model;
    rep["init"] = to_string(options.init);
    rep["stage_seconds"]["load"] = load_seconds;
    rep["stage_seconds"]["rasterize"] = rasterize_seconds;
    if (!a->truth.empty()) {
      report(progress, "evaluate", 0.0);
      nlohmann::json scores;
      to_json(scores, evaluate_segmentation(labels, truth, 1, a->truth_label));
      rep["scores"] = scores;
      rep["truth"] = a->truth;
    }

    // Everything goes to a temporary folder renamed into place at the end.
    report(progress, "write", 0.0);
    AtomicDirectory out(a->output);
    const std::filesystem::path dir = out.temp_path();
    std::filesystem::create_directories(dir / "levels");
    const auto write_meshes = [&] {
      write_mesh((dir / "surface.vtp").string(), result.surface);
      for (const LevelOutcome& l : result.levels)
        write_mesh((dir / "levels" / ("level_" + std::to_string(l.level) + ".vtp")).string(), l.surface);
      write_text_file_atomically((dir / "report.json").string(), rep.dump(2) + "\n");
    };
    // The compressed labels are written on the other core, beside the meshes.
    run_both_in_parallel(write_meshes,
                         [&] { write_volume((dir / "labels.nii.gz").string(), labels, VoxelType::uint8); });
    // After the join: the page's render forks a child, which must not start while another
    // thread may hold a lock (the allocator's, the loader's) that the child would then wait on.
    write_segment_page(dir / "report.html", a->image, image, a->truth.empty() ? nullptr : &truth, a->truth_label, result,
                       rep);
    out.commit();
    report(progress, "done", 1.0);

    if (a->json) {
      print_json(rep);
    } else {
      info("segmented " + a->image + " in " + std::to_string(result.compute_seconds) + " s of compute (" +
           std::to_string(result.levels.size()) + " levels, " + std::to_string(result.surface.num_vertices()) +
           " vertices, " + std::to_string(result.self_intersections) + " self-intersections)");
      if (rep.contains("scores")) {
        char line[160];
        std::snprintf(line, sizeof line, "Dice %.4f, ASSD %.3f mm, HD95 %.3f mm", rep["scores"]["dice"].get<double>(),
                      rep["scores"]["assd_mm"].is_null() ? INFINITY : rep["scores"]["assd_mm"].get<double>(),
                      rep["scores"]["hd95_mm"].is_null() ? INFINITY : rep["scores"]["hd95_mm"].get<double>());
        info(line);
      }
      info("wrote " + a->output + "/{surface.vtp, labels.nii.gz, levels/, report.json, report.html}");
    }
  });
}

}  // namespace mrsnake::cli
