// mrsnake synth: synthetic volumes with an exactly known truth (see phantoms/synth.h).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "apps/cli.h"
#include "model/label_files.h"
#include "mesh/atomic_file.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/json_text.h"
#include "mesh/label_repair.h"
#include "mesh/mesh_io.h"
#include "mesh/topology.h"
#include "phantoms/synth.h"

namespace mrsnake::cli {
namespace {

/// "64" or "64,64,48" (and the like for doubles): one value for all axes, or three.
template <class T>
std::array<T, 3> parse_triple(const std::string& text, const std::string& option) {
  std::vector<T> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::istringstream is(item);
    T v{};
    if (!(is >> v) || !(is >> std::ws).eof())
      throw CLI::ValidationError(option, "'" + text + "' is not 1 or 3 comma-separated numbers");
    values.push_back(v);
  }
  if (values.size() == 1) return {values[0], values[0], values[0]};
  if (values.size() == 3) return {values[0], values[1], values[2]};
  throw CLI::ValidationError(option, "'" + text + "' needs 1 or 3 comma-separated numbers");
}

nlohmann::json read_json_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("parameter file '" + path + "' does not exist or cannot be read; check the path");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError("parameter file '" + path + "' is not valid JSON (" + e.what() + ")");
  }
}

Volume label_mask(const Volume& labels, int label) {
  Volume mask = labels;
  for (float& v : mask.data) v = std::lround(v) == label ? 1.0f : 0.0f;
  return mask;
}

}  // namespace

