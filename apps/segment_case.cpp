#include "apps/segment_case.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>

#include "apps/cli.h"
#include "apps/report/segment_page.h"
#include "evaluation/evaluate.h"
#include "mesh/atomic_file.h"
#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/json_text.h"
#include "mesh/marching_cubes.h"
#include "mesh/mesh_io.h"
#include "mesh/parallel.h"
#include "model/label_files.h"
#include "model/model_set.h"
#include "model/snake_adapter.h"
#include "snake/label_map.h"
#include "snake/quality_control.h"

namespace fs = std::filesystem;

namespace mrsnake::cli {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

bool one_structure(const SegmentModel& model) { return model.structures.size() == 1; }

// The names segment writes into its folder: only an earlier result of it may be replaced.
ReplaceableFolder segment_folder() {
  return folder_of_entries(
      [](const std::string& name) {
        return name == "surface.vtp" || name == "labels.nii.gz" || name == "labels.seg.nrrd" ||
               name == "labels.itksnap.txt" || name == "labels.ctbl" || name == "levels" || name == "surfaces" ||
               name == "report.json" || name == "report.html" || name == "slices.png" ||
               name == ".snakemake_timestamp";  // the study workflow's mark on the folder
      },
      "an output of mrsnake segment");
}

// The image and the optional truth, and the seconds they took.
struct CaseInputs {
  Volume image, truth;
  double seconds = 0;
  bool truth_holds(int value) const {
    return std::find(truth.data.begin(), truth.data.end(), static_cast<float>(value)) != truth.data.end();
  }
};

CaseInputs read_inputs(const SegmentCase& c) {
  const auto t = std::chrono::steady_clock::now();
  CaseInputs in;
  in.image = read_volume(c.image, c.series);
  if (!c.truth.empty()) {
    in.truth = read_volume(c.truth);
    require_same_grid(in.image, in.truth, "IMAGE", "TRUTH");
  }
  in.seconds = seconds_since(t);
  return in;
}

// One structure; if its initialization finds nothing to align to (an image of something
// else), it is deformed from the model's own pose and its verdict says why, so that one
// structure cannot stop the others.
SegmentResult segment_or_flag(const SegmentationImage& image, const SnakeModel& structure, const SegmentOptions& o,
                              const ProgressFn& progress, const ReferenceRegistration* registration) {
  try {
    return segment(image, structure, o, progress, registration);
  } catch (const AlgorithmError& e) {
    SegmentOptions at_pose = o;
    at_pose.init = InitMode::pose;
    SegmentResult result = segment(image, structure, at_pose, progress);
    result.registration = registration ? std::optional<ReferenceRegistration>(*registration) : std::nullopt;
    result.initialization_failure = e.what();
    return result;
  }
}

// Every structure deformed on the image prepared once, from one shared registration.
std::vector<SegmentResult> segment_structures(const Volume& image, const SegmentModel& model,
                                              const SegmentOptions& options, const ProgressFn& progress,
                                              nlohmann::json& shared_seconds) {
  SegmentOptions o = options;
  o.count_self_intersections = false;  // counted below, beside the label map
  const SegmentationImage prepared = prepare_segmentation_image(image, o, progress);
  for (const auto& [name, s] : prepared.stage_seconds) shared_seconds[name] = s;
  const auto t = std::chrono::steady_clock::now();
  const std::optional<ReferenceRegistration> registration =
      register_structures(prepared, model.structures[model.registering], o, progress);
  if (registration) shared_seconds["register"] = seconds_since(t);
  std::vector<SegmentResult> results;
  for (std::size_t i = 0; i < model.structures.size(); ++i) {
    if (!one_structure(model)) report(progress, model.labels[i].name, static_cast<double>(i) / model.structures.size());
    results.push_back(segment_or_flag(prepared, model.structures[i], o, one_structure(model) ? progress : ProgressFn{},
                                      registration ? &*registration : nullptr));
  }
  if (registration && !registration->accepted)
    warn("the reference image registration was not used (" + registration->rejection + "); initialized with " +
         to_string(results.front().init) + " instead");
  return results;
}

// The label map of every structure and each final surface's self-intersections, side by side.
StructureLabelMap label_map_and_counts(const Volume& image, const SegmentModel& model,
                                       std::vector<SegmentResult>& results, nlohmann::json& shared_seconds) {
  std::vector<TriMesh> surfaces;
  for (const SegmentResult& r : results) surfaces.push_back(r.surface);
  StructureLabelMap map;
  double map_seconds = 0, count_seconds = 0;
  run_both_in_parallel(
      [&] {
        const auto t = std::chrono::steady_clock::now();
        map = structure_label_map(surfaces, model.values, image);
        map_seconds = seconds_since(t);
      },
      [&] {
        const auto t = std::chrono::steady_clock::now();
        for (SegmentResult& r : results) r.self_intersections = count_self_intersections(r.surface);
        count_seconds = seconds_since(t);
      });
  shared_seconds["rasterize"] = map_seconds;
  shared_seconds["self_intersections"] = count_seconds;
  return map;
}

// One structure's part of report.json: its run, its volume as the label map holds it, the
// verdict, and its scores against the truth.
nlohmann::json structure_report(const SegmentCase& c, const CaseInputs& in, const SegmentModel& model, std::size_t i,
                                const SegmentResult& result, const StructureLabelMap& map) {
  nlohmann::json rep = segment_report(result);
  const double voxel_mm3 = in.image.spacing[0] * in.image.spacing[1] * in.image.spacing[2];
  const int value = model.values[i];
  rep["value"] = value;
  rep["name"] = model.labels[i].name;
  rep["color"] = model.labels[i].color;
  rep["volume_mm3"] = static_cast<double>(map.voxels[i]) * voxel_mm3;
  rep["contested_voxels"] = map.contested[i];
  const SnakeModel& m = model.structures[i];
  const int L = m.finest_level();
  rep["model_volume_mm3"] = enclosed_volume(TriMesh{m.levels[L], m.faces(L)});
  const QualityControl qc = assess_segmentation(result, m, rep["volume_mm3"].get<double>());
  rep["quality_control"] = qc;
  rep["volume_ratio_to_model"] = qc.volume_ratio;
  rep["suspect"] = qc.suspect;
  rep["reason"] = qc.reason;
  if (!c.truth.empty()) {
    // The structure's own value; a truth without it, of one structure, is 1 inside (as synth writes it).
    const int truth_label = c.truth_label >= 0                               ? c.truth_label
                            : !one_structure(model) || in.truth_holds(value) ? value
                                                                             : 1;
    nlohmann::json scores;
    try {
      to_json(scores, evaluate_segmentation(map.labels, in.truth, value, truth_label));
    } catch (const InputError& e) {  // the truth lacks this structure: the others are still scored
      scores = {{"error", e.what()}};
    }
    rep["scores"] = scores;
    rep["truth_label"] = truth_label;
  }
  return rep;
}

// report.json: the run's shared part, every structure, and the verdict over all of them.
// A model of one structure also keeps that structure's keys at the top, as before.
nlohmann::json case_report(const SegmentCase& c, const SegmentModel& model, const std::string& model_path,
                           const SegmentOptions& options, const std::vector<nlohmann::json>& structures,
                           const nlohmann::json& shared_seconds, double compute_seconds,
                           const CaseFingerprint& fingerprint) {
  nlohmann::json rep = one_structure(model) ? structures[0] : nlohmann::json::object();
  rep["image"] = c.image;
  rep["model"] = model_path;
  rep["fingerprint"] = fingerprint;
  rep["init"] = to_string(options.init);
  rep["options"] = options;  // as given: what --config reads
  if (!c.truth.empty()) rep["truth"] = c.truth;
  if (structures[0].contains("registration")) rep["registration"] = structures[0]["registration"];
  rep["init_used"] = structures[model.registering]["init_used"];  // the route of the shared registration
  rep["compute_seconds"] = compute_seconds;
  nlohmann::json stages = one_structure(model) ? structures[0]["stage_seconds"] : nlohmann::json::object();
  for (const auto& [name, s] : shared_seconds.items()) stages[name] = s;
  rep["stage_seconds"] = stages;
  rep["structures"] = structures;
  int self_intersections = 0;
  for (const nlohmann::json& st : structures) self_intersections += st["self_intersections"].get<int>();
  rep["self_intersections"] = self_intersections;  // over every structure
  std::string reason;
  bool suspect = false;
  for (const nlohmann::json& s : structures) {
    if (!s["suspect"].get<bool>()) continue;
    suspect = true;
    const std::string own = s["reason"].get<std::string>();
    reason += (reason.empty() ? "" : "; ") +
              (one_structure(model)
                   ? own
                   : s["name"].get<std::string>() + " (" + std::to_string(s["value"].get<int>()) + "): " + own);
  }
  rep["suspect"] = suspect;
  rep["reason"] = reason;
  return rep;
}

// report.html and slices.png: slices with every structure's contour, a render, convergence, the tables.
void write_pages(const fs::path& dir, const SegmentCase& c, const CaseInputs& in, const SegmentModel& model,
                 const std::vector<SegmentResult>& results, const nlohmann::json& rep) {
  reports::SegmentPageInput page;
  page.title = "mrsnake segment " + fs::path(c.image).filename().string();
  page.image = &in.image;
  for (std::size_t i = 0; i < results.size(); ++i)
    page.structures.push_back({&results[i].surface, model.labels[i].name, model.values[i], model.labels[i].color});
  page.surface = &results[0].surface;
  if (!c.truth.empty()) {
    page.truth = &in.truth;
    page.truth_label = static_cast<float>(rep["structures"][0]["truth_label"].get<int>());
  }
  for (const LevelOutcome& l : results[0].levels) {
    reports::SnakeConvergence conv;
    conv.level = l.level;
    conv.deformed = l.deformed;
    for (const auto& it : l.snake.history) {
      conv.energy.push_back(it.energy);
      conv.external_energy.push_back(it.external_energy);
      conv.internal_energy.push_back(it.internal_energy);
      conv.mean_abs_offset_mm.push_back(it.mean_abs_offset_mm);
    }
    page.convergence.push_back(std::move(conv));
  }
  if (!one_structure(model)) page.convergence_of = model.labels[0].name + " (" + std::to_string(model.values[0]) + ")";
  page.report = rep;
  reports::write_segment_report((dir / "report.html").string(), page);
  try {
    const std::vector<std::uint8_t> png = reports::slices_png(page);
    write_text_file_atomically((dir / "slices.png").string(), std::string(png.begin(), png.end()));
  } catch (const std::exception& e) {  // a picture for people: its failure does not fail the segmentation
    warn(std::string("slices.png was not written: ") + e.what());
  }
}

// The meshes and report.json into `dir`.
void write_meshes(const fs::path& dir, const SegmentModel& model, const std::vector<SegmentResult>& results,
                  const nlohmann::json& rep) {
  fs::create_directories(dir / "surfaces");
  for (std::size_t i = 0; i < results.size(); ++i)
    write_mesh((dir / "surfaces" / (std::to_string(model.values[i]) + ".vtp")).string(), results[i].surface);
  if (one_structure(model)) {
    fs::create_directories(dir / "levels");
    write_mesh((dir / "surface.vtp").string(), results[0].surface);
    for (const LevelOutcome& l : results[0].levels)
      write_mesh((dir / "levels" / ("level_" + std::to_string(l.level) + ".vtp")).string(), l.surface);
  }
  write_text_file_atomically((dir / "report.json").string(), json_text(rep, 2) + "\n");
}

// The label map with its names and colours: labels.nii.gz, and for 3D Slicer and ITK-SNAP a
// segmentation of named segments (labels.seg.nrrd), a colour table and a label description.
void write_label_files(const fs::path& dir, const SegmentModel& model, const Volume& labels) {
  std::vector<NamedValue> named;
  for (std::size_t i = 0; i < model.values.size(); ++i) named.push_back({model.values[i], model.labels[i]});
  write_named_label_map(dir.string(), "labels", labels, named, label_voxel_type(model));
}

// Everything goes to a temporary folder renamed into place at the end.
void write_outputs(const SegmentCase& c, const CaseInputs& in, const SegmentModel& model,
                   const std::vector<SegmentResult>& results, const StructureLabelMap& map, const nlohmann::json& rep,
                   const ProgressFn& progress) {
  report(progress, "write", 0.0);
  AtomicDirectory out(c.output, segment_folder());
  const fs::path dir = out.temp_path();
  // The compressed labels are written on the other core, beside the meshes.
  run_both_in_parallel([&] { write_meshes(dir, model, results, rep); },
                       [&] { write_label_files(dir, model, map.labels); });
  // After the join: the page's render forks a child, which must not start while another
  // thread may hold a lock (the allocator's, the loader's) that the child would then wait on.
  write_pages(dir, c, in, model, results, rep);
  out.commit();
  report(progress, "done", 1.0);
}

}  // namespace

