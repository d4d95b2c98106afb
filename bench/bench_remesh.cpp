// bench_remesh: the project's remesher (`mrsnake remesh`, relaxed and --no-relax) against
// CGAL's isotropic_remeshing on the same inputs, at the same face counts, measured in the
// same run: time, peak memory, faces, regularity, triangle quality and distance to the input.
//
//   bench_remesh [--data DIR] [--mrsnake PATH] [--inputs a,b,...] [--targets 16000,32000]
//                [--out DIR] [--samples N] [--iterations N] [--timeout SECONDS] [--repeat N]
//                [--markdown FILE]
//
// mrsnake runs as a subprocess through its command-line contract
//   mrsnake remesh INPUT -o DIR --faces N [--no-relax]  ->  DIR/level_0.vtp ... level_L.vtp, report.json
// (wall time of the whole command and the child's peak RSS from wait4), and the level whose
// face count is nearest N is measured. The speed ratio compares the remeshing alone:
// mrsnake's own time (report.json's "seconds", wall; its parallel loops use the machine's
// threads, at most 8) against CGAL's call (one thread); the ratio to the whole command is
// printed too. Each time is the median of --repeat runs; each of CGAL's runs follows one of mrsnake's
// (relaxed), so that a slow spell of the machine slows both alike. CGAL runs in this process (10 iterations,
// constraints not protected) with a target edge length from the equilateral estimate, corrected once, aimed at the face
// count of mrsnake's measured level (at N if mrsnake has none); its peak RSS is the process's high-water mark during
// the call (reset before it).
//
// Inputs (default: all of them, in this order):
// - meshes DIR/meshes/NAME.off: mushroom, heart, bear, blobby, retinal, armadillo, horse,
//   octopus, human, cheburashka, cactus, helix (closed genus 0), mask, lilium (disks);
// - label-derived (label_inputs() below): liver (liver-labels.nii.gz, label 255), ventricles
//   (MRIcrop-seg.gipl.gz, label 1, the lateral ventricles), mouse-hippocampus, mouse-caudate,
//   mouse-cerebellum (mouse-brain/mouse1_labels.nii.gz, labels 1, 3, 8). The remeshers' input
//   is the surface `mrsnake build-model` uses by default, made with `mrsnake mc`:
//     --spacing S: S = default_marching_cubes_spacing(measure_structure(labels, label))
//       (snake/structure_scale.h, computed here by the same functions on the same voxels:
//       the label's K-th part with --component K, as build-model does): the equivalent
//       radius / 60 when the voxels are finer than that (the liver: about 1.2 mm), the finest
//       voxel side for thick slices, else 0 = the voxels' own surface (the ventricles, the mice);
//     --smooth 5 when S > 0, else 20 (build-model's defaults);
//     --close-tunnels 3 (build-model's default; nothing changes on a genus-0 label),
//     --remove-spurs (build-model's default: the label's voxels hanging by at most one face
//     go, which --smooth would make needles), and
//     --component 1 (the largest part) for the ventricles and the mice.
//   Their distances (RMS, Hausdorff), for mrsnake and CGAL alike, are measured against the
//   label's `mrsnake mc --smooth 20` surface (the voxels' surface, windowed-sinc smoothed; the
//   same --component, --close-tunnels and --remove-spurs), not against the remeshers' input. When S = 0 the
//   two are the same surface.
// - held-out (not a default): the eight genus-0 structures of mice 2, 3 and 4 (labels 1, 3, 5,
//   7, 8, 9, 13, 18 of mouseN_labels.nii.gz, as mouseN-hippocampus ... mouseN-midbrain-rest),
//   made and measured as the mice above. No default of the remesher was chosen on them: they
//   check the targets on shapes it was not tuned on (docs/bench-remesh-held-out.md).
// - any other name with a '/' or '.' is read as a mesh file.
//
// Targets, checked on every mrsnake row (CGAL's rows are the reference of RMS and time):
// valence 6 on >= 99 % of the interior vertices (val6), min angle >= 30 degrees (angle),
// Q min >= 0.6 (Qmin), Q mean >= 0.9 (Qmean), RMS <= CGAL's at the same target (RMS),
// Hausdorff <= 0.5 % of the reference's bounding-box diagonal (Haus), remeshing time
// (algo_s) < CGAL's (time). A row without figures (mrsnake refused the input: non-zero exit)
// misses all of them. --markdown FILE also writes the table as a Markdown page.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/version.h>

#include <fcntl.h>
#include <malloc.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/atomic_file.h"
#include "mesh/distance.h"
#include "mesh/image_io.h"
#include "mesh/label_repair.h"
#include "mesh/mesh_io.h"
#include "mesh/quality.h"
#include "mesh/topology.h"
#include "snake/structure_scale.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using namespace mrsnake;
using Clock = std::chrono::steady_clock;

// ---------------------------------------------------------------------------------------------
// Options

struct Options {
  std::string data;
  std::string mrsnake = MRSNAKE_DEFAULT_BIN;
  std::vector<std::string> inputs = {
      "mushroom",        "heart", "bear",    "blobby",     "retinal",           "liver",
      "armadillo",       "horse", "octopus", "human",      "cheburashka",       "cactus",
      "helix",           "mask",  "lilium",  "ventricles", "mouse-hippocampus", "mouse-caudate",
      "mouse-cerebellum"};
  std::vector<int> targets = {16000, 32000};
  std::string out = "bench-remesh-out";
  int samples = 10;
  int iterations = 10;
  double timeout = 1800;
  int repeat = 3;                 ///< timed runs per method and case; the medians are reported
  std::string markdown;           ///< also write the table as a Markdown page here (empty: no)
  std::string config;             ///< `mrsnake remesh --config` of the mrsnake rows (empty: the defaults)
  std::vector<std::string> argv;  ///< this process's command line, for the Markdown page
};

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  const std::size_t h = values.size() / 2;
  return values.size() % 2 ? values[h] : 0.5 * (values[h - 1] + values[h]);
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> items;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

int parse_count(std::string s) {
  int scale = 1;
  if (!s.empty() && (s.back() == 'k' || s.back() == 'K')) {
    scale = 1000;
    s.pop_back();
  }
  std::size_t used = 0;
  const int value = std::stoi(s, &used);
  if (used != s.size() || value <= 0) throw std::invalid_argument("not a positive count: " + s);
  return value * scale;
}

