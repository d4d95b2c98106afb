// mrsnake segment: the multiresolution snake on a new volume (see snake/segment.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <thread>
#include <vector>

#include <stdlib.h>

#include "apps/batch_pool.h"
#include "apps/cli.h"
#include "apps/exit_codes.h"
#include "apps/hints.h"
#include "apps/report/segment_page.h"
#include "apps/slicer_module.h"
#include "mesh/atomic_file.h"
#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/json_options.h"
#include "mesh/json_text.h"
#include "mesh/marching_cubes.h"
#include "mesh/merge.h"
#include "mesh/mesh_io.h"
#include "mesh/parallel.h"
#include "evaluation/evaluate.h"
#include "apps/segment_case.h"
#include "model/snake_adapter.h"
#include "snake/rasterize.h"
#include "snake/segment.h"
#include "model/model_io.h"

namespace mrsnake::cli {

namespace {

// The options segment and segment-batch share, and the SegmentOptions they give.
// With --config, the file's options, and of the flags only those given.
struct SnakeArgs {
  std::string config, init = "auto", force = "auto", register_metric = "mattes";
  int max_iterations = -1;
  const CLI::Option *init_flag = nullptr, *force_flag = nullptr, *metric_flag = nullptr;

  void add_to(CLI::App* cmd) {
    cmd->add_option("--config", config,
                    "Segmentation options, a JSON file (docs/segmentation.md; report.json's \"options\" is one); "
                    "the flags given replace its values");
    init_flag =
        cmd->add_option("--init", init,
                        "Initial pose: auto (register+fit if the model has a reference image, else moments+fit), pose, "
                        "moments, fit, moments+fit, register, register+fit")
            ->capture_default_str();
    metric_flag =
        cmd->add_option(
               "--register-metric", register_metric,
               "Metric of --init register: mattes (mutual information) or mean_squares (normalized intensities)")
            ->capture_default_str();
    force_flag =
        cmd->add_option(
               "--force", force,
               "External force: auto (profiles if the model has an appearance, unless they learned a clean step), "
               "profile, edge")
            ->capture_default_str();
    cmd->add_option("--max-iterations", max_iterations,
                    "Iterations per level at most (default " + std::to_string(SnakeOptions{}.max_iterations) +
                        "; 0 writes the placed model)")
        ->check(CLI::Range(0, kMaxSnakeIterations));
  }
  SegmentOptions options() const {
    SegmentOptions o = config.empty() ? SegmentOptions{} : read_options_file<SegmentOptions>(config);
    if (config.empty() || init_flag->count() > 0) o.init = parse_init_mode(init);
    if (config.empty() || metric_flag->count() > 0)
      o.registration.itk.metric = parse_registration_metric(register_metric);
    if (config.empty() || force_flag->count() > 0) o.force = parse_force_mode(force);
    if (max_iterations >= 0) o.snake.max_iterations = max_iterations;
    check_options(o);  // before the model and the images are read
    return o;
  }
};

// What `segment` prints: the compute time, and per structure its volume, verdict and scores.
void print_case_summary(const SegmentCase& c, const SegmentModel& model, const SegmentCaseOutcome& outcome) {
  const nlohmann::json& rep = outcome.report;
  char line[240];
  std::snprintf(line, sizeof line, "segmented %s in %.3f s of compute (%zu structure%s)", c.image.c_str(),
                rep["compute_seconds"].get<double>(), model.structures.size(), model.structures.size() == 1 ? "" : "s");
  info(line);
  for (const nlohmann::json& s : rep["structures"]) {
    std::snprintf(line, sizeof line, "  %d %s: %.4g mm3, %d vertices, %d self-intersections%s", s["value"].get<int>(),
                  s["name"].get<std::string>().c_str(), s["volume_mm3"].get<double>(), s["vertices"].get<int>(),
                  s["self_intersections"].get<int>(), s["suspect"].get<bool>() ? ", SUSPECT" : "");
    std::string text = line;
    if (s.contains("scores") && s["scores"].contains("dice")) {
      const auto& sc = s["scores"];
      std::snprintf(line, sizeof line, "; Dice %.4f, ASSD %.3f mm, HD95 %.3f mm", sc["dice"].get<double>(),
                    sc["assd_mm"].is_null() ? INFINITY : sc["assd_mm"].get<double>(),
                    sc["hd95_mm"].is_null() ? INFINITY : sc["hd95_mm"].get<double>());
      text += line;
    }
    info(text);
  }
  info("wrote " + c.output +
       "/{labels.nii.gz, labels.seg.nrrd, labels.ctbl, labels.itksnap.txt, surfaces/, report.json, report.html, "
       "slices.png" +
       (model.structures.size() == 1 ? std::string(", surface.vtp, levels/}") : std::string("}")));
}

// segment as a 3D Slicer CLI module: the image and the outputs Slicer loads back as positional
// arguments (the schema's indexed parameters), the result folder optional, and Slicer's
// return parameter file.
struct SlicerOutputs {
  std::string image, labels, surfaces, return_parameters;
};

void add_slicer_form(CLI::App* cmd, SlicerOutputs& s) {
  cmd->add_option("IMAGE", s.image, "The volume to segment, as a positional argument (instead of --image)");
  cmd->add_option("LABELS_OUT", s.labels,
                  "Also write the label map here (any image format: .nrrd, .nii.gz, ...), as 3D Slicer asks");
  cmd->add_option("SURFACES_OUT", s.surfaces,
                  "Also write every structure's surface here, as one mesh (.vtk .vtp .stl .ply .obj)");
  cmd->add_option("--returnparameterfile", s.return_parameters,
                  "Write volume_mm3, suspect and reason here as 'name = value' lines (3D Slicer's return parameters)");
  cmd->add_flag_callback(
      "--xml",
      [] {
        std::cout << segment_module_xml();
        throw CLI::Success();
      },
      "Print the 3D Slicer CLI module description (Slicer Execution Model XML) and exit");
}

// The result folder of a run without -o: a temporary one, removed when the run ends.
class TemporaryResult {
 public:
  explicit TemporaryResult(std::string path) : path_(std::move(path)) {}
  ~TemporaryResult() {
    std::error_code ec;
    if (!path_.empty()) std::filesystem::remove_all(path_, ec);
  }
  TemporaryResult(const TemporaryResult&) = delete;
  TemporaryResult& operator=(const TemporaryResult&) = delete;

