#pragma once
/// \file primitives.h
/// Analytic meshes for tests, demos and base meshes.
#include "mesh/subdivision.h"
#include "mesh/trimesh.h"

namespace mrsnake {

/// The regular icosahedron inscribed in the sphere of the given radius at the origin,
/// faces oriented outward. 12 vertices of valence 5, 30 edges, 20 faces.
TriMesh icosahedron(double radius = 1.0);

/// A sphere: the icosahedron split 1:4 `levels` times, every vertex projected onto the
/// sphere. Its connectivity nests (the SubdivisionConnectivity of the icosahedron).
TriMesh icosphere(int levels, double radius = 1.0);

}  // namespace mrsnake
