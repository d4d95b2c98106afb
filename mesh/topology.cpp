#include "mesh/topology.h"

#include <algorithm>
#include <numeric>
#include <cstdint>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/vertex_stars.h"

namespace mrsnake {
namespace {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

std::uint64_t key(int a, int b) { return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b); }

}  // namespace

bool TopologyReport::is_closed_genus0() const {
  return components == 1 && is_manifold() && boundary_loops == 0 && genus == 0;
}

bool TopologyReport::is_disk() const { return components == 1 && is_manifold() && boundary_loops == 1 && genus == 0; }

std::string TopologyReport::describe() const {
  if (faces == 0) return "an empty mesh";
  std::string s;
  if (is_closed_genus0()) return "a closed genus-0 surface";
  if (is_disk()) return "a disk (one boundary loop)";
  s = std::to_string(components) + (components == 1 ? " component" : " components");
  if (genus) s += ", genus " + std::to_string(genus);
  s += boundary_loops ? ", " + std::to_string(boundary_loops) + " boundary loop" + (boundary_loops > 1 ? "s" : "")
                      : ", closed";
  if (non_manifold_edges) s += ", " + std::to_string(non_manifold_edges) + " non-manifold edges";
  if (non_manifold_vertices) s += ", " + std::to_string(non_manifold_vertices) + " non-manifold vertices";
  return s;
}