 private:
  std::string path_;
};

// The image and the result folder of the run, from the flags or the positional form.
std::unique_ptr<TemporaryResult> start_slicer_form(const SlicerOutputs& s, std::string& image, std::string& output) {
  if (image.empty() == s.image.empty())
    throw CLI::ValidationError("--image", "give the volume to segment once: --image IMAGE, or IMAGE first");
  if (image.empty()) image = s.image;
  if (!output.empty()) return nullptr;
  if (s.labels.empty()) throw CLI::ValidationError("-o", "give the result folder, -o DIR (or LABELS_OUT after IMAGE)");
  std::string pattern = (std::filesystem::temp_directory_path() / "mrsnake-segment-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr)
    throw OutputError("cannot create a temporary result folder in " + std::filesystem::temp_directory_path().string() +
                      "; give the result folder with -o DIR");
  output = pattern;
  return std::make_unique<TemporaryResult>(output);
}

// The positional outputs and the return parameters, from the run.
void finish_slicer_form(const SlicerOutputs& s, const SegmentModel& model, const SegmentCaseOutcome& outcome) {
  if (!s.labels.empty()) {
    write_volume(s.labels, outcome.labels, label_voxel_type(model));
  }
  if (!s.surfaces.empty()) {
    std::vector<const TriMesh*> surfaces;
    for (const SegmentResult& r : outcome.results) surfaces.push_back(&r.surface);
    write_mesh(s.surfaces, merged_meshes(surfaces));
  }
  for (const std::string& path : {s.labels, s.surfaces, s.return_parameters})
    if (!path.empty()) info("wrote " + path);
  if (!s.return_parameters.empty()) {
    double volume = 0;
    for (const nlohmann::json& st : outcome.report["structures"]) volume += st["volume_mm3"].get<double>();
    write_return_parameters(s.return_parameters, {{"volume_mm3", std::to_string(volume)},
                                                  {"suspect", outcome.report["suspect"].get<bool>() ? "true" : "false"},
                                                  {"reason", outcome.report["reason"].get<std::string>()}});
  }
}
}  // namespace

void add_segment_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "segment", "Segment a volume with a shape model: coarse-to-fine snake, labels, surfaces and a report");
  struct Args {
    SegmentCase c;
    std::string model;
    SnakeArgs snake;
    bool json = false;
    int truth_label = 1;
    const CLI::Option* truth_label_flag = nullptr;
    SlicerOutputs slicer;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--image", a->c.image, "Volume to segment (.nii.gz .nrrd .mha ..., or a DICOM folder)");
  cmd->add_option("--series", a->c.series,
                  "The DICOM series to segment when the --image folder holds several: its Series Instance UID "
                  "(without it, such a folder is refused with a list of its series)");
  cmd->add_option("--model", a->model, "Shape model folder (made by 'mrsnake build-model')")->required();
  cmd->add_option("-o,--output", a->c.output,
                  "Output folder: labels.nii.gz (the reference's label values; named in labels.seg.nrrd, labels.ctbl "
                  "and labels.itksnap.txt), surfaces/VALUE.vtp, report.json, report.html, slices.png; for a model of "
                  "one structure also surface.vtp and levels/level_j.vtp");
  a->snake.add_to(cmd);
  cmd->add_option("--truth", a->c.truth,
                  "Truth labels on the image's grid: adds the scores of 'mrsnake evaluate' to the report");
  a->truth_label_flag =
      cmd->add_option("--truth-label", a->truth_label,
                      "Value of the structure in --truth, for a model of one structure (default: its own value "
                      "when the truth holds it, else 1); a model of several is scored on each "
                      "structure's own value");
  cmd->add_flag("--json", a->json, "Print the report as JSON on stdout");
  add_slicer_form(cmd, a->slicer);
  cmd->footer(
      "Example:\n"
      "  mrsnake segment --image case7/image.nii.gz --model heart.model -o case7/seg --truth case7/truth.nii.gz\n"
      "Writes DIR/labels.nii.gz (every structure with its reference label value, on the image's grid; a voxel\n"
      "inside two surfaces goes to the one it lies deepest inside), DIR/surfaces/VALUE.vtp per structure,\n"
      "DIR/report.json (per structure: volume, scores, and 'suspect' with its 'reason') and DIR/report.html;\n"
      "for a model of one structure also DIR/surface.vtp and DIR/levels/level_j.vtp (each level deformed).\n"
      "With a model built by 'build-model --image', the default initialization registers the model's\n"
      "reference image to IMAGE (ITK, similarity), then fits the coarse mesh; report.json's\n"
      "'registration' holds the transform, the metric and whether it was used or why not.\n"
      "Many images with one model: 'mrsnake segment-batch'. As a 3D Slicer module (--xml, docs/slicer.md):\n"
      "  mrsnake segment --model heart.model [-o DIR] IMAGE LABELS_OUT [SURFACES_OUT]");
  cmd->callback([a] {
    const auto progress = terminal_progress();
    const auto temporary = start_slicer_form(a->slicer, a->c.image, a->c.output);
    const SegmentOptions options = a->snake.options();
    report(progress, "load", 0.0);
    if (a->truth_label_flag->count() > 0) a->c.truth_label = a->truth_label;
    const SegmentModel model = load_segment_model(a->model);
    if (a->c.truth_label >= 0 && model.structures.size() > 1)
      throw OptionsError(
          "--truth-label names the structure's value in the truth for a model of one structure; the "
          "truth of a model of several must hold the reference's values");
    const SegmentCaseOutcome outcome = segment_case(a->c, model, a->model, options, model.load_seconds, progress);
    const nlohmann::json& rep = outcome.report;
    finish_slicer_form(a->slicer, model, outcome);
    if (a->json) {
      print_json(rep);
    } else {
      print_case_summary(a->c, model, outcome);
    }
  });
}

namespace {

// An output folder name per image: the file name without its extensions (a DICOM folder's
// own name), without leading dots. Names that collide take as many of their parent folders'
// names in front as tell them apart (study/mouse01/ct.nii.gz: mouse01_ct), then a number
// that no other name has.
std::vector<std::string> case_names(const std::vector<std::string>& images) {
  struct Entry {
    std::vector<std::string> parents;  // nearest first
    std::string name;
  };
  std::vector<Entry> entries;
  for (const std::string& image : images) {
    std::filesystem::path p = std::filesystem::absolute(image).lexically_normal();
    if (p.filename().empty()) p = p.parent_path();  // a folder given with a trailing slash
    Entry e;
    e.name = p.filename().string();
    if (std::error_code ec;
        !std::filesystem::is_directory(p, ec)) {  // a DICOM folder's name (a UID, 1.2.840...) is kept whole
      if (e.name.size() > 3 && e.name.compare(e.name.size() - 3, 3, ".gz") == 0) e.name.resize(e.name.size() - 3);
      if (const auto dot = e.name.rfind('.'); dot != std::string::npos && dot > 0) e.name.resize(dot);
    }
    // No hidden names: ".", ".." and the temporaries' ".tmp-" would not be folders of their own.
    e.name.erase(0, e.name.find_first_not_of('.'));
    if (e.name.empty()) e.name = "image";
    for (std::filesystem::path q = p.parent_path(); !q.filename().empty(); q = q.parent_path())
      e.parents.push_back(q.filename().string());
    entries.push_back(std::move(e));
  }
  // Per group of equal names, the fewest parent folders that tell its different paths apart
  // (the same image given twice stays one name, numbered below).
  std::map<std::string, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < entries.size(); ++i) groups[entries[i].name].push_back(i);
  for (const auto& [name, members] : groups) {
    if (members.size() < 2) continue;
    const auto prefix = [&](std::size_t i, std::size_t depth) {
      std::string text;
      for (std::size_t d = std::min(depth, entries[i].parents.size()); d > 0; --d)
        text += entries[i].parents[d - 1] + "_";
      return text;
    };
    std::size_t deepest = 0;
    for (const std::size_t i : members) deepest = std::max(deepest, entries[i].parents.size());
    std::set<std::string> paths;
    for (const std::size_t i : members) paths.insert(prefix(i, deepest));
    if (paths.size() < 2) continue;  // one image given several times
    std::size_t depth = 1;
    for (; depth < deepest; ++depth) {
      std::map<std::string, std::string> path_of;  // prefix -> the full path that has it
      bool distinct = true;
      for (const std::size_t i : members) {
        const std::string full = prefix(i, deepest);
        const auto [it, inserted] = path_of.emplace(prefix(i, depth), full);
        distinct = distinct && (inserted || it->second == full);
      }
      if (distinct) break;
    }
    for (const std::size_t i : members) entries[i].name = prefix(i, depth) + name;
  }
  // Numbered against every name taken so far, the summary's files included.
  std::set<std::string> taken{"batch.json", "batch.csv"};
  std::vector<std::string> names;
  for (const Entry& e : entries) {
    std::string base = e.name;  // a parent's name in front may bring a leading dot back (.cache_a)
    base.erase(0, base.find_first_not_of('.'));
    std::string name = base;
    for (int n = 2; taken.count(name) > 0; ++n) name = base + "_" + std::to_string(n);
    taken.insert(name);
    names.push_back(name);
  }
  return names;
}

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return quoted + "\"";
}

