#pragma once
/// \file topology.h
/// Topology queries on a triangle mesh: counts, boundaries, components, genus and defects.
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "mesh/trimesh.h"

namespace mrsnake {

/// What the mesh is, topologically. Counts cover the referenced vertices only.
struct TopologyReport {
  int vertices = 0;             ///< rows of V
  int referenced_vertices = 0;  ///< vertices used by at least one face
  int faces = 0;
  int edges = 0;  ///< undirected edges
  int boundary_edges = 0;
  int boundary_loops = 0;
  int components = 0;                     ///< connected components (through shared vertices)
  int euler_characteristic = 0;           ///< V - E + F over referenced vertices
  int genus = 0;                          ///< total genus, from χ = 2c - 2g - b; meaningful on manifolds
  int non_manifold_edges = 0;             ///< edges with more than two faces
  int non_manifold_vertices = 0;          ///< vertices whose faces form more than one fan
  int degenerate_faces = 0;               ///< repeated corners or (near) zero area
  int inconsistently_oriented_edges = 0;  ///< interior edges used twice in the same direction

  bool is_manifold() const { return non_manifold_edges == 0 && non_manifold_vertices == 0; }
  bool is_closed() const { return boundary_edges == 0; }
  /// One component, manifold, no boundary, genus 0 (a topological sphere).
  bool is_closed_genus0() const;
  /// One component, manifold, one boundary loop, genus 0 (a topological disk).
  bool is_disk() const;
  /// A short human description, e.g. "closed genus-0 surface" or "genus 3, 2 boundary loops".
  std::string describe() const;
};

/// Computes the topology report.
/// \pre F's indices are in [0, V.rows()).
TopologyReport topology_report(const TriMesh& mesh);

/// The faces of each connected component (through shared vertices), largest first.
std::vector<std::vector<int>> connected_components(const TriMesh& mesh);

/// The submesh made of the given faces, with unreferenced vertices dropped.
TriMesh extract_faces(const TriMesh& mesh, const std::vector<int>& faces);

/// Drops vertices no face references, keeping the order of the others.
TriMesh remove_unreferenced_vertices(const TriMesh& mesh);

/// Throws unless the mesh is a disk or a closed genus-0 surface with consistently oriented
/// faces, saying what was found and what to do. Used by every algorithm that parameterizes.
/// \throw TopologyError naming the defect.
void require_disk_or_sphere(const TopologyReport& report, const std::string& what);

void to_json(nlohmann::json& j, const TopologyReport& r);

}  // namespace mrsnake