TopologyReport topology_report(const TriMesh& mesh) {
  TopologyReport r;
  const int n = mesh.num_vertices();
  const int m = mesh.num_faces();
  r.vertices = n;
  r.faces = m;
  const double diag = bounding_box_diagonal(mesh.V);
  const double area_eps = 1e-14 * diag * diag;

  // Half-edges as sorted keys of their undirected edge (runs = counts), shifted left by one
  // with the direction in the lowest bit (1 = from the larger index): sorting is several
  // times faster than hashing on meshes of hundreds of thousands of faces, and an edge's two
  // half-edges are consistently oriented exactly when their bits differ. (Indices are
  // non-negative ints, so the key's top bit is free for the shift.)
  // The keys are bucketed by their smaller vertex (a counting sort) and each bucket, a
  // vertex's few edges, is sorted on its own: the same order as one sort of the whole array.
  std::vector<char> used(n, 0);
  std::vector<int> bucket(static_cast<std::size_t>(n) + 1, 0);
  UnionFind faces_uf(n);
  for (int f = 0; f < m; ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    if (a == b || b == c || c == a) {
      ++r.degenerate_faces;
    } else {
      const Eigen::Vector3d e1 = mesh.V.row(b) - mesh.V.row(a), e2 = mesh.V.row(c) - mesh.V.row(a);
      if (0.5 * e1.cross(e2).norm() <= area_eps) ++r.degenerate_faces;
    }
    faces_uf.unite(a, b);  // joins a, b and c: the same components as uniting every edge
    faces_uf.unite(b, c);
    for (int k = 0; k < 3; ++k) {
      const int u = mesh.F(f, k), v = mesh.F(f, (k + 1) % 3);
      used[u] = 1;
      if (u != v) ++bucket[std::min(u, v) + 1];
    }
  }
  for (int v = 0; v < n; ++v) bucket[v + 1] += bucket[v];
  std::vector<std::uint64_t> undirected(static_cast<std::size_t>(bucket[n]));
  {
    std::vector<int> next(bucket.begin(), bucket.end() - 1);
    for (int f = 0; f < m; ++f)
      for (int k = 0; k < 3; ++k) {
        const int u = mesh.F(f, k), v = mesh.F(f, (k + 1) % 3);
        if (u != v) undirected[next[std::min(u, v)]++] = key(std::min(u, v), std::max(u, v)) << 1 | (u > v ? 1u : 0u);
      }
  }
  for (int v = 0; v < n; ++v) {
    const auto first = undirected.begin() + bucket[v], last = undirected.begin() + bucket[v + 1];
    if (last - first <= 32) {
      for (auto i = first; i != last; ++i)  // insertion sort: a handful of keys
        for (auto j = i; j != first && *(j - 1) > *j; --j) std::iter_swap(j - 1, j);
    } else {
      std::sort(first, last);
    }
  }
  r.referenced_vertices = static_cast<int>(std::count(used.begin(), used.end(), 1));

  // Boundary edges and loops: boundary vertices are joined by boundary edges; a loop is a
  // component of that graph (a vertex where two loops touch is counted non-manifold below).
  UnionFind boundary_uf(n);
  std::vector<char> on_boundary(n, 0);
  for (std::size_t i = 0; i < undirected.size();) {
    std::size_t j = i + 1;
    while (j < undirected.size() && undirected[j] >> 1 == undirected[i] >> 1) ++j;
    const std::size_t count = j - i;
    const std::uint64_t k = undirected[i] >> 1;
    const int u = static_cast<int>(k >> 32), v = static_cast<int>(k & 0xffffffffu);
    ++r.edges;
    if (count == 1) {
      ++r.boundary_edges;
      boundary_uf.unite(u, v);
      on_boundary[u] = on_boundary[v] = 1;
    } else if (count > 2) {
      ++r.non_manifold_edges;
    } else if (undirected[i] == undirected[i + 1]) {  // both half-edges run the same way
      ++r.inconsistently_oriented_edges;
    }
    i = j;
  }
  for (int v = 0; v < n; ++v)
    if (on_boundary[v] && boundary_uf.find(v) == v) ++r.boundary_loops;
  for (int v = 0; v < n; ++v)
    if (used[v] && faces_uf.find(v) == v) ++r.components;

  // Non-manifold vertices: the link (opposite edges of the incident faces) must be connected.
  // Incident faces in one flat array (offsets per vertex); a star's link vertices are
  // numbered by their rank in its sorted list.
  const VertexStars stars(mesh.F, n);
  const std::vector<int>& offset = stars.offset;
  const std::vector<int>& incident = stars.faces;
  std::vector<int> link, parent;
  // Most stars are small: their link vertices go into fixed arrays searched linearly (no
  // allocation, no sort); larger stars use the sorted vectors.
  constexpr int kSmallStar = 16;
  for (int v = 0; v < n; ++v) {
    const int star = offset[v + 1] - offset[v];
    if (star < 2) continue;
    if (star <= kSmallStar) {
      int ids[2 * kSmallStar], up[2 * kSmallStar], count = 0;
      const auto id = [&](int w) {
        for (int i = 0; i < count; ++i)
          if (ids[i] == w) return i;
        ids[count] = w;
        up[count] = count;
        return count++;
      };
      const auto root = [&](int x) {
        while (up[x] != x) x = up[x] = up[up[x]];
        return x;
      };
      for (int i = offset[v]; i < offset[v + 1]; ++i) {
        int others[2], c = 0;
        for (int k = 0; k < 3 && c < 2; ++k)
          if (mesh.F(incident[i], k) != v) others[c++] = mesh.F(incident[i], k);
        if (c < 2) continue;
        const int a = id(others[0]), b = id(others[1]);
        up[root(a)] = root(b);
      }
      int fans = 0;
      for (int x = 0; x < count; ++x)
        if (root(x) == x) ++fans;
      if (fans > 1) ++r.non_manifold_vertices;
      continue;
    }
    link.clear();
    for (int i = offset[v]; i < offset[v + 1]; ++i) {
      int others[2], c = 0;
      for (int k = 0; k < 3 && c < 2; ++k)
        if (mesh.F(incident[i], k) != v) others[c++] = mesh.F(incident[i], k);
      if (c == 2) link.insert(link.end(), others, others + 2);
    }
    std::sort(link.begin(), link.end());
    link.erase(std::unique(link.begin(), link.end()), link.end());
    parent.resize(link.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto id = [&](int w) { return static_cast<int>(std::lower_bound(link.begin(), link.end(), w) - link.begin()); };
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (int i = offset[v]; i < offset[v + 1]; ++i) {
      const int f = incident[i];
      int others[2], c = 0;
      for (int k = 0; k < 3 && c < 2; ++k)
        if (mesh.F(f, k) != v) others[c++] = mesh.F(f, k);
      if (c < 2) continue;
      const int a = id(others[0]), b = id(others[1]);
      parent[find(a)] = find(b);
    }
    int fans = 0;
    for (int x = 0; x < static_cast<int>(parent.size()); ++x)
      if (find(x) == x) ++fans;
    if (fans > 1) ++r.non_manifold_vertices;
  }

  r.euler_characteristic = r.referenced_vertices - r.edges + r.faces;
  r.genus = (2 * r.components - r.euler_characteristic - r.boundary_loops) / 2;
  return r;
}

std::vector<std::vector<int>> connected_components(const TriMesh& mesh) {
  UnionFind uf(mesh.num_vertices());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    uf.unite(mesh.F(f, 0), mesh.F(f, 1));
    uf.unite(mesh.F(f, 1), mesh.F(f, 2));
  }
  std::unordered_map<int, int> index;
  std::vector<std::vector<int>> comps;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto [it, inserted] = index.try_emplace(uf.find(mesh.F(f, 0)), static_cast<int>(comps.size()));
    if (inserted) comps.emplace_back();
    comps[it->second].push_back(f);
  }
  std::stable_sort(comps.begin(), comps.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return comps;
}