[[noreturn]] void usage(const std::string& error) {
  if (!error.empty()) std::cerr << "bench_remesh: " << error << "\n";
  std::cerr << "usage: bench_remesh [--data DIR] [--mrsnake PATH] [--inputs mushroom,heart,...,mouse-cerebellum]\n"
               "                    [--targets 16000,32000] [--out DIR] [--samples N] [--iterations N]\n"
               "                    [--timeout SECONDS] [--repeat N] [--markdown FILE]\n"
               "  --data DIR        shared data folder (default $MRSNAKE_DATA, else ../shared/data)\n"
               "  --mrsnake PATH    the mrsnake binary (default: the one built beside this benchmark)\n"
               "  --inputs LIST     names under DIR/meshes (.off); liver, ventricles, mouse-hippocampus,\n"
               "                    mouse-caudate, mouse-cerebellum (labels, through mrsnake mc); held-out\n"
               "                    (mice 2-4's eight genus-0 structures, mouse2-hippocampus ...); or mesh paths\n"
               "                    (default: the 14 meshes and the 5 labels)\n"
               "  --targets LIST    face counts to aim at (16k accepted)\n"
               "  --out DIR         working folder; bench_remesh.json is written there\n"
               "  --samples N       random points per face for the surface distance (default 10)\n"
               "  --iterations N    CGAL isotropic_remeshing iterations (default 10)\n"
               "  --timeout S       per mrsnake run (default 1800)\n"
               "  --repeat N        timed runs of each method per case, CGAL's alternating with mrsnake's;\n"
               "                    medians are reported (default 3)\n"
               "  --markdown FILE   also write the table as a Markdown page (commit, machine, command)\n"
               "  --config FILE     options of the mrsnake rows (mrsnake remesh --config; default: none)\n";
  std::exit(error.empty() ? 0 : 2);
}

Options parse_options(int argc, char** argv) {
  Options o;
  o.argv.assign(argv, argv + argc);
  if (const char* env = std::getenv("MRSNAKE_DATA"); env && *env)
    o.data = env;
  else
    o.data = "../shared/data";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(arg + " needs a value");
      return argv[++i];
    };
    try {
      if (arg == "--data")
        o.data = value();
      else if (arg == "--mrsnake")
        o.mrsnake = value();
      else if (arg == "--inputs")
        o.inputs = split_list(value());
      else if (arg == "--targets") {
        o.targets.clear();
        for (const auto& t : split_list(value())) o.targets.push_back(parse_count(t));
      } else if (arg == "--out")
        o.out = value();
      else if (arg == "--samples")
        o.samples = std::stoi(value());
      else if (arg == "--iterations")
        o.iterations = std::stoi(value());
      else if (arg == "--timeout")
        o.timeout = std::stod(value());
      else if (arg == "--repeat")
        o.repeat = std::stoi(value());
      else if (arg == "--markdown")
        o.markdown = value();
      else if (arg == "--config")
        o.config = value();
      else if (arg == "-h" || arg == "--help")
        usage("");
      else
        usage("unknown option " + arg);
    } catch (const std::invalid_argument& e) {
      usage(arg + ": " + e.what());
    } catch (const std::out_of_range&) {
      usage(arg + ": value out of range");
    }
  }
  if (o.inputs.empty() || o.targets.empty()) usage("--inputs and --targets need at least one entry");
  if (o.samples < 0 || o.iterations < 1 || o.timeout <= 0 || o.repeat < 1)
    usage("--samples, --iterations, --timeout, --repeat must be positive");
  return o;
}

// ---------------------------------------------------------------------------------------------
// Subprocesses and memory

struct ChildRun {
  int exit_code = -1;  ///< -1 if it did not exit normally (signal, timeout, exec failure)
  bool timed_out = false;
  double seconds = 0;
  double cpu_seconds = 0;  ///< the child's user + system time (wait4)
  double peak_mib = 0;     ///< the child's peak RSS (wait4)
};

double cpu_seconds_of(const struct rusage& u) {
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// User + system time of the calling thread so far.
double thread_cpu_seconds() {
  struct rusage u {};
  getrusage(RUSAGE_THREAD, &u);
  return cpu_seconds_of(u);
}

/// Runs a program with its output going to log_path; waits up to timeout seconds.
ChildRun run_child(const std::vector<std::string>& args, const std::string& log_path, double timeout) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ChildRun r;
  const auto start = Clock::now();
  const pid_t pid = fork();
  if (pid < 0) return r;
  if (pid == 0) {
    const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      ::close(fd);
    }
    execv(argv[0], argv.data());
    std::fprintf(stderr, "cannot run %s\n", argv[0]);
    _exit(127);
  }
  int status = 0;
  struct rusage usage {};
  for (;;) {
    const pid_t done = wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    if (done < 0) return r;
    if (std::chrono::duration<double>(Clock::now() - start).count() > timeout) {
      kill(pid, SIGKILL);
      wait4(pid, &status, 0, &usage);
      r.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.cpu_seconds = cpu_seconds_of(usage);
  r.peak_mib = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
  if (!r.timed_out && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  return r;
}

std::string last_line_of(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

/// Resets this process's peak RSS (VmHWM) to its current RSS; false if the kernel refuses.
bool reset_peak_rss() {
  malloc_trim(0);  // hand freed heap back first, so the baseline is what is really in use
  std::ofstream clear("/proc/self/clear_refs");
  if (!clear) return false;
  clear << "5";
  clear.flush();
  return static_cast<bool>(clear);
}

/// A field of /proc/self/status in MiB (VmHWM = peak RSS, VmRSS = current RSS).
double proc_status_mib(const std::string& field) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1)) / 1024.0;  // kB
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// ---------------------------------------------------------------------------------------------
// CGAL's isotropic remeshing

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

SurfaceMesh to_surface_mesh(const TriMesh& m) {
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> vs;
  vs.reserve(m.num_vertices());
  for (int v = 0; v < m.num_vertices(); ++v) vs.push_back(sm.add_vertex({m.V(v, 0), m.V(v, 1), m.V(v, 2)}));
  for (int f = 0; f < m.num_faces(); ++f)
    if (sm.add_face(vs[m.F(f, 0)], vs[m.F(f, 1)], vs[m.F(f, 2)]) == SurfaceMesh::null_face())
      throw std::runtime_error("face " + std::to_string(f) + " is non-manifold or misoriented for CGAL's Surface_mesh");
  return sm;
}

TriMesh to_trimesh(const SurfaceMesh& sm) {
  TriMesh m;
  m.V.resize(sm.number_of_vertices(), 3);
  std::vector<int> index(sm.num_vertices(), -1);  // num_vertices() counts removed slots too
  int next = 0;
  for (auto v : sm.vertices()) {
    const auto& p = sm.point(v);
    m.V.row(next) << p.x(), p.y(), p.z();
    index[v.idx()] = next++;
  }
  m.F.resize(sm.number_of_faces(), 3);
  int f = 0;
  for (auto face : sm.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(face), sm)) {
      if (k < 3) m.F(f, k) = index[v.idx()];
      ++k;
    }
    if (k != 3) throw std::runtime_error("CGAL returned a non-triangle face");
    ++f;
  }
  return m;
}

double total_area(const TriMesh& m) {
  double a = 0;
  for (int f = 0; f < m.num_faces(); ++f)
    a += 0.5 * (m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0))).cross(m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0))).norm();
  return a;
}

struct CgalRun {
  TriMesh mesh;
  double seconds = 0;      ///< the isotropic_remeshing call that produced `mesh`
  double cpu_seconds = 0;  ///< its user + system time
  double peak_mib = 0;     ///< process peak RSS during that call
  double rss_before_mib = 0;
  double target_edge_length = 0;
  double probe_edge_length = 0;
  int probe_faces = 0;
  double probe_seconds = 0;
};

