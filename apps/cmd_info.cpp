// mrsnake info MESH: the topology report of a mesh.
#include <iostream>

#include "apps/cli.h"
#include "mesh/mesh_io.h"
#include "mesh/topology.h"

namespace mrsnake::cli {

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Print a mesh's topology: counts, boundaries, components, genus, defects");
  auto mesh_path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("MESH", *mesh_path, "Mesh file (.vtp .vtk .stl .ply .obj .off)")->required();
  cmd->add_flag("--json", *json, "Print JSON instead of text");
  cmd->footer("Example: mrsnake info liver.vtp --json");
  cmd->callback([=] {
    const TriMesh mesh = read_mesh(*mesh_path);
    const TopologyReport r = topology_report(mesh);
    if (*json) {
      nlohmann::json j = r;
      j["file"] = *mesh_path;
      print_json(j);
      return;
    }
    std::cout << *mesh_path << ": " << r.describe() << '\n'
              << "  vertices               " << r.vertices << " (" << r.referenced_vertices << " referenced)\n"
              << "  faces                  " << r.faces << '\n'
              << "  edges                  " << r.edges << '\n'
              << "  boundary loops         " << r.boundary_loops << " (" << r.boundary_edges << " edges)\n"
              << "  components             " << r.components << '\n'
              << "  euler characteristic   " << r.euler_characteristic << '\n'
              << "  genus                  " << r.genus << '\n'
              << "  non-manifold edges     " << r.non_manifold_edges << '\n'
              << "  non-manifold vertices  " << r.non_manifold_vertices << '\n'
              << "  degenerate faces       " << r.degenerate_faces << '\n'
              << "  misoriented edges      " << r.inconsistently_oriented_edges << '\n';
  });
}

}  // namespace mrsnake::cli