TriMesh extract_faces(const TriMesh& mesh, const std::vector<int>& faces) {
  TriMesh sub;
  sub.V = mesh.V;
  sub.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) sub.F.row(static_cast<Eigen::Index>(i)) = mesh.F.row(faces[i]);
  return remove_unreferenced_vertices(sub);
}

TriMesh remove_unreferenced_vertices(const TriMesh& mesh) {
  std::vector<int> remap(mesh.num_vertices(), -1);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) remap[mesh.F(f, k)] = 0;
  int next = 0;
  for (int& r : remap)
    if (r == 0) r = next++;
  TriMesh out;
  out.V.resize(next, 3);
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (remap[v] >= 0) out.V.row(remap[v]) = mesh.V.row(v);
  out.F.resize(mesh.num_faces(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) out.F(f, k) = remap[mesh.F(f, k)];
  return out;
}

void require_disk_or_sphere(const TopologyReport& r, const std::string& what) {
  if ((r.is_disk() || r.is_closed_genus0()) && r.inconsistently_oriented_edges > 0)
    throw TopologyError(what + " has " + std::to_string(r.inconsistently_oriented_edges) +
                        " inconsistently oriented edges; orient its faces consistently first");
  if (r.is_disk() || r.is_closed_genus0()) return;
  std::string advice;
  if (r.faces == 0)
    advice = "the mesh is empty";
  else if (r.components > 1)
    advice = "keep only the largest component (mrsnake mc does this)";
  else if (!r.is_manifold())
    advice = "repair the non-manifold parts first";
  else if (r.genus > 0)
    advice = "close the handles (e.g. fill the label volume's tunnels) so it becomes genus 0";
  else
    advice = "fill all holes but one, or close the surface";
  throw TopologyError(what + " is " + r.describe() +
                      ", but only a disk or a closed genus-0 surface can be parameterized; " + advice);
}

void to_json(nlohmann::json& j, const TopologyReport& r) {
  j = nlohmann::json{{"vertices", r.vertices},
                     {"referenced_vertices", r.referenced_vertices},
                     {"faces", r.faces},
                     {"edges", r.edges},
                     {"boundary_edges", r.boundary_edges},
                     {"boundary_loops", r.boundary_loops},
                     {"components", r.components},
                     {"euler_characteristic", r.euler_characteristic},
                     {"genus", r.genus},
                     {"non_manifold_edges", r.non_manifold_edges},
                     {"non_manifold_vertices", r.non_manifold_vertices},
                     {"degenerate_faces", r.degenerate_faces},
                     {"inconsistently_oriented_edges", r.inconsistently_oriented_edges},
                     {"is_manifold", r.is_manifold()},
                     {"is_closed", r.is_closed()},
                     {"type", r.describe()}};
}

}  // namespace mrsnake