CgalRun cgal_remesh_once(const TriMesh& input, double edge_length, int iterations) {
  CgalRun r;
  r.target_edge_length = edge_length;
  const bool reset = reset_peak_rss();
  r.rss_before_mib = proc_status_mib("VmRSS");
  SurfaceMesh sm = to_surface_mesh(input);
  const auto start = Clock::now();
  const double cpu_start = thread_cpu_seconds();
  CGAL::Polygon_mesh_processing::isotropic_remeshing(
      faces(sm), edge_length, sm,
      CGAL::parameters::number_of_iterations(static_cast<unsigned>(iterations)).protect_constraints(false));
  r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.cpu_seconds = thread_cpu_seconds() - cpu_start;
  sm.collect_garbage();
  r.peak_mib = reset ? proc_status_mib("VmHWM") : std::nan("");
  r.mesh = to_trimesh(sm);
  return r;
}

/// CGAL's timed runs, taken one at a time so that they can alternate with mrsnake's: a slow
/// spell of the machine then slows both methods' runs alike, not only one method's.
class CgalTimedRuns {
 public:
  CgalTimedRuns(const TriMesh& input, int iterations) : input_(input), iterations_(iterations) {}

  /// One timed run. The first aims the edge length at `faces` (ignored after it): the
  /// equilateral estimate, F faces of edge e cover F·(√3/4)e², so e = sqrt(4A/(√3·F)), and one
  /// correction by the face count an untimed probe run gave (faces scale as 1/e²). A failure
  /// is kept (error()), not thrown: the runs are taken between mrsnake's, and end there.
  void run_once(int faces) {
    if (!error_.empty()) return;
    try {
      if (runs_ == 0) aim_at(faces);
      const CgalRun again = cgal_remesh_once(input_, edge_length_, iterations_);  // CGAL is deterministic
      if (runs_ == 0) result_ = again;
      seconds_.push_back(again.seconds);
      cpu_seconds_.push_back(again.cpu_seconds);
      result_.peak_mib = std::max(result_.peak_mib, again.peak_mib);
      ++runs_;
    } catch (const std::exception& e) {
      error_ = e.what();
    }
  }

  int runs() const { return runs_; }
  const std::string& error() const { return error_; }  ///< why a run failed; empty if none did

  /// The first run's mesh with the median times and the largest peak memory of all runs.
  /// \pre runs() > 0
  CgalRun result() const {
    CgalRun r = result_;
    r.seconds = median(seconds_);
    r.cpu_seconds = median(cpu_seconds_);
    r.probe_edge_length = probe_.target_edge_length;
    r.probe_faces = probe_.mesh.num_faces();
    r.probe_seconds = probe_.seconds;
    return r;
  }

 private:
  void aim_at(int faces) {
    const double e0 = std::sqrt(4.0 * total_area(input_) / (std::sqrt(3.0) * faces));
    probe_ = cgal_remesh_once(input_, e0, iterations_);
    edge_length_ = e0 * std::sqrt(static_cast<double>(probe_.mesh.num_faces()) / faces);
  }

  const TriMesh& input_;
  int iterations_;
  int runs_ = 0;
  double edge_length_ = 0;
  CgalRun probe_, result_;
  std::vector<double> seconds_, cpu_seconds_;
  std::string error_;
};

// ---------------------------------------------------------------------------------------------
// Label-derived inputs

/// An input made from one label of a label volume (see the opening comment).
struct LabelInput {
  std::string name;
  std::string volume;  ///< under --data
  int label;
  int component;          ///< mc's and build-model's --component: the K-th largest part; 0 = the whole label
  bool held_out = false;  ///< not a default input: no default was chosen on it
};

/// The genus-0 mouse structures of the data README (label, name), each hemisphere's first.
const std::pair<int, const char*> kMouseStructures[] = {
    {1, "hippocampus"},        {3, "caudate"},       {5, "globus-pallidus"}, {7, "thalamus"}, {8, "cerebellum"},
    {9, "superior-colliculi"}, {13, "central-gray"}, {18, "midbrain-rest"}};

/// The benchmark's label inputs, then the held-out ones: mice 2 to 4's eight structures
/// (mouseN-NAME), which no default was chosen on: `--inputs held-out` runs them.
const std::vector<LabelInput>& label_inputs() {
  static const std::vector<LabelInput> inputs = [] {
    std::vector<LabelInput> all = {
        {"liver", "volumes/liver-labels.nii.gz", 255, 0},
        {"ventricles", "volumes/MRIcrop-seg.gipl.gz", 1, 1},
        {"mouse-hippocampus", "volumes/mouse-brain/mouse1_labels.nii.gz", 1, 1},
        {"mouse-caudate", "volumes/mouse-brain/mouse1_labels.nii.gz", 3, 1},
        {"mouse-cerebellum", "volumes/mouse-brain/mouse1_labels.nii.gz", 8, 1},
    };
    for (int mouse = 2; mouse <= 4; ++mouse)
      for (const auto& [label, name] : kMouseStructures)
        all.push_back({"mouse" + std::to_string(mouse) + "-" + name,
                       "volumes/mouse-brain/mouse" + std::to_string(mouse) + "_labels.nii.gz", label, 1, true});
    return all;
  }();
  return inputs;
}

/// `names` with `held-out` replaced by the held-out inputs' names.
std::vector<std::string> with_held_out_expanded(const std::vector<std::string>& names) {
  std::vector<std::string> expanded;
  for (const std::string& name : names) {
    if (name != "held-out")
      expanded.push_back(name);
    else
      for (const LabelInput& in : label_inputs())
        if (in.held_out) expanded.push_back(in.name);
  }
  return expanded;
}

/// build-model's default --close-tunnels (model/build_model.h); a genus-0 label is untouched.
constexpr int kCloseTunnels = 3;

const LabelInput* find_label_input(const std::string& name) {
  for (const LabelInput& in : label_inputs())
    if (name == in.name) return &in;
  return nullptr;
}

std::string format_number(double x) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", x);  // round-trips: mc gets build-model's very spacing
  return text;
}

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string text;
  for (std::size_t i = 0; i < items.size(); ++i) text += (i ? separator : "") + items[i];
  return text;
}

/// Runs `mrsnake -q mc ARGS --json`; returns its JSON summary (mc's warnings come first in
/// the log). \throw std::runtime_error with the log's last line if mc fails.
json run_mc(const Options& o, const std::vector<std::string>& mc_args, const std::string& log) {
  std::vector<std::string> args = {o.mrsnake, "-q", "mc"};
  args.insert(args.end(), mc_args.begin(), mc_args.end());
  args.push_back("--json");
  const ChildRun mc = run_child(args, log, o.timeout);
  if (mc.exit_code != 0) throw std::runtime_error("'mrsnake mc' failed (" + last_line_of(log) + ")");
  std::ifstream in(log);
  std::string line, text;
  bool started = false;
  while (std::getline(in, line)) {
    if (!started && !line.empty() && line[0] == '{') started = true;
    if (started) text += line + "\n";
  }
  json summary = json::object();
  try {
    if (started) summary = json::parse(text);
  } catch (const std::exception&) {
  }
  summary["warnings"] = json::array();
  std::ifstream again(log);
  while (std::getline(again, line) && !(!line.empty() && line[0] == '{'))
    if (!line.empty()) summary["warnings"].push_back(line);
  return summary;
}