std::string csv_number(const nlohmann::json& value) {
  if (value.is_null()) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value.get<double>());
  return text;
}

// The structures of the batch's rows, in increasing value: one column each.
std::vector<std::string> structure_columns(const nlohmann::json& cases) {
  std::set<int> values;
  for (const auto& c : cases)
    if (c.contains("structures"))
      for (const auto& [value, s] : c["structures"].items()) values.insert(std::stoi(value));
  std::vector<std::string> columns;
  for (const int v : values) columns.push_back(std::to_string(v));
  return columns;
}

// One row's volume and verdict of each structure column.
std::string structure_fields(const nlohmann::json& c, const std::vector<std::string>& values) {
  std::string fields;
  for (const std::string& v : values) {
    const bool has = c.contains("structures") && c["structures"].contains(v);
    fields += "," + (has ? csv_number(c["structures"][v]["volume_mm3"]) : std::string()) + "," +
              (has ? std::string(c["structures"][v]["suspect"].get<bool>() ? "true" : "false") : std::string());
  }
  return fields;
}

// batch.csv: one row per image, in the order given, with each structure's volume and verdict.
std::string batch_csv(const nlohmann::json& cases) {
  const std::vector<std::string> values = structure_columns(cases);
  std::string csv =
      "image,output,status,volume_mm3,compute_seconds,load_seconds,wall_seconds,self_intersections,init_used,"
      "registration,suspect,reason,error,resumed";
  for (const std::string& v : values) csv += ",volume_mm3_" + v + ",suspect_" + v;
  csv += "\n";
  for (const auto& c : cases) {
    csv += csv_field(c["image"].get<std::string>()) + "," + csv_field(c["output"].get<std::string>()) + "," +
           c["status"].get<std::string>() + "," + csv_number(c.value("volume_mm3", nlohmann::json())) + "," +
           csv_number(c.value("compute_seconds", nlohmann::json())) + "," +
           csv_number(c.value("load_seconds", nlohmann::json())) + "," + csv_number(c["wall_seconds"]) + "," +
           (c.contains("self_intersections") ? csv_number(c["self_intersections"]) : std::string()) + "," +
           csv_field(c.value("init_used", std::string())) + "," + csv_field(c.value("registration", std::string())) +
           "," + (c.contains("suspect") ? std::string(c["suspect"].get<bool>() ? "true" : "false") : std::string()) +
           "," + csv_field(c.value("reason", std::string())) + "," + csv_field(c.value("error", std::string())) + "," +
           (c.value("resumed", false) ? "true" : "false") + structure_fields(c, values) + "\n";
  }
  return csv;
}