SegmentModel load_segment_model(const std::string& path) {
  const auto t = std::chrono::steady_clock::now();
  const ModelSet set = load_model_set(path);
  SegmentModel model;
  model.structures = snake_models_from(set);
  double largest = -1;
  for (std::size_t i = 0; i < set.structures.size(); ++i) {
    model.values.push_back(set.structures[i].value);
    model.labels.push_back(set.structures[i].label);
    const SnakeModel& m = model.structures[i];
    const double volume = enclosed_volume(TriMesh{m.levels.back(), m.faces(m.finest_level())});
    if (volume > largest) {
      largest = volume;
      model.registering = i;
    }
  }
  model.fingerprint = model_fingerprint(path);
  model.load_seconds = seconds_since(t);
  return model;
}

VoxelType label_voxel_type(const SegmentModel& model) {
  return *std::max_element(model.values.begin(), model.values.end()) > 255 ? VoxelType::int16 : VoxelType::uint8;
}

CaseFingerprint case_fingerprint(const std::string& image, const std::string& series, const SegmentModel& model,
                                 const SegmentOptions& options) {
  return {image_fingerprint(image, series), model.fingerprint, options_fingerprint(options), MRSNAKE_VERSION};
}

nlohmann::json reusable_result(const std::string& output, const SegmentModel& model, const CaseFingerprint& expected) {
  const fs::path dir(output);
  std::vector<fs::path> files{"labels.nii.gz", "labels.seg.nrrd", "labels.itksnap.txt", "labels.ctbl",
                              "report.json",   "report.html",     "slices.png"};
  for (const int value : model.values) files.push_back(fs::path("surfaces") / (std::to_string(value) + ".vtp"));
  if (one_structure(model)) files.push_back("surface.vtp");
  std::error_code ec;
  for (const fs::path& f : files)
    if (!fs::is_regular_file(dir / f, ec)) return nullptr;
  nlohmann::json rep;
  try {
    std::ifstream in(dir / "report.json");
    rep = nlohmann::json::parse(in);
  } catch (const std::exception&) {  // unreadable or cut short: made again
    return nullptr;
  }
  if (!rep.is_object() || !(fingerprint_from_json(rep.value("fingerprint", nlohmann::json())) == expected))
    return nullptr;
  return rep;
}

