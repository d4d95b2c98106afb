#include "mesh/marching_cubes.h"

#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkFlyingEdges3D.h>
#include <vtkNew.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "mesh/errors.h"
#include "mesh/label_repair.h"
#include "mesh/label_spurs.h"
#include "mesh/label_resample.h"
#include "mesh/topology.h"
#include "mesh/vtk_convert.h"

namespace mrsnake {
namespace {

/// Maps vertices from (unpadded) index space to physical space. An improper index-to-
/// physical map (negative determinant) mirrors the triangles, so their order is flipped.
void index_to_physical(const Volume& volume, TriMesh& mesh) {
  Eigen::Matrix3d M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = volume.direction[3 * r + c] * volume.spacing[c];
  const Eigen::RowVector3d origin(volume.origin[0], volume.origin[1], volume.origin[2]);
  mesh.V = (mesh.V * M.transpose()).rowwise() + origin;
  if (M.determinant() < 0) mesh.F.col(1).swap(mesh.F.col(2));
}

/// Makes a closed mesh outward-oriented (positive enclosed volume).
void orient_outward(TriMesh& mesh) {
  if (enclosed_volume(mesh) < 0) mesh.F.col(1).swap(mesh.F.col(2));
}

std::string labels_present(const Volume& labels) {
  std::set<float> values;
  for (float v : labels.data) {
    values.insert(v);
    if (values.size() > 12) break;
  }
  std::string s;
  int shown = 0;
  for (float v : values) {
    if (shown++ == 12) {
      s += ", ...";
      break;
    }
    s += (s.empty() ? "" : ", ") + std::to_string(static_cast<long long>(v));
  }
  return s;
}

TriMesh windowed_sinc(const TriMesh& mesh, int iterations, double passband) {
  vtkNew<vtkWindowedSincPolyDataFilter> smoother;
  smoother->SetInputData(to_polydata(mesh));
  smoother->SetNumberOfIterations(iterations);
  smoother->SetPassBand(passband);
  smoother->BoundarySmoothingOff();
  smoother->FeatureEdgeSmoothingOff();
  smoother->NonManifoldSmoothingOn();
  // Normalizing keeps the filter's numerics independent of the mesh's size and position.
  smoother->NormalizeCoordinatesOn();
  smoother->Update();
  TriMesh out = from_polydata(smoother->GetOutput());
  out.F = mesh.F;  // the filter moves points only; keep our own face order
  return out;
}

}  // namespace

double enclosed_volume(const TriMesh& mesh) {
  double six_v = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

namespace {

LabelSurface extract_once(const Volume& labels, int label, const LabelSurfaceOptions& options,
                          const ProgressFn& progress) {
  const auto target = static_cast<float>(label);
  TriMesh mesh;
  if (options.resample_spacing_mm > 0) {
    OccupancyOptions occupancy;
    occupancy.spacing_mm = options.resample_spacing_mm;
    const Volume field = label_occupancy(labels, label, occupancy);
    vtkNew<vtkFlyingEdges3D> mc;
    mc->SetInputData(to_index_space_image(field, 1, 0.0f));
    mc->SetValue(0, 0.5);
    mc->ComputeNormalsOff();
    mc->ComputeGradientsOff();
    mc->ComputeScalarsOff();
    mc->Update();
    mesh = from_polydata(mc->GetOutput());
    if (mesh.empty())
      throw InputError("label " + std::to_string(label) + " gives an empty surface at a spacing of " +
                       std::to_string(options.resample_spacing_mm) + " mm; use a finer spacing");
    index_to_physical(field, mesh);
  } else {
    // Pad with a value that is not the label, so that objects touching the border close.
    const float outside = target == 0.0f ? 1.0f : 0.0f;
    vtkNew<vtkDiscreteFlyingEdges3D> mc;
    mc->SetInputData(to_index_space_image(labels, 1, outside));
    mc->SetValue(0, target);
    mc->ComputeNormalsOff();
    mc->ComputeGradientsOff();
    mc->ComputeScalarsOff();
    mc->Update();
    mesh = from_polydata(mc->GetOutput());
    if (mesh.empty()) throw InputError("label " + std::to_string(label) + " gives an empty surface");
    index_to_physical(labels, mesh);
  }
  report(progress, "marching cubes", 0.5);

  LabelSurface result;
  auto components = connected_components(mesh);
  result.components_found = static_cast<int>(components.size());
  if (options.keep_largest_component && components.size() > 1) {
    for (std::size_t c = 1; c < components.size(); ++c)
      result.dropped_component_faces.push_back(static_cast<int>(components[c].size()));
    mesh = extract_faces(mesh, components.front());
  } else {
    mesh = remove_unreferenced_vertices(mesh);
  }
  orient_outward(mesh);
  if (options.smoothing_iterations > 0) {
    report(progress, "smoothing", 0.0);
    mesh = windowed_sinc(mesh, options.smoothing_iterations, options.smoothing_passband);
  }
  result.mesh = std::move(mesh);
  return result;
}

// The surface of `label`; if it is not genus 0, that of the label closed with the smallest radius
// up to options.max_closing_radius that makes it genus 0.
LabelSurface extract_surface_and_close_tunnels(const Volume& labels, int label, const LabelSurfaceOptions& options,
                                               const ProgressFn& progress) {
  LabelSurface result = extract_once(labels, label, options, progress);
  result.genus_before_repair = topology_report(result.mesh).genus;
  for (int radius = 1; result.genus_before_repair > 0 && radius <= options.max_closing_radius; ++radius) {
    report(progress, "closing tunnels (radius " + std::to_string(radius) + ")", 0.0);
    LabelSurface closed = extract_once(close_label(labels, label, radius), 1, options, progress);
    if (topology_report(closed.mesh).genus == 0) {
      closed.genus_before_repair = result.genus_before_repair;
      closed.closing_radius = radius;
      result = std::move(closed);
      break;
    }
  }
  return result;
}

}  // namespace

LabelSurface extract_label_surface(const Volume& labels, int label, const LabelSurfaceOptions& options,
                                   const ProgressFn& progress) {
  const auto target = static_cast<float>(label);
  if (std::none_of(labels.data.begin(), labels.data.end(), [&](float v) { return v == target; }))
    throw InputError("label " + std::to_string(label) +
                         " is not present in the volume (labels present: " + labels_present(labels) + ")",
                     Remedy::choose_label);
  report(progress, "marching cubes", 0.0);
  // The label is copied only when it has spurs to remove: a CT volume can be hundreds of MB.
  const std::vector<std::size_t> spurs = options.remove_spurs ? label_spurs(labels, label) : std::vector<std::size_t>{};
  Volume without_spurs;
  if (!spurs.empty()) {
    without_spurs = labels;
    for (std::size_t v : spurs) without_spurs.data[v] = 0;
  }
  LabelSurface result =
      extract_surface_and_close_tunnels(spurs.empty() ? labels : without_spurs, label, options, progress);
  result.spur_voxels_removed = static_cast<int>(spurs.size());
  report(progress, "marching cubes", 1.0);
  return result;
}

TriMesh extract_isosurface(const Volume& field, double iso, bool inside_is_greater) {
  // Pad with an "outside" value so that the inside is bounded and the surface closed.
  const float outside = static_cast<float>(inside_is_greater ? iso - 1.0 : iso + 1.0);
  vtkNew<vtkFlyingEdges3D> mc;
  mc->SetInputData(to_index_space_image(field, 1, outside));
  mc->SetValue(0, iso);
  mc->ComputeNormalsOff();
  mc->ComputeGradientsOff();
  mc->ComputeScalarsOff();
  mc->Update();
  TriMesh mesh = from_polydata(mc->GetOutput());
  if (mesh.empty()) throw InputError("the isosurface at " + std::to_string(iso) + " is empty");
  index_to_physical(field, mesh);
  mesh = remove_unreferenced_vertices(mesh);
  orient_outward(mesh);
  return mesh;
}

}  // namespace mrsnake