// Image paths from a list file: one per line; blank lines and lines starting with # skipped;
// relative paths are relative to the list's folder.
std::vector<std::string> read_image_list(const std::string& list) {
  std::ifstream in(list);
  if (std::error_code ec; !in || std::filesystem::is_directory(list, ec))
    throw InputError("cannot read the image list '" + list + "' (a text file, one path per line); check the path");
  std::vector<std::string> images;
  const std::filesystem::path base = std::filesystem::path(list).parent_path();
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::filesystem::path p = line.substr(first);
    images.push_back((p.is_absolute() ? p : base / p).string());
  }
  return images;
}

// The fields of a batch.json row that come from the image's report.json.
void fill_row_from_report(nlohmann::json& row, const nlohmann::json& rep) {
  row["status"] = "ok";
  row["volume_mm3"] = rep.value("volume_mm3", nlohmann::json());
  row["compute_seconds"] = rep["compute_seconds"];
  row["load_seconds"] = rep["stage_seconds"]["load"];
  row["self_intersections"] = rep["self_intersections"];
  row["init_used"] = rep.value("init_used", std::string());
  row["suspect"] = rep["suspect"];
  row["reason"] = rep["reason"];
  nlohmann::json volumes = nlohmann::json::object();
  for (const nlohmann::json& s : rep["structures"])
    volumes[std::to_string(s["value"].get<int>())] = {
        {"name", s["name"]}, {"volume_mm3", s["volume_mm3"]}, {"suspect", s["suspect"]}};
  row["structures"] = volumes;
  if (rep.contains("registration"))
    row["registration"] = rep["registration"].value("accepted", false) ? "accepted" : "rejected";
}

