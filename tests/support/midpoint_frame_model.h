#pragma once
/// \file midpoint_frame_model.h
/// A test double of the shape model: a SnakeModel without wavelets.
#include "mesh/subdivision.h"
#include "mesh/trimesh.h"
#include "snake/segment.h"

namespace mrsnake {

/// A stand-in model without lifting: S_j is the prefix of the finest level, the details are
/// the offsets of each new vertex from its parent edge's midpoint in the edge's local frame
/// (edge direction, mean normal of its endpoints, their cross product; scaled by the edge
/// length), so that synthesis follows a similarity of S_j.
/// \pre finest has conn.vertex_counts.back() rows.
SnakeModel midpoint_frame_model(const SubdivisionConnectivity& conn, const RowMatrixX3d& finest);

}  // namespace mrsnake