SegmentCaseOutcome segment_case(const SegmentCase& c, const SegmentModel& model, const std::string& model_path,
                                const SegmentOptions& options, double model_load_seconds, const ProgressFn& progress) {
  // Checked before the work too: an output named after a DICOM input folder would be that folder.
  require_replaceable(c.output, segment_folder());
  report(progress, "load", 0.0);
  const CaseInputs in = read_inputs(c);
  const auto t_compute = std::chrono::steady_clock::now();
  nlohmann::json shared_seconds = {{"load", model_load_seconds + in.seconds}};
  SegmentCaseOutcome outcome;
  outcome.results = segment_structures(in.image, model, options, progress, shared_seconds);
  const double compute_seconds = seconds_since(t_compute);
  report(progress, "rasterize", 0.0);
  StructureLabelMap map = label_map_and_counts(in.image, model, outcome.results, shared_seconds);
  std::vector<nlohmann::json> structures;
  for (std::size_t i = 0; i < model.structures.size(); ++i)
    structures.push_back(structure_report(c, in, model, i, outcome.results[i], map));
  outcome.report = case_report(c, model, model_path, options, structures, shared_seconds, compute_seconds,
                               c.fingerprint ? *c.fingerprint : case_fingerprint(c.image, c.series, model, options));
  if (outcome.report["suspect"].get<bool>())
    warn("the result is doubtful: " + outcome.report["reason"].get<std::string>());
  write_outputs(c, in, model, outcome.results, map, outcome.report, progress);
  outcome.labels = std::move(map.labels);
  return outcome;
}

}  // namespace mrsnake::cli