// One image of a batch: its row of batch.json. With `resume`, an earlier complete result
// made from the same image, model and options is kept ("resumed": true). The image's own
// failures are recorded in the row, not thrown: the batch goes on.
nlohmann::json batch_row(const std::string& image, const std::string& output, const SegmentModel& model,
                         const std::string& model_path, const SegmentOptions& options, bool resume,
                         const ProgressFn& progress) {
  const auto t_case = std::chrono::steady_clock::now();
  nlohmann::json row = {{"image", image}, {"output", output}, {"resumed", false}};
  const auto failed = [&](const std::string& error, ExitCode code) {
    row["status"] = "failed";
    row["error"] = error;
    row["exit_code"] = static_cast<int>(code);
  };
  try {
    SegmentCase c;
    c.image = image;
    c.output = output;
    nlohmann::json earlier;
    if (resume) {
      c.fingerprint = case_fingerprint(image, "", model, options);
      earlier = reusable_result(output, model, *c.fingerprint);
    }
    if (!earlier.is_null()) {
      fill_row_from_report(row, earlier);
      row["resumed"] = true;
    } else {
      fill_row_from_report(row, segment_case(c, model, model_path, options, 0.0, progress).report);
    }
  } catch (const Error& e) {
    failed(message_with_hint(e, "segment-batch"), exit_code_of(e));
  } catch (const std::bad_alloc&) {
    failed("out of memory", ExitCode::failed);
  } catch (const std::exception& e) {  // a bug; the other images may still succeed
    failed(std::string("internal error: ") + e.what(), ExitCode::internal);
  }
  row["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_case).count();
  return row;
}

}  // namespace

