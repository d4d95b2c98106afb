#pragma once
/// \file base_route.h
/// remesh() on the base-mesh domain (ParameterDomain::base_mesh): MAPS simplifies the input to
/// the base mesh K and maps each patch onto its base triangle (remesh/maps.h), the levels are
/// split and relaxed in the charts of K (remesh/base_levels.h) and lifted through the map's
/// inverse (remesh/base_lift.h). Internal to the remesh module; remesh() calls it.
#include "remesh/remesh.h"
#include "remesh/remesh_stages.h"

namespace mrsnake {

/// \pre the options passed remesh()'s checks; input has faces.
/// \throw TopologyError, AlgorithmError as remesh().
RemeshResult remesh_on_base_mesh(const TriMesh& input, const RemeshOptions& options);

/// The same from an input already prepared (the automatic domain prepares it once for both
/// routes); the report's seconds count from `start`.
/// \pre prepared is remesh_stages::prepare_input(input, options, ...); the options passed
///      remesh()'s checks.
/// \throw AlgorithmError as remesh().
RemeshResult remesh_on_base_mesh(remesh_stages::PreparedInput prepared, const RemeshOptions& options,
                                 remesh_stages::Clock::time_point start);

}  // namespace mrsnake
