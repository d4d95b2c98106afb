// mrsnake remesh MESH -o DIR: the semi-regular hierarchy of section 4 of the seed paper.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "apps/cli.h"
#include "apps/report/remesh_page.h"
#include "mesh/atomic_file.h"
#include "mesh/json_options.h"
#include "mesh/json_text.h"
#include "mesh/mesh_io.h"
#include "remesh/remesh.h"
#include "remesh/remesh_options_json.h"

namespace mrsnake::cli {

namespace {

// A finest level that passes through itself, or cuts a part of the input off, is flagged:
// its quality figures look fine. The cause varies (a tip thinner than an edge, a fold of the
// base mesh), and so does the cure.
void warn_about_doubts(const nlohmann::json& report) {
  for (const auto& reason : report.value("suspect_reasons", nlohmann::json::array()))
    warn(reason.get<std::string>() + "; check it before use (report.json suspect_reasons)");
}

}  // namespace

void add_remesh_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("remesh",
                                 "Remesh a disk or closed genus-0 surface into a nested semi-regular hierarchy "
                                 "(level_0.vtp ... level_L.vtp, report.json and report.html)");
  struct Args {
    std::string mesh, out, config;
    // Bound directly, so that the defaults live in one place. The method's other settings are
    // one set of defaults for every shape (remesh/remesh.h), read from --config to change them.
    RemeshOptions options;
    bool no_relax = false, strict = false, json = false, compare_unrelaxed = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh,
                  "Input surface (.vtp .vtk .stl .ply .obj .off): a disk or a closed genus-0 surface")
      ->required();
  cmd->add_option("-o,--output", args->out, "Output folder")->required();
  auto* levels =
      cmd->add_option("--levels", args->options.levels, "Number of 1:4 splits L (base of --base-vertices vertices)")
          ->check(CLI::Range(1, 10));
  auto* faces =
      cmd->add_option("--faces", args->options.target_faces, "Wanted face count of the finest level (default 16000)")
          ->check(CLI::Range(16, 50000000));
  levels->excludes(faces);
  cmd->add_option("--base-vertices", args->options.base_vertices, "Base mesh size with --levels (default 32)")
      ->check(CLI::Range(6, 100000))
      ->needs(levels);
  auto* no_relax = cmd->add_flag("--no-relax", args->no_relax, "Split without relaxation (the paper's baseline)");
  auto* strict =
      cmd->add_flag("--strict", args->strict, "Relax only the new vertices of each level (the paper's exact method)");
  no_relax->excludes(strict);
  add_fit_rounds_option(*cmd, args->options.fit.rounds);
  add_sphere_map_option(*cmd, args->options.sphere_map);
  cmd->add_option("--config", args->config,
                  "Options of the method from a JSON file (the form of report.json's \"options\"; keys left out keep "
                  "their defaults); the flags given override it")
      ->check(CLI::ExistingFile);
  cmd->add_flag_callback(
         "--print-config",
         [] {
           print_json(nlohmann::json(RemeshOptions{}));
           throw CLI::Success();
         },
         "Print the default options as JSON (a start for --config) and exit")
      ->trigger_on_parse();
  cmd->add_flag("--compare-unrelaxed", args->compare_unrelaxed,
                "Also remesh without relaxation (a second run) and compare both in report.html and report.json")
      ->excludes(no_relax);
  cmd->add_flag("--json", args->json, "Print report.json to stdout");
  cmd->footer(
      "Example: mrsnake remesh liver.vtp -o liver_model --faces 16000\n"
      "Repeat a run: mrsnake remesh liver.vtp -o again --config <(jq .options liver_model/report.json)");
  auto* fit_rounds = cmd->get_option("--fit-rounds");
  auto* sphere_map = cmd->get_option("--sphere-map");
  auto* base_vertices = cmd->get_option("--base-vertices");
  cmd->callback([args, levels, faces, base_vertices, fit_rounds, sphere_map] {
    // Only an earlier remesh output is replaced: checked before the work, and at the end.
    const ReplaceableFolder earlier = folder_of_entries(
        [](const std::string& name) {
          return name == "report.json" || name == "report.html" ||
                 (name.rfind("level_", 0) == 0 && std::filesystem::path(name).extension() == ".vtp");
        },
        "an output of mrsnake remesh");
    require_replaceable(args->out, earlier);
    // The file's options (or the defaults), then the flags given.
    RemeshOptions options = args->config.empty() ? RemeshOptions{} : read_options_file<RemeshOptions>(args->config);
    if (levels->count() > 0) options.levels = args->options.levels;
    if (faces->count() > 0) {
      options.target_faces = args->options.target_faces;
      options.levels = 0;
    }
    if (base_vertices->count() > 0) options.base_vertices = args->options.base_vertices;
    if (fit_rounds->count() > 0) options.fit.rounds = args->options.fit.rounds;
    if (sphere_map->count() > 0) options.sphere_map = args->options.sphere_map;
    if (args->no_relax) options.relax = RelaxMode::none;
    if (args->strict) options.relax = RelaxMode::new_vertices_only;
    check_options(options);  // before the mesh is read
    const TriMesh input = read_mesh(args->mesh);
    if (!global_options().quiet) options.progress = terminal_progress();
    const RemeshResult result = remesh(input, options);
    nlohmann::json report = remesh_report(result, options);
    report["input"] = args->mesh;
    std::optional<RemeshResult> unrelaxed;
    if (args->compare_unrelaxed) {
      RemeshOptions plain = options;
      plain.relax = RelaxMode::none;
      unrelaxed = remesh(input, plain);
      report["unrelaxed"] = remesh_report(*unrelaxed, plain);
    }
    // Everything is computed before anything is written, into a temporary folder renamed
    // into place at the end: a failure or an interrupt leaves nothing under DIR.
    AtomicDirectory out(args->out, earlier);
    const std::filesystem::path dir(out.temp_path());
    for (int j = 0; j <= result.connectivity.levels(); ++j)
      write_mesh((dir / ("level_" + std::to_string(j) + ".vtp")).string(), result.mesh(j));
    write_text_file_atomically((dir / "report.json").string(), json_text(report, 2) + "\n");
    mrsnake::reports::RemeshPageOptions page;
    page.title = "mrsnake remesh " + std::filesystem::path(args->mesh).filename().string();
    page.input = &input;
    page.unrelaxed = unrelaxed ? &*unrelaxed : nullptr;
    page.report = report;
    mrsnake::reports::write_remesh_report((dir / "report.html").string(), result, page);
    out.commit();
    warn_about_doubts(report);
    if (args->json) {
      print_json(report);
      return;
    }
    std::ostringstream table;
    table << std::fixed << std::setprecision(2);
    table
        << "level  vertices    faces  min_angle  q_min  q_mean  val6%   rms%  hausdorff%  crossing  flipped  seconds\n";
    for (const auto& level : result.levels) {
      const auto& s = level.stats;
      table << std::setw(5) << s["level"].get<int>() << std::setw(10) << s["vertices"].get<long>() << std::setw(9)
            << s["faces"].get<long>();
      if (s.contains("quality")) {
        const auto& q = s["quality"];
        const auto& d = s["distance"];
        table << std::setw(11) << q["min_angle_deg"].get<double>() << std::setw(7) << q["q_min"].get<double>()
              << std::setw(8) << q["q_mean"].get<double>() << std::setw(7) << q["pct_valence6_interior"].get<double>()
              << std::setprecision(3) << std::setw(7) << d["rms_pct"].get<double>() << std::setw(12)
              << d["hausdorff_pct"].get<double>() << std::setw(10) << s["self_intersections"].get<int>()
              << std::setprecision(2);
      }
      table << std::setw(9) << level.flipped_triangles << std::setw(9) << level.seconds << '\n';
    }
    std::cout << table.str() << "wrote " << result.levels.size() << " levels and report.json and report.html to "
              << args->out << '\n';
  });
}

}  // namespace mrsnake::cli