void add_synth_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "synth", "Write a synthetic volume with an exactly known truth: image, label, surface and parameters");
  struct Args {
    std::string out, shape = "sphere", size = "64", spacing = "1", noise = "gaussian", contrast = "200,50",
                     pose = "none";
    std::string from_image, from_labels, params;
    double snr = 10, blur = 0.5, bias = 0, deform = 0;
    int label = 1, supersampling = 4, component = 0;
    std::uint64_t seed = 1;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("-o,--output", a->out,
                  "Output folder: image.nii.gz, truth.nii.gz (named in truth.seg.nrrd, truth.ctbl, truth.itksnap.txt), "
                  "truth.vtp, params.json")
      ->required();
  cmd->add_option(
         "--shape", a->shape,
         "sphere, ellipsoid, blob (random star-shaped), aneurysm (vessel with a sac), heart (cavity in a thick wall)")
      ->check(CLI::IsMember({"sphere", "ellipsoid", "blob", "aneurysm", "heart"}))
      ->capture_default_str();
  cmd->add_option("--size", a->size, "Voxels: N or NX,NY,NZ")->capture_default_str();
  cmd->add_option("--spacing", a->spacing, "Voxel size in mm: S or SX,SY,SZ")->capture_default_str();
  cmd->add_option("--noise", a->noise, "none, gaussian or rician (magnitude of complex Gaussian noise)")
      ->check(CLI::IsMember({"none", "gaussian", "rician"}))
      ->capture_default_str();
  cmd->add_option("--snr", a->snr, "|foreground - background| / noise sigma; <= 0 for no noise")->capture_default_str();
  cmd->add_option("--blur", a->blur, "Gaussian blur sigma in mm (0: none)")->capture_default_str();
  cmd->add_option("--bias", a->bias, "Strength B of a smooth multiplicative bias field within [e^-B, e^B] (0: none)")
      ->capture_default_str();
  cmd->add_option("--contrast", a->contrast, "Foreground,background intensities")->capture_default_str();
  cmd->add_option("--pose", a->pose,
                  "random: a random similarity (rotation <= 15 deg, shift <= 5% of the field of view, scale 0.9-1.1)")
      ->check(CLI::IsMember({"none", "random"}))
      ->capture_default_str();
  cmd->add_option("--deform", a->deform, "Largest displacement in mm of a random smooth deformation (0: none)")
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "Random seed: the same seed gives the same case")->capture_default_str();
  cmd->add_option("--supersampling", a->supersampling, "Partial volume: N^3 samples per boundary voxel")
      ->capture_default_str();
  auto* from_image = cmd->add_option("--from-image", a->from_image,
                                     "Warp this real image instead of rendering a shape (adds no noise or blur unless "
                                     "--noise, --snr or --blur is given)");
  auto* from_labels = cmd->add_option("--from-labels", a->from_labels, "The label volume of --from-image");
  cmd->add_option("--label", a->label, "The label of --from-labels that becomes the truth")->capture_default_str();
  auto* component =
      cmd->add_option("--component", a->component,
                      "Only the label's K-th largest connected part becomes the truth (1 = the largest; as "
                      "'build-model --component'); 0 = all of it")
          ->check(CLI::Range(0, 1000))
          ->capture_default_str();
  component->needs(from_labels);
  auto* params = cmd->add_option("--params", a->params, "Regenerate the case recorded in this params.json");
  from_image->needs(from_labels);
  from_labels->needs(from_image);
  params->excludes(from_image)->excludes(from_labels);
  cmd->add_flag("--json", a->json, "Print a JSON summary");
  cmd->footer(
      "Examples:\n"
      "  mrsnake synth --shape blob --size 96 --spacing 1,1,1.5 --noise rician --snr 5 --pose random --deform 3 --seed "
      "7 -o case7\n"
      "  mrsnake synth --from-image ct.nii.gz --from-labels seg.nii.gz --label 5 --deform 4 -o liver-warped\n"
      "  mrsnake synth --params case7/params.json -o case7-again");
  cmd->callback([cmd, a] {
    SynthParams params;
    Volume source_image, source_labels;
    // The label volume as the truth sees it: with --component, the other parts are background.
    const auto read_source_labels = [](const SynthOptions& o) {
      Volume labels = read_volume(o.source_labels);
      return o.source_component > 0 ? keep_label_part(labels, o.source_label, o.source_component) : labels;
    };
    if (!a->params.empty()) {
      for (const char* option : {"--shape", "--size", "--spacing", "--noise", "--snr", "--blur", "--bias", "--contrast",
                                 "--pose", "--deform", "--seed", "--supersampling", "--label", "--component"})
        if (cmd->count(option) > 0)
          throw CLI::ValidationError(option, "--params regenerates the recorded case as it was; drop " +
                                                 std::string(option) + " or drop --params");
      params = synth_params_from_json(read_json_file(a->params));
    } else {
      SynthOptions o;
      o.shape = parse_synth_shape(a->shape);
      o.noise = parse_synth_noise(a->noise);
      o.snr = a->snr;
      o.blur_mm = a->blur;
      o.bias = a->bias;
      o.random_pose = a->pose == "random";
      o.deform_mm = a->deform;
      o.seed = a->seed;
      o.supersampling = a->supersampling;
      if (a->from_image.empty()) {
        o.size = parse_triple<int>(a->size, "--size");
        o.spacing = parse_triple<double>(a->spacing, "--spacing");
        std::vector<double> fb;
        bool numbers = true;
        std::stringstream ss(a->contrast);
        for (std::string item; std::getline(ss, item, ',');) {
          std::istringstream is(item);
          double v = 0;
          numbers = numbers && (is >> v) && (is >> std::ws).eof();
          fb.push_back(v);
        }
        if (!numbers || fb.size() != 2)
          throw CLI::ValidationError("--contrast", "give two intensities: FOREGROUND,BACKGROUND, e.g. 200,50");
        o.foreground = fb[0];
        o.background = fb[1];
      } else {
        for (const char* option : {"--shape", "--size", "--spacing", "--contrast", "--supersampling"})
          if (cmd->count(option) > 0)
            throw CLI::ValidationError(
                option, std::string(option) +
                            " does not apply to --from-image, which keeps the grid and intensities of the image");
        // A real image already has its noise and blur: add none unless asked.
        if (cmd->count("--noise") == 0 && cmd->count("--snr") == 0) o.noise = SynthNoise::none;
        if (cmd->count("--blur") == 0) o.blur_mm = 0;
        o.source_image = std::filesystem::absolute(a->from_image).string();
        o.source_labels = std::filesystem::absolute(a->from_labels).string();
        o.source_label = a->label;
        o.source_component = a->component;
        source_image = read_volume(a->from_image);
        source_labels = read_source_labels(o);
        const Volume mask = label_mask(source_labels, a->label);
        params = draw_synth_params(o, &mask);
      }
      if (!o.from_image()) params = draw_synth_params(o);
    }
    if (params.options.from_image() && source_image.data.empty()) {
      source_image = read_volume(params.options.source_image);
      source_labels = read_source_labels(params.options);
    }
    ensure_writable_directory(a->out);
    const auto progress = terminal_progress();
    const SynthResult r = params.options.from_image() ? render_from_image(params, source_image, source_labels, progress)
                                                      : render_synth(params, progress);
    const std::filesystem::path dir(a->out);
    const std::string image_path = (dir / "image.nii.gz").string(), truth_path = (dir / "truth.nii.gz").string();
    const std::string mesh_path = (dir / "truth.vtp").string(), params_path = (dir / "params.json").string();
    write_volume(image_path, r.image, VoxelType::float32);
    write_named_label_map(dir.string(), "truth", r.truth, numbered_values(r.truth), VoxelType::uint8);
    write_mesh(mesh_path, r.truth_mesh);
    const TopologyReport topology = topology_report(r.truth_mesh);
    if (!topology.is_closed_genus0())
      warn("the truth surface is " + topology.describe() + " (the label has several parts or holes)");
    nlohmann::json pj = params;
    write_text_file_atomically(params_path, json_text(pj, 2) + "\n");

    std::size_t object_voxels = 0;
    for (float v : r.truth.data) object_voxels += v == kTruthLabel;
    const double voxel_mm3 = r.truth.spacing[0] * r.truth.spacing[1] * r.truth.spacing[2];
    nlohmann::json summary = {{"image", image_path},
                              {"truth", truth_path},
                              {"truth_mesh", mesh_path},
                              {"params", params_path},
                              {"label", kTruthLabel},
                              {"size", r.truth.size},
                              {"spacing", r.truth.spacing},
                              {"object_voxels", object_voxels},
                              {"object_volume_mm3", object_voxels * voxel_mm3},
                              {"mesh_vertices", r.truth_mesh.num_vertices()},
                              {"mesh_faces", r.truth_mesh.num_faces()}};
    if (a->json) {
      print_json(summary);
      return;
    }
    std::cout << "image       " << image_path << '\n'
              << "truth       " << truth_path << " (label " << kTruthLabel << ": " << object_voxels << " voxels, "
              << object_voxels * voxel_mm3 << " mm3)\n"
              << "truth mesh  " << mesh_path << " (" << r.truth_mesh.num_vertices() << " vertices, "
              << r.truth_mesh.num_faces() << " faces)\n"
              << "parameters  " << params_path << '\n';
  });
}

}  // namespace mrsnake::cli