struct LabelSurfaces {
  std::string input_path;      ///< build-model's default surface: what the remeshers get
  std::string reference_path;  ///< mc --smooth 20: what the distances are measured against
  json record;                 ///< how both were made (commands, spacing, mc's summaries)
};

/// Both surfaces of one label (the opening comment says which). \throw std::exception.
LabelSurfaces make_label_input(const Options& o, const LabelInput& in) {
  const std::string labels = (fs::path(o.data) / in.volume).string();
  double spacing = 0;
  StructureScale scale;
  {
    // build-model's default spacing, from the same voxels it measures (its --component part).
    const Volume volume =
        in.component > 0 ? keep_label_part(read_volume(labels), in.label, in.component) : read_volume(labels);
    scale = measure_structure(volume, in.label);
    spacing = default_marching_cubes_spacing(scale);
  }
  const int smooth = spacing > 0 ? 5 : 20;  // build-model: 5 on the resampled occupancy, else 20
  std::vector<std::string> label_args = {"--labels", labels, "--label", std::to_string(in.label)};
  if (in.component > 0) label_args.insert(label_args.end(), {"--component", std::to_string(in.component)});
  label_args.insert(label_args.end(), {"--close-tunnels", std::to_string(kCloseTunnels), "--remove-spurs"});

  LabelSurfaces s;
  s.input_path = (fs::path(o.out) / (std::string(in.name) + ".vtp")).string();
  std::vector<std::string> input_args = label_args;
  if (spacing > 0) input_args.insert(input_args.end(), {"--spacing", format_number(spacing)});
  input_args.insert(input_args.end(), {"--smooth", std::to_string(smooth), "-o", s.input_path});
  std::cerr << in.name << ": mrsnake mc " << join(input_args, " ") << "\n";
  const json input_mc = run_mc(o, input_args, (fs::path(o.out) / (std::string(in.name) + "-mc.log")).string());

  std::vector<std::string> reference_args = label_args;
  json reference_mc;
  if (spacing > 0) {
    s.reference_path = (fs::path(o.out) / (std::string(in.name) + "-reference.vtp")).string();
    reference_args.insert(reference_args.end(), {"--smooth", "20", "-o", s.reference_path});
    std::cerr << in.name << ": reference: mrsnake mc " << join(reference_args, " ") << "\n";
    reference_mc = run_mc(o, reference_args, (fs::path(o.out) / (std::string(in.name) + "-mc-reference.log")).string());
  } else {
    s.reference_path = s.input_path;  // build-model's default is then the --smooth 20 voxel surface itself
    reference_args = input_args;
    reference_mc = input_mc;
  }
  json scale_json;
  to_json(scale_json, scale);
  s.record = {{"labels", labels},
              {"label", in.label},
              {"component", in.component},
              {"structure_scale", scale_json},
              {"marching_cubes_spacing_mm", spacing},
              {"smoothing_iterations", smooth},
              {"input_command", "mrsnake mc " + join(input_args, " ")},
              {"input_mc", input_mc},
              {"reference_command", "mrsnake mc " + join(reference_args, " ")},
              {"reference_mc", reference_mc}};
  return s;
}

// ---------------------------------------------------------------------------------------------
// One row of the table

struct Row {
  std::string input, method;
  int target = 0;
  std::string status = "ok";  ///< "ok", or why there are no figures
  int faces = 0, level = -1;
  double seconds = 0, cpu_seconds = 0, peak_mib = 0;
  /// The remeshing alone: report.json's "seconds" for mrsnake (no file reading or writing, no
  /// distance statistics), the isotropic_remeshing call for CGAL. NaN if unknown.
  double algorithm_seconds = std::nan("");
  std::optional<QualityReport> quality;
  std::optional<SurfaceDistance> distance;
  int self_intersections = -1;                ///< pairs of intersecting faces; -1 if not counted
  double speed_ratio = std::nan("");          ///< CGAL's algorithm_seconds / this row's (> 1: faster than CGAL)
  double command_speed_ratio = std::nan("");  ///< CGAL's call / the whole mrsnake command, wall
  double cpu_speed_ratio = std::nan("");      ///< the same with user + system time
  /// The targets this row misses (kTargetNames); unset on CGAL's rows, the reference.
  std::optional<std::vector<std::string>> missed;
  json extra = json::object();
};

/// The targets, as the table names them (the opening comment gives their values).
const std::vector<std::string> kTargetNames = {"val6", "angle", "Qmin", "Qmean", "RMS", "Haus", "time"};

/// The targets an mrsnake row misses; all of them without figures (refused, timed out, ...).
std::vector<std::string> missed_targets(const Row& r, const Row& cgal) {
  if (r.status != "ok" || !r.quality || !r.distance) return kTargetNames;
  const bool cgal_ok = cgal.status == "ok" && cgal.distance.has_value();
  std::vector<std::string> missed;
  const auto check = [&](bool met, const std::string& name) {
    if (!met) missed.push_back(name);
  };
  check(r.quality->pct_valence6_interior >= 99.0, "val6");
  check(r.quality->min_angle_deg >= 30.0, "angle");
  check(r.quality->q_min >= 0.6, "Qmin");
  check(r.quality->q_mean >= 0.9, "Qmean");
  check(cgal_ok && r.distance->rms_pct <= cgal.distance->rms_pct, "RMS");
  check(r.distance->hausdorff_pct <= 0.5, "Haus");
  check(cgal_ok && r.algorithm_seconds < cgal.algorithm_seconds, "time");  // false on NaN: unknown is missed
  return missed;
}

/// "all met", the missed targets ("angle,Qmin"), "-" on CGAL's rows.
std::string targets_text(const Row& r) {
  if (!r.missed) return "-";
  if (r.missed->empty()) return "all met";
  if (r.status != "ok") return "all missed";
  return join(*r.missed, ",");
}

void measure(Row& row, const TriMesh& output, const TriMesh& input, int samples) {
  row.faces = output.num_faces();
  row.quality = mesh_quality(output);
  DistanceOptions options;
  options.samples_per_face = samples;
  row.distance = surface_distance(output, input, options);
  try {
    row.self_intersections = count_self_intersections(output);
  } catch (const std::exception& e) {
    row.extra["self_intersections_error"] = e.what();
  }
}

