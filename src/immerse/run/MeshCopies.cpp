#include "immerse/run/MeshCopies.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/io/XdmfWriter.hpp"
#include "immerse/simulation/ConfigSetup.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

MeshCopies MeshCopies::of(const io::Config& config, const WallGeometry* walls) {
  MeshCopies copies{config, {}};
  std::map<std::filesystem::path, std::string> copy_of;  // the source file -> the name of its copy
  // Copies the file of key k (unless left out or empty) as `name`, once per source file, and names the copy in k.
  const auto copy = [&](const std::string& k, const std::string& name) {
    const std::string source = config.get<std::string>(k);
    if (config.left_out(k) || source.empty()) return;
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::weakly_canonical(std::filesystem::absolute(source), ec);
    const auto [it, added] = copy_of.emplace(full, name);
    if (added) {
      std::ifstream in(source, std::ios::binary);
      std::ostringstream content;
      content << in.rdbuf();
      if (!in || ec) throw InputError(k + " " + source + ": cannot read the file to copy it into the run folder");
      copies.files.emplace_back(it->second, content.str());
    }
    copies.config.derive(k, io::format_toml(it->second), "the copy of " + full.string() + " in the run folder");
  };
  for (std::size_t i = 0; i < config.count("membrane"); ++i)
    for (const std::string key : {"mesh.file", "mesh.reference_file"})
      copy("membrane[" + std::to_string(i) + "]." + key,
           "mesh_membrane" + std::to_string(i) + (key == "mesh.file" ? "" : "_reference") + ".msh");
  // The surface files of the walls: mesh_wallN.msh for a Gmsh file (by its name), mesh_wallN.stl otherwise.
  for (std::size_t i = 0; i < config.count("wall"); ++i) {
    const std::string k = "wall[" + std::to_string(i) + "].file";
    const bool gmsh = std::filesystem::path(config.get<std::string>(k)).extension() == ".msh";
    copy(k, "mesh_wall" + std::to_string(i) + (gmsh ? ".msh" : ".stl"));
  }
  // The walls as ParaView sees them: walls.xdmf, their triangulated surfaces inline.
  if (walls) {
    copies.files.emplace_back("walls.xdmf", io::walls_xdmf(*walls, run_grid(config).h()));
  }
  return copies;
}

}  // namespace immerse