void add_segment_batch_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "segment-batch",
      "Segment many volumes with one shape model, read once: a folder per image and a summary (batch.json, batch.csv)");
  struct Args {
    std::vector<std::string> images;
    std::string model, output, list;
    SnakeArgs snake;
    int jobs = 1;
    bool json = false, resume = false;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("images", a->images, "Volumes to segment (.nii.gz .nrrd .mha ..., or DICOM folders)");
  cmd->add_option("--list", a->list,
                  "A text file of volumes to segment, one path per line (# comments; relative to the file)");
  cmd->add_option("--model", a->model, "Shape model folder (made by 'mrsnake build-model')")->required();
  cmd->add_option("-o,--output", a->output,
                  "Output folder: DIR/NAME/ per image (as 'mrsnake segment' writes it), DIR/batch.json, DIR/batch.csv")
      ->required();
  a->snake.add_to(cmd);
  cmd->add_option("--jobs", a->jobs,
                  "Images segmented at once, each in a worker process of its own (default 1; the cores: " +
                      std::to_string(std::max(1u, std::thread::hardware_concurrency())) + ")")
      ->check(CLI::Range(1, 256));
  cmd->add_flag("--resume", a->resume,
                "Keep each earlier result in DIR that is complete and was made from the same image, model and "
                "options (by content, as report.json's fingerprint records them); segment the others");
  cmd->add_flag("--json", a->json, "Print the summary (batch.json) on stdout");
  cmd->footer(
      "Example:\n"
      "  mrsnake segment-batch --model heart.model -o study/seg study/mouse*/ct.nii.gz\n"
      "Each image gets DIR/NAME/ (NAME: its file name without extensions, with its parent folder's name in\n"
      "front when two images share a name), written as 'mrsnake segment' writes it. A failing image does\n"
      "not stop the batch: batch.json and batch.csv (rewritten after every image) give each image's status,\n"
      "error, segmented volume (mm3), times, self-intersections and initialization. Exit code 6 when some failed.");
  cmd->callback([a] {
    std::vector<std::string> images = a->images;
    if (!a->list.empty()) {
      const std::vector<std::string> listed = read_image_list(a->list);
      images.insert(images.end(), listed.begin(), listed.end());
    }
    if (images.empty()) throw CLI::ValidationError("images", "give the volumes to segment, or --list FILE");
    const SegmentOptions options = a->snake.options();
    const SegmentModel model = load_segment_model(a->model);
    const double model_seconds = model.load_seconds;
    ensure_writable_directory(a->output);
    const std::filesystem::path dir(a->output);
    std::vector<std::string> outputs;
    for (const std::string& name : case_names(images)) outputs.push_back((dir / name).string());
    const auto t_batch = std::chrono::steady_clock::now();

    std::vector<nlohmann::json> rows(images.size());
    int finished = 0, failed = 0;
    nlohmann::json summary;
    // Each finished image: a line on the terminal, and the summary rewritten (an interrupted
    // batch leaves the record of what it did).
    const auto done = [&](std::size_t i, nlohmann::json row) {
      ++finished;
      const std::string position = "[" + std::to_string(finished) + "/" + std::to_string(images.size()) + "] ";
      const std::string name = std::filesystem::path(outputs[i]).filename().string();
      if (row["status"] == "ok") {
        char line[200];
        std::snprintf(line, sizeof line, "%s%s: %s%.3f s of compute, %zu structure%s", position.c_str(), name.c_str(),
                      row["resumed"].get<bool>() ? "kept from an earlier run, " : "",
                      row["compute_seconds"].get<double>(), row["structures"].size(),
                      row["structures"].size() == 1 ? "" : "s");
        std::string text = line;
        if (row["volume_mm3"].is_number()) {
          std::snprintf(line, sizeof line, ", volume %.1f mm3", row["volume_mm3"].get<double>());
          text += line;
        }
        if (row["suspect"].get<bool>()) text += "; doubtful: " + row["reason"].get<std::string>();
        info(text);
      } else {
        ++failed;
        warn(position + name + " failed: " + row["error"].get<std::string>());
      }
      rows[i] = std::move(row);
      summary = {{"model", a->model},
                 {"model_load_seconds", model_seconds},
                 {"jobs", a->jobs},
                 {"cases", nlohmann::json::array()}};
      for (const nlohmann::json& r : rows)
        if (!r.is_null()) summary["cases"].push_back(r);
      summary["succeeded"] = finished - failed;
      summary["failed"] = failed;
      int resumed = 0;
      for (const nlohmann::json& r : summary["cases"]) resumed += r.value("resumed", false) ? 1 : 0;
      summary["resumed"] = resumed;
      summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_batch).count();
      write_text_file_atomically((dir / "batch.json").string(), json_text(summary, 2) + "\n");
      write_text_file_atomically((dir / "batch.csv").string(), batch_csv(summary["cases"]));
    };
    if (a->jobs > 1 && images.size() > 1) {
      const auto row = [&](std::size_t i) {
        return batch_row(images[i], outputs[i], model, a->model, options, a->resume, {});
      };
      run_batch_in_processes(a->jobs, images, outputs, row, done);
    } else {
      for (std::size_t i = 0; i < images.size(); ++i)
        done(i, batch_row(images[i], outputs[i], model, a->model, options, a->resume, terminal_progress()));
    }
    if (a->json) print_json(summary);
    std::vector<double> compute;
    for (const nlohmann::json& r : rows)
      if (r.contains("compute_seconds")) compute.push_back(r["compute_seconds"].get<double>());
    std::string line = "segmented " + std::to_string(finished - failed) + " of " + std::to_string(images.size()) +
                       " images in " + std::to_string(summary["seconds"].get<double>()) + " s";
    if (!compute.empty()) {
      std::nth_element(compute.begin(), compute.begin() + static_cast<long>(compute.size() / 2), compute.end());
      line += " (median compute " + std::to_string(compute[compute.size() / 2]) + " s)";
    }
    info(line + "; summary in " + (dir / "batch.csv").string());
    if (failed > 0)
      throw PartialFailure(std::to_string(failed) + " of " + std::to_string(images.size()) +
                           " images failed; each is listed with its error in " + (dir / "batch.json").string());
  });
}

}  // namespace mrsnake::cli