/// The remesher's own time from report.json: its top-level "seconds", else the sum of the
/// parameterization's and every level's "seconds" (under "per_level" or "levels").
std::optional<double> internal_seconds(const json& report) {
  if (report.contains("seconds") && report["seconds"].is_number()) return report["seconds"].get<double>();
  double total = 0;
  bool found = false;
  if (report.contains("parameterization") && report["parameterization"].is_object() &&
      report["parameterization"].contains("seconds") && report["parameterization"]["seconds"].is_number()) {
    total += report["parameterization"]["seconds"].get<double>();
    found = true;
  }
  for (const char* key : {"per_level", "levels"})
    if (report.contains(key) && report[key].is_array())
      for (const auto& level : report[key])
        if (level.is_object() && level.contains("seconds") && level["seconds"].is_number()) {
          total += level["seconds"].get<double>();
          found = true;
        }
  if (!found) return std::nullopt;
  return total;
}

/// Whether a level of `faces` faces is nearer `target` than the nearest so far (`nearest` < 0:
/// none yet). Levels come coarse to fine, so a tie keeps the coarser one.
bool nearer_target(int faces, int nearest, int target) {
  return nearest < 0 || std::abs(faces - target) < std::abs(nearest - target);
}

/// The face count of report.json's level nearest `target` (the level the row measures), or
/// `target` if the report has no levels.
int nearest_level_faces(const json& report, int target) {
  int nearest = -1;
  if (report.contains("per_level") && report["per_level"].is_array())
    for (const auto& level : report["per_level"]) {
      const int faces = level.value("faces", -1);
      if (faces > 0 && nearer_target(faces, nearest, target)) nearest = faces;
    }
  return nearest > 0 ? nearest : target;
}

/// `reference`: what the distances are measured against (the input, or a label's mc --smooth 20 surface).
/// `after_each_run` is called after every run that succeeded, with its report.json (null if unread).
Row run_mrsnake_remesh(const Options& o, const std::string& name, const std::string& input_path,
                       const TriMesh& reference, int target, bool relax, bool available,
                       const std::function<void(const json&)>& after_each_run = {}) {
  Row row;
  row.input = name;
  row.target = target;
  row.method = relax ? "mrsnake" : "mrsnake-norelax";
  if (!available) {
    row.status = "mrsnake remesh unavailable";
    return row;
  }
  const fs::path dir = fs::path(o.out) / name / (row.method + "-" + std::to_string(target));
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  std::vector<std::string> args = {o.mrsnake, "-q",         "remesh",  input_path,
                                   "-o",      dir.string(), "--faces", std::to_string(target)};
  if (!relax) args.push_back("--no-relax");
  if (!o.config.empty()) {
    args.push_back("--config");
    args.push_back(o.config);
  }
  // Beside the folder, not in it: remesh replaces only a folder of its own outputs, and
  // writes it whole (a temporary folder renamed at the end).
  const std::string log = dir.string() + ".log";
  // The output is deterministic: every run writes the same levels; the timings are medians.
  std::vector<double> seconds, cpu_seconds, algorithm_seconds;
  for (int run = 0; run < o.repeat; ++run) {
    fs::remove(dir / "report.json");  // each run's own, or none
    const ChildRun child = run_child(args, log, o.timeout);
    if (child.timed_out) {
      row.status = "timed out after " + std::to_string(static_cast<int>(o.timeout)) + " s";
      return row;
    }
    if (child.exit_code != 0) {
      row.status = "exit " + std::to_string(child.exit_code) + ": " + last_line_of(log);
      return row;
    }
    seconds.push_back(child.seconds);
    cpu_seconds.push_back(child.cpu_seconds);
    row.peak_mib = std::max(row.peak_mib, child.peak_mib);
    json report;
    if (!fs::exists(dir / "report.json")) {
      row.extra["report_error"] = "report.json missing";
    } else {
      try {
        std::ifstream in(dir / "report.json");
        report = json::parse(in);
        if (const auto a = internal_seconds(report)) algorithm_seconds.push_back(*a);
      } catch (const std::exception& e) {
        row.extra["report_error"] = e.what();
      }
    }
    if (after_each_run) after_each_run(report);
  }
  row.extra["algorithm_runs"] = algorithm_seconds.size();
  row.seconds = median(seconds);
  row.cpu_seconds = median(cpu_seconds);
  if (!algorithm_seconds.empty()) row.algorithm_seconds = median(algorithm_seconds);
  row.extra["runs"] = o.repeat;
  // The level nearest the target face count.
  int best_faces = -1;
  TriMesh best;
  for (int level = 0;; ++level) {
    const fs::path file = dir / ("level_" + std::to_string(level) + ".vtp");
    if (!fs::exists(file)) break;
    TriMesh m = read_mesh(file.string());
    if (nearer_target(m.num_faces(), best_faces, target)) {
      best_faces = m.num_faces();
      best = std::move(m);
      row.level = level;
    }
  }
  if (best_faces < 0) {
    row.status = "no level_0.vtp in " + dir.string();
    return row;
  }
  measure(row, best, reference, o.samples);
  row.extra["levels_dir"] = dir.string();
  if (std::isnan(row.algorithm_seconds) && !row.extra.contains("report_error"))
    row.extra["report_error"] = "report.json without seconds";
  return row;
}

/// CGAL's row from `timed`, with the runs it still lacks (of --repeat) taken now, aimed at
/// `faces` (the face count mrsnake reached, so both are compared at the same size; the target
/// N when mrsnake has no result). The row is still filed under `target`. The distances are
/// measured against `reference`, as mrsnake's.
Row run_cgal(const Options& o, const std::string& name, const TriMesh& reference, int target, int faces,
             CgalTimedRuns& timed) {
  Row row;
  row.input = name;
  row.target = target;
  row.method = "cgal-isotropic";
  try {
    while (timed.runs() < o.repeat && timed.error().empty()) timed.run_once(faces);
    if (!timed.error().empty()) throw std::runtime_error(timed.error());
    const CgalRun r = timed.result();
    row.seconds = r.seconds;
    row.cpu_seconds = r.cpu_seconds;
    row.peak_mib = r.peak_mib;
    row.algorithm_seconds = r.seconds;
    row.speed_ratio = row.command_speed_ratio = row.cpu_speed_ratio = 1.0;
    measure(row, r.mesh, reference, o.samples);
    row.extra.update(json{{"iterations", o.iterations},
                          {"aimed_faces", faces},
                          {"target_edge_length", r.target_edge_length},
                          {"probe_edge_length", r.probe_edge_length},
                          {"probe_faces", r.probe_faces},
                          {"probe_seconds", r.probe_seconds},
                          {"rss_before_mib", r.rss_before_mib}});
    write_mesh((fs::path(o.out) / name / ("cgal-isotropic-" + std::to_string(target) + ".vtp")).string(), r.mesh);
  } catch (const std::exception& e) {
    row.status = std::string("failed: ") + e.what();
  }
  return row;
}

