#pragma once
/// \file render.h
/// Offscreen 3D renders of meshes with VTK. Debian's VTK renders through X only, so a
/// render needs a display (a real one or Xvfb: the scripts use `xvfb-run -a`); without one
/// the functions say so instead of letting VTK abort.
#include <cstdint>
#include <string>
#include <vector>

#include "mesh/trimesh.h"

namespace mrsnake::reports {

struct RenderOptions {
  int width = 640;
  int height = 480;
  bool wireframe = true;                ///< draw the edges over the shaded surface
  std::vector<double> face_scalars;     ///< optional: colour faces by these values
  bool log_scale = false;               ///< colour by log10 of the scalars
  std::string scalar_title;             ///< title of the colour bar
  double azimuth = 35, elevation = 20;  ///< camera angles around the mesh, in degrees
  /// Optional second mesh drawn as a translucent overlay (e.g. the truth surface).
  const TriMesh* overlay = nullptr;
  /// A render that takes longer is stopped; it throws, and later renders of the process are
  /// left out (display_available() then says why).
  double max_seconds = 120;
};

/// True when an X display answers (DISPLAY set and reachable). Otherwise `why` says what
/// is missing.
bool display_available(std::string* why = nullptr);

/// PNG bytes of a shaded render of the mesh. The render runs in a forked child process: VTK
/// aborts when it cannot open an OpenGL window, and that must cost a picture, not the program.
/// \pre display_available()
/// \throw Error if no display is available, or the renderer failed, stopped or outlasted
///        options.max_seconds (its child is then killed).
std::vector<std::uint8_t> render_mesh_png(const TriMesh& mesh, const RenderOptions& options = {});

}  // namespace mrsnake::reports
