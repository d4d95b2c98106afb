// libFuzzer harness: read_mesh on arbitrary bytes, under each supported extension.
// The first byte picks the format; the rest is the file. Any mrsnake::Error is a correct
// rejection; a crash, a hang, a sanitizer report or another exception is a bug.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

#include "mesh/errors.h"
#include "mesh/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const char* kExtensions[] = {".off", ".obj", ".ply", ".stl", ".vtp", ".vtk"};
  if (size < 1) return 0;
  const std::string path = "/tmp/mrsnake-fuzz-" + std::to_string(getpid()) + kExtensions[data[0] % 6];
  {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const mrsnake::TriMesh mesh = mrsnake::read_mesh(path);
    // A mesh that was accepted must be safe to use.
    if (mesh.F.size() && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.num_vertices())) __builtin_trap();
  } catch (const mrsnake::Error&) {
  }
  std::remove(path.c_str());
  return 0;
}