json row_json(const Row& r) {
  json j = {{"input", r.input}, {"target_faces", r.target}, {"method", r.method}, {"status", r.status}};
  if (r.missed) j["targets"] = {{"all_met", r.missed->empty()}, {"missed", *r.missed}};
  if (r.status != "ok") return j;
  j["faces"] = r.faces;
  j["seconds"] = r.seconds;
  j["cpu_seconds"] = r.cpu_seconds;
  j["peak_mib"] = std::isnan(r.peak_mib) ? json(nullptr) : json(r.peak_mib);
  if (r.level >= 0) j["level"] = r.level;
  if (r.quality) j["quality"] = *r.quality;
  if (r.distance) j["distance"] = *r.distance;
  if (r.self_intersections >= 0) j["self_intersections"] = r.self_intersections;
  const auto number_or_null = [](double x) { return std::isnan(x) ? json(nullptr) : json(x); };
  j["algorithm_seconds"] = number_or_null(r.algorithm_seconds);
  j["speed_ratio_vs_cgal"] = number_or_null(r.speed_ratio);
  j["command_speed_ratio_vs_cgal"] = number_or_null(r.command_speed_ratio);
  j["cpu_speed_ratio_vs_cgal"] = number_or_null(r.cpu_speed_ratio);
  for (const auto& [k, v] : r.extra.items()) j[k] = v;
  return j;
}

void print_header() {
  std::printf("%-17s %6s %-16s %7s %8s %7s %7s %8s %7s %7s %6s %6s %7s %7s %5s %6s %6s  %s\n", "input", "target",
              "method", "faces", "seconds", "cpu_s", "algo_s", "peakMiB", "val6%", "minang", "Qmin", "Qmean", "RMS%",
              "Haus%", "selfX", "speed", "cmd_sp", "targets missed");
}

void print_row(const Row& r) {
  std::printf("%-17s %6d %-16s ", r.input.c_str(), r.target, r.method.c_str());
  if (r.status != "ok") {
    if (r.missed)
      std::printf("misses every target: %s\n", r.status.c_str());
    else
      std::printf("%s\n", r.status.c_str());
    return;
  }
  std::printf("%7d %8.2f %7.2f ", r.faces, r.seconds, r.cpu_seconds);
  if (std::isnan(r.algorithm_seconds))
    std::printf("%7s ", "-");
  else
    std::printf("%7.3f ", r.algorithm_seconds);
  std::printf("%8.1f %7.2f %7.2f %6.3f %6.3f %7.4f %7.4f ", r.peak_mib, r.quality->pct_valence6_interior,
              r.quality->min_angle_deg, r.quality->q_min, r.quality->q_mean, r.distance->rms_pct,
              r.distance->hausdorff_pct);
  if (r.self_intersections >= 0)
    std::printf("%5d ", r.self_intersections);
  else
    std::printf("%5s ", "-");
  for (const double ratio : {r.speed_ratio, r.command_speed_ratio}) {
    if (std::isnan(ratio))
      std::printf("%6s ", "-");
    else
      std::printf("%6.2f ", ratio);
  }
  std::printf(" %s\n", targets_text(r).c_str());
}

/// Rows meeting every target, per mrsnake method: "mrsnake 3 of 8, mrsnake-norelax 0 of 8".
std::string targets_summary(const std::vector<Row>& rows) {
  std::vector<std::string> parts;
  for (const char* method : {"mrsnake", "mrsnake-norelax"}) {
    int met = 0, total = 0, without = 0;
    for (const Row& r : rows)
      if (r.method == method && r.missed) {
        ++total;
        met += r.missed->empty();
        without += r.status != "ok";
      }
    parts.push_back(std::string(method) + " " + std::to_string(met) + " of " + std::to_string(total) +
                    (without ? " (" + std::to_string(without) + " without figures: refused or failed)" : ""));
  }
  return "rows meeting all targets: " + join(parts, ", ") +
         "; CGAL's rows are the reference of the RMS and time targets";
}

// ---------------------------------------------------------------------------------------------
// The Markdown page

