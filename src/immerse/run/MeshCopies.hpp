#pragma once
// The mesh files of a run, to be copied into its folder, and the configuration naming the copies
// (mesh_membraneN.msh, mesh_membraneN_reference.msh, N the first membrane using the file; mesh_wallN.stl or
// mesh_wallN.msh for the surface of [[wall]] N), so that the folder runs again as it is. A file several membranes or
// walls use is copied once. With [[wall]] shapes also walls.xdmf, their surfaces triangulated for ParaView
// (io::walls_xdmf).
#include <string>
#include <utility>
#include <vector>

#include "immerse/io/Config.hpp"

namespace immerse {

class WallGeometry;

struct MeshCopies {
  io::Config config;
  std::vector<std::pair<std::string, std::string>> files;  ///< name in the run folder, content

  /// Reads the mesh files of `config` (InputError if one cannot be read); with `walls` (those the run holds), their
  /// surfaces as walls.xdmf.
  static MeshCopies of(const io::Config& config, const WallGeometry* walls);
};

}  // namespace immerse
