#include "immerse/run/MeshCopies.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/io/TomlFormat.hpp"

namespace immerse {

MeshCopies MeshCopies::of(const io::Config& config) {
  MeshCopies copies{config, {}};
  std::map<std::filesystem::path, std::string> copy_of;  // the source file -> the name of its copy
  for (std::size_t i = 0; i < config.count("membrane"); ++i)
    for (const std::string key : {"mesh.file", "mesh.reference_file"}) {
      const std::string k = "membrane[" + std::to_string(i) + "]." + key;
      const std::string source = config.get<std::string>(k);
      if (config.left_out(k) || source.empty()) continue;
      std::error_code ec;
      const std::filesystem::path full = std::filesystem::weakly_canonical(std::filesystem::absolute(source), ec);
      const auto [it, added] = copy_of.emplace(
          full, "mesh_membrane" + std::to_string(i) + (key == "mesh.file" ? "" : "_reference") + ".msh");
      if (added) {
        std::ifstream in(source, std::ios::binary);
        std::ostringstream content;
        content << in.rdbuf();
        if (!in || ec) throw InputError(k + " " + source + ": cannot read the file to copy it into the run folder");
        copies.files.emplace_back(it->second, content.str());
      }
      copies.config.derive(k, io::format_toml(it->second), "the copy of " + full.string() + " in the run folder");
    }
  // The surface files of the walls: mesh_wallN.msh for a Gmsh file (by its name), mesh_wallN.stl otherwise.
  for (std::size_t i = 0; i < config.count("wall"); ++i) {
    const std::string k = "wall[" + std::to_string(i) + "].file";
    const std::string source = config.get<std::string>(k);
    if (config.left_out(k) || source.empty()) continue;
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::weakly_canonical(std::filesystem::absolute(source), ec);
    const std::string extension = std::filesystem::path(source).extension() == ".msh" ? ".msh" : ".stl";
    const auto [it, added] = copy_of.emplace(full, "mesh_wall" + std::to_string(i) + extension);
    if (added) {
      std::ifstream in(source, std::ios::binary);
      std::ostringstream content;
      content << in.rdbuf();
      if (!in || ec) throw InputError(k + " " + source + ": cannot read the file to copy it into the run folder");
      copies.files.emplace_back(it->second, content.str());
    }
    copies.config.derive(k, io::format_toml(it->second), "the copy of " + full.string() + " in the run folder");
  }
  return copies;
}

}  // namespace immerse