/// The first line a shell command prints ("" if it fails).
std::string command_output(const std::string& command) {
  std::string text;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[512];
    while (std::fgets(buffer, sizeof buffer, pipe)) text += buffer;
    pclose(pipe);
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

/// One argument as a POSIX shell reads it back.
std::string shell_quote(const std::string& arg) {
  if (!arg.empty() &&
      arg.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_./,=:+-@%") ==
          std::string::npos)
    return arg;
  std::string quoted = "'";
  for (char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

/// "AMD EPYC, 2 cores": /proc/cpuinfo's first model name and the logical CPUs.
std::string machine_text() {
  std::ifstream in("/proc/cpuinfo");
  std::string model, line;
  int processors = 0;
  while (std::getline(in, line)) {
    if (line.rfind("processor", 0) == 0) ++processors;
    if (model.empty() && line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      model = line.substr(line.find(':') + 1);
      model.erase(0, model.find_first_not_of(" \t"));
    }
  }
  if (processors == 0) processors = static_cast<int>(std::thread::hardware_concurrency());
  return (model.empty() ? std::string("unknown CPU") : model) + ", " + std::to_string(processors) +
         " cores (logical CPUs)";
}

std::string markdown_cell(std::string text) {
  for (std::size_t at = 0; (at = text.find('|', at)) != std::string::npos; at += 2) text.replace(at, 1, "\\|");
  return text;
}

std::string fixed(double x, int digits) {
  if (std::isnan(x)) return "–";
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, x);
  return text;
}

void write_markdown(const Options& o, const std::vector<Row>& rows, const json& inputs) {
  const std::string source = MRSNAKE_SOURCE_DIR;
  std::string commit = command_output("git -C " + shell_quote(source) + " rev-parse --short HEAD 2>/dev/null");
  if (commit.empty())
    commit = "unknown";
  else if (!command_output("git -C " + shell_quote(source) + " status --porcelain --untracked-files=no 2>/dev/null")
                .empty())
    commit += " with uncommitted changes";
  char date[64] = "";
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::vector<std::string> quoted;
  for (const auto& arg : o.argv) quoted.push_back(shell_quote(arg));

  std::ostringstream md;
  md << "# Remeshing benchmark: mrsnake remesh against CGAL isotropic_remeshing\n\n";
  md << "Commit " << commit << " (source tree " << source << "), machine: " << machine_text() << ", " << date
     << ", CGAL " << CGAL_VERSION_STR << ".\n\n";
  md << "Command: ";
  if (const char* script = std::getenv("MRSNAKE_BENCH_COMMAND"); script && *script)
    md << "`" << script << "`, which ran ";
  md << "`" << join(quoted, " ") << "`\n\n";

  md << "## Inputs\n\n| input | remeshed surface | vertices | faces | topology | distances measured against |\n"
        "|---|---|---|---|---|---|\n";
  for (const json& in : inputs) {
    md << "| " << in.value("name", "") << " | ";
    if (in.value("status", "") != "ok") {
      md << markdown_cell(in.value("status", "")) << " | | | | |\n";
      continue;
    }
    if (in.contains("label_input"))
      md << "`" << markdown_cell(in["label_input"]["input_command"].get<std::string>()) << "`";
    else
      md << markdown_cell(in.value("file", ""));
    md << " | " << in.value("vertices", 0) << " | " << in.value("faces", 0) << " | "
       << markdown_cell(in.value("topology", "")) << " | ";
    if (in.contains("reference")) {
      const json& ref = in["reference"];
      if (ref.value("same_as_input", false))
        md << "the input (`mc --smooth 20` itself)";
      else
        md << "`" << markdown_cell(in["label_input"]["reference_command"].get<std::string>()) << "` ("
           << ref.value("faces", 0) << " faces, " << markdown_cell(ref.value("topology", "")) << ")";
      md << "; diagonal " << fixed(ref.value("diagonal_mm", std::nan("")), 2) << " mm";
      if (ref.contains("input_distance"))
        md << "; the input itself is at RMS " << fixed(ref["input_distance"].value("rms_pct", std::nan("")), 4)
           << " %, Hausdorff " << fixed(ref["input_distance"].value("hausdorff_pct", std::nan("")), 4) << " % from it";
    } else {
      md << "the input; diagonal " << fixed(in.value("diagonal_mm", std::nan("")), 2) << " mm";
    }
    md << " |\n";
  }

  md << "\n## Results\n\n"
        "| input | target | method | faces | seconds | CPU s | algo s | peak MiB | valence 6 % | min angle | Q min | "
        "Q mean | RMS % | Hausdorff % | selfX | speed | cmd speed | targets missed |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    md << "| " << r.input << " | " << r.target << " | " << r.method << " | ";
    if (r.status != "ok") {
      for (int cell = 0; cell < 14; ++cell) md << "| ";  // faces ... cmd speed
      md << markdown_cell((r.missed ? "all (" : "(") + r.status + ")") << " |\n";
      continue;
    }
    md << r.faces << " | " << fixed(r.seconds, 2) << " | " << fixed(r.cpu_seconds, 2) << " | "
       << fixed(r.algorithm_seconds, 3) << " | " << fixed(r.peak_mib, 1) << " | "
       << fixed(r.quality->pct_valence6_interior, 2) << " | " << fixed(r.quality->min_angle_deg, 2) << " | "
       << fixed(r.quality->q_min, 3) << " | " << fixed(r.quality->q_mean, 3) << " | " << fixed(r.distance->rms_pct, 4)
       << " | " << fixed(r.distance->hausdorff_pct, 4) << " | "
       << (r.self_intersections >= 0 ? std::to_string(r.self_intersections) : std::string("–")) << " | "
       << fixed(r.speed_ratio, 2) << " | " << fixed(r.command_speed_ratio, 2) << " | " << targets_text(r) << " |\n";
  }
  md << "\n" << targets_summary(rows) << ".\n\n";
  md << "Targets (mrsnake rows): val6 = valence 6 on ≥ 99 % of the interior vertices; angle = min angle ≥ 30°; "
        "Qmin = Q min ≥ 0.6; Qmean = Q mean ≥ 0.9; RMS = RMS ≤ CGAL's at the same target; Haus = Hausdorff ≤ 0.5 % "
        "of the reference's bounding-box diagonal; time = algo s < CGAL's. A row without figures (mrsnake refused "
        "the input) misses all of them.\n\n"
        "mrsnake: wall time and peak RSS of the whole `mrsnake remesh` command; algo s = report.json's seconds (the "
        "remeshing alone). CGAL: the isotropic_remeshing call in process ("
     << o.iterations
     << " iterations, one thread), its edge length tuned to the face count of mrsnake's level. RMS %, "
        "Hausdorff % = symmetric distance to the reference in % of its bounding-box diagonal ("
     << o.samples
     << " samples per face + vertices); label-derived inputs are measured against their label's "
        "`mrsnake mc --smooth 20` surface (its spurs removed, as build-model does), and where that is not the input, "
        "the Inputs table gives the input's own "
        "distance to it, which a remesh that follows its input does not get below. speed = CGAL's algo s / algo s (> "
        "1: faster than CGAL); cmd speed = "
        "CGAL's call / the whole mrsnake command. Times are medians of "
     << o.repeat
     << " runs, each of CGAL's right after one of mrsnake's (relaxed), so that a slow spell of the "
        "machine slows both alike.\n";
  write_text_file_atomically(o.markdown, md.str());
}

/// Whether `mrsnake --help` lists the subcommand (`mrsnake CMD --help` cannot tell: an
/// unknown subcommand's --help still prints the main help and exits 0).
bool has_command(const Options& o, const std::string& command) {
  if (!fs::exists(o.mrsnake)) return false;
  const std::string log = (fs::path(o.out) / "mrsnake-help.log").string();
  if (run_child({o.mrsnake, "--help"}, log, 60).exit_code != 0) return false;
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string first;
    // Subcommands are listed one per line, indented, name first.
    if (!line.empty() && line[0] == ' ' && words >> first && first == command) return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_options(argc, argv);
  try {
    fs::create_directories(o.out);
  } catch (const std::exception& e) {
    std::cerr << "bench_remesh: cannot create the output folder " << o.out << ": " << e.what() << "\n";
    return 4;
  }
  const bool remesh_available = has_command(o, "remesh");
  if (!remesh_available)
    std::cerr << "bench_remesh: '" << o.mrsnake
              << " remesh' is unavailable (binary missing or no remesh command): only CGAL rows will have figures\n";

  std::vector<Row> rows;
  json inputs_json = json::array();
  int inputs_read = 0;
  // An input that cannot be read still gets its rows, saying why.
  auto skip_input = [&](const std::string& name, const std::string& why) {
    for (int t : o.targets)
      for (const char* m : {"mrsnake", "mrsnake-norelax", "cgal-isotropic"}) {
        Row r;
        r.input = name;
        r.target = t;
        r.method = m;
        r.status = why;
        if (r.method != "cgal-isotropic") r.missed = kTargetNames;
        rows.push_back(r);
      }
  };
  for (const std::string& name : with_held_out_expanded(o.inputs)) {
    // Resolve the input file, and the surface the distances are measured against.
    std::string path, reference_path;
    std::string label = name;
    json label_record;
    if (const LabelInput* label_input = find_label_input(name)) {
      try {
        LabelSurfaces surfaces = make_label_input(o, *label_input);
        path = surfaces.input_path;
        reference_path = surfaces.reference_path;
        label_record = std::move(surfaces.record);
      } catch (const std::exception& e) {
        const std::string why = std::string("skipped: ") + e.what();
        std::cerr << name << ": " << why << "\n";
        skip_input(name, why);
        inputs_json.push_back({{"name", name}, {"status", why}});
        continue;
      }
    } else if (name.find('/') != std::string::npos || name.find('.') != std::string::npos) {
      path = name;
      label = fs::path(name).stem().string();
    } else {
      path = (fs::path(o.data) / "meshes" / (name + ".off")).string();
    }
    TriMesh input;
    std::optional<TriMesh> reference_mesh;  // set when it is not the input itself
    try {
      input = read_mesh(path);
      if (!reference_path.empty() && reference_path != path) reference_mesh = read_mesh(reference_path);
    } catch (const std::exception& e) {
      std::cerr << label << ": skipped: " << e.what() << "\n";
      skip_input(label, std::string("skipped: ") + e.what());
      inputs_json.push_back({{"name", label}, {"file", path}, {"status", std::string("skipped: ") + e.what()}});
      continue;
    }
    const TriMesh& reference = reference_mesh ? *reference_mesh : input;
    ++inputs_read;
    fs::create_directories(fs::path(o.out) / label);
    const TopologyReport topo = topology_report(input);
    json input_json = {{"name", label},
                       {"file", path},
                       {"status", "ok"},
                       {"vertices", input.num_vertices()},
                       {"faces", input.num_faces()},
                       {"topology", topo.describe()},
                       {"diagonal_mm", bounding_box_diagonal(input.V)}};
    std::cerr << label << ": " << input.num_faces() << " faces, " << topo.describe() << "\n";
    if (!label_record.is_null()) {
      input_json["label_input"] = label_record;
      input_json["reference"] = {{"file", reference_path},
                                 {"same_as_input", !reference_mesh.has_value()},
                                 {"vertices", reference.num_vertices()},
                                 {"faces", reference.num_faces()},
                                 {"topology", topology_report(reference).describe()},
                                 {"diagonal_mm", bounding_box_diagonal(reference.V)}};
      if (reference_mesh) {
        std::cerr << label << ": distances against " << reference_path << " (" << reference.num_faces() << " faces, "
                  << input_json["reference"]["topology"].get<std::string>() << ")\n";
        // The input's own distance: a remesh that follows its input can do no better.
        DistanceOptions options;
        options.samples_per_face = o.samples;
        input_json["reference"]["input_distance"] = surface_distance(input, reference, options);
      }
    }
    inputs_json.push_back(input_json);
    for (int target : o.targets) {
      std::cerr << label << " " << target << ": mrsnake and cgal-isotropic, run by run...\n";
      CgalTimedRuns cgal_runs(input, o.iterations);
      Row relaxed =
          run_mrsnake_remesh(o, label, path, reference, target, true, remesh_available,
                             [&](const json& report) { cgal_runs.run_once(nearest_level_faces(report, target)); });
      std::cerr << label << " " << target << ": mrsnake --no-relax...\n";
      Row plain = run_mrsnake_remesh(o, label, path, reference, target, false, remesh_available);
      const int aim = relaxed.status == "ok" ? relaxed.faces : target;
      if (cgal_runs.runs() < o.repeat)
        std::cerr << label << " " << target << ": cgal-isotropic (aiming at " << aim << " faces)...\n";
      Row cgal = run_cgal(o, label, reference, target, aim, cgal_runs);
      for (Row* r : {&relaxed, &plain})
        if (r->status == "ok" && cgal.status == "ok" && r->seconds > 0) {
          if (r->algorithm_seconds > 0) r->speed_ratio = cgal.seconds / r->algorithm_seconds;
          r->command_speed_ratio = cgal.seconds / r->seconds;
          if (r->cpu_seconds > 0) r->cpu_speed_ratio = cgal.cpu_seconds / r->cpu_seconds;
        }
      relaxed.missed = missed_targets(relaxed, cgal);
      plain.missed = missed_targets(plain, cgal);
      rows.push_back(relaxed);
      rows.push_back(plain);
      rows.push_back(cgal);
    }
  }

  std::printf("\nRemeshing benchmark: mrsnake remesh against CGAL isotropic_remeshing (%d iterations)\n", o.iterations);
  std::printf(
      "mrsnake: wall time and peak RSS of the whole 'mrsnake remesh' command (subprocess);\n"
      "CGAL: the isotropic_remeshing call in process, peak RSS of this process during it; its edge\n"
      "length is tuned to the face count of mrsnake's level (else to the target).\n"
      "val6%% = interior vertices of valence 6; RMS%%, Haus%% = symmetric distance to the input in %% of\n"
      "its bounding-box diagonal (%d samples per face + vertices; a label-derived input is measured against\n"
      "its label's 'mrsnake mc --smooth 20' surface instead); selfX = pairs of intersecting faces;\n"
      "cpu_s = user + system time; algo_s = the remeshing alone, wall (mrsnake: report.json's seconds,\n"
      "without reading, writing and the report's distance statistics; its parallel loops use up to %u\n"
      "threads here; CGAL: its call, one thread);\n"
      "speed = CGAL's algo_s / algo_s (> 1 is faster than CGAL); cmd_sp = CGAL's call / the whole mrsnake\n"
      "command, wall (the JSON also has the CPU ratio of the whole command).\n"
      "Times are medians of %d runs of each method, CGAL's alternating with mrsnake's; peak memory\n"
      "the largest of them.\n"
      "targets missed (mrsnake rows): val6 >= 99 %%, angle >= 30 deg, Qmin >= 0.6, Qmean >= 0.9, RMS <= CGAL's,\n"
      "Haus <= 0.5 %%, time = algo_s < CGAL's; a row without figures misses all of them.\n\n",
      o.samples, std::min(8u, std::max(1u, std::thread::hardware_concurrency())), o.repeat);
  print_header();
  for (const Row& r : rows) print_row(r);
  std::printf("\n%s\n", targets_summary(rows).c_str());

  json j = {{"benchmark", "remesh"},
            {"mrsnake", o.mrsnake},
            {"mrsnake_remesh_available", remesh_available},
            {"cgal_version", CGAL_VERSION_STR},
            {"cgal_iterations", o.iterations},
            {"timed_runs", o.repeat},
            {"samples_per_face", o.samples},
            {"hardware_threads", std::thread::hardware_concurrency()},
            {"inputs", inputs_json},
            {"target_values",
             {{"val6_pct_min", 99.0},
              {"min_angle_deg_min", 30.0},
              {"q_min_min", 0.6},
              {"q_mean_min", 0.9},
              {"rms", "<= CGAL's at the same target"},
              {"hausdorff_pct_max", 0.5},
              {"time", "algorithm_seconds < CGAL's"}}},
            {"targets_summary", targets_summary(rows)},
            {"rows", json::array()}};
  for (const Row& r : rows) j["rows"].push_back(row_json(r));
  const std::string json_path = (fs::path(o.out) / "bench_remesh.json").string();
  try {
    write_text_file_atomically(json_path, j.dump(2) + "\n");
    std::printf("\nwrote %s\n", json_path.c_str());
    if (!o.markdown.empty()) {
      write_markdown(o, rows, inputs_json);
      std::printf("wrote %s\n", o.markdown.c_str());
    }
    if (inputs_read == 0) {
      std::cerr << "bench_remesh: no input could be read; set --data or MRSNAKE_DATA to the shared data folder\n";
      return 3;
    }
  } catch (const std::exception& e) {
    std::cerr << "bench_remesh: " << e.what() << "\n";
    return 4;
  }
  return 0;
}
