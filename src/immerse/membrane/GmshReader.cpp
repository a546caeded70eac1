#include "immerse/membrane/GmshReader.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <unordered_map>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/MeshValidation.hpp"

namespace immerse {
namespace {

constexpr int kTriangle3 = 2, kTriangle6 = 9;

int nodes_per_element(int type) {
  // Gmsh element types 1..31 (lines, triangles, quads, tets, hexes, prisms, pyramids, points, higher orders).
  static constexpr int count[] = {0,  2,  3,  4,  4,  8,  6,  5,  3,  6,  9,  10, 27, 18, 14, 1,
                                  8,  20, 15, 13, 9,  10, 12, 15, 15, 21, 4,  5,  6,  20, 35, 56};
  return type >= 1 && type <= 31 ? count[type] : -1;
}

/// A triangle as read: Gmsh element tag and Gmsh node tags (3 or 6).
struct RawTriangle {
  std::size_t tag;
  std::vector<std::size_t> nodes;
};

class Parser {
 public:
  Parser(std::istream& in, const std::string& label) : in_(in), label_(label) {}

  Mesh parse() {
    std::string line;
    bool have_format = false, have_nodes = false, have_elements = false;
    for (bool first = true; std::getline(in_, line); first = false) {
      // A UTF-8 byte-order mark (written by some editors) is not part of the first line.
      if (first && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
      line = trim(line);
      if (line == "$MeshFormat") {
        read_format();
        have_format = true;
      } else if (line == "$Nodes") {
        require_format(have_format);
        v4_ ? read_nodes_v4() : read_nodes_v2();
        expect_end("$EndNodes");
        have_nodes = true;
      } else if (line == "$Elements") {
        require_format(have_format);
        v4_ ? read_elements_v4() : read_elements_v2();
        expect_end("$EndElements");
        have_elements = true;
      } else if (!line.empty() && line[0] == '$' && line.rfind("$End", 0) != 0) {
        skip_section(line.substr(1));
      }
    }
    if (!have_format) fail("no $MeshFormat section (not a Gmsh .msh file?)");
    if (!have_nodes) fail("no $Nodes section");
    if (!have_elements) fail("no $Elements section");
    return assemble();
  }

 private:
  static std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    const auto e = s.find_last_not_of(" \t\r\n");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError("mesh " + echoed(label_) + ": " + what); }
  void require_format(bool have) const {
    if (!have) fail("section before $MeshFormat");
  }

  template <class T>
  T next(const char* what) {
    T v;
    if (!(in_ >> v)) fail(std::string("truncated or malformed file while reading ") + what);
    return v;
  }

  // A count or an id: a non-negative integer (reading "-1" into an unsigned type would wrap it to 2^64 - 1).
  std::size_t whole(const char* what) {
    const auto v = next<long long>(what);
    if (v < 0) fail(std::string(what) + ": " + std::to_string(v) + " given, must be a non-negative integer");
    return static_cast<std::size_t>(v);
  }

  void expect_end(const std::string& end) {
    std::string word;
    if (!(in_ >> word) || word != end)
      fail("expected " + end + (word.empty() ? " but the file ends" : " but found '" + word + "'") +
           " (truncated file or wrong counts)");
  }

  void skip_section(const std::string& name) {
    std::string line;
    while (std::getline(in_, line))
      if (trim(line) == "$End" + name) return;
    fail("section $" + name + " has no $End" + name + " (truncated file)");
  }

  void read_format() {
    const auto version = next<std::string>("$MeshFormat");
    const int file_type = next<int>("$MeshFormat");
    next<int>("$MeshFormat");  // data size
    if (version.rfind("2.", 0) == 0) v4_ = false;
    else if (version == "4.1") v4_ = true;
    else fail("format version " + version + " is not supported (use Gmsh ASCII format 2.2 or 4.1)");
    if (file_type != 0) fail("binary .msh files are not supported (save as ASCII, format 2.2 or 4.1)");
    expect_end("$EndMeshFormat");
  }

  void add_node(std::size_t tag, const Vec3& x) {
    if (!node_index_.emplace(tag, coords_.size()).second) fail("node id " + std::to_string(tag) + " appears twice");
    coords_.push_back(x);
    node_tags_.push_back(tag);
  }

  // Reads one coordinate; "nan" and "inf" are read as such, and so is a value beyond the double range (overflow:
  // infinite, underflow: zero or subnormal), so that validation can name the node.
  double coordinate(std::size_t tag) {
    const auto s = next<std::string>("node coordinates");
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size())
      fail("node id " + std::to_string(tag) + " has a malformed coordinate '" + s + "'");
    return v;
  }

  Vec3 point(std::size_t tag) {
    Vec3 x;
    for (int d = 0; d < 3; ++d) x[d] = coordinate(tag);
    return x;
  }

  void read_nodes_v2() {
    const auto n = whole("$Nodes count");
    for (std::size_t i = 0; i < n; ++i) {
      const auto tag = whole("$Nodes");
      add_node(tag, point(tag));
    }
  }

  void read_nodes_v4() {
    const auto blocks = whole("$Nodes header");
    whole("$Nodes header");
    whole("$Nodes header");
    whole("$Nodes header");
    for (std::size_t b = 0; b < blocks; ++b) {
      const int dim = next<int>("$Nodes block header");
      next<int>("$Nodes block header");
      const int parametric = next<int>("$Nodes block header");  // then each node has `dim` parametric coordinates
      const auto n = whole("$Nodes block header");
      std::vector<std::size_t> tags;  // not sized by the count read: a damaged count must not allocate
      for (std::size_t i = 0; i < n; ++i) tags.push_back(whole("$Nodes block tags"));
      for (auto t : tags) {
        add_node(t, point(t));
        for (int k = 0; k < (parametric ? dim : 0); ++k) next<double>("$Nodes parametric coordinates");
      }
    }
  }

  void add_element(std::size_t tag, int type, const std::vector<std::size_t>& nodes) {
    if (type == kTriangle3 || type == kTriangle6) triangles_.push_back({tag, nodes});
  }

  void read_elements_v2() {
    const auto n = whole("$Elements count");
    for (std::size_t i = 0; i < n; ++i) {
      const auto tag = whole("$Elements");
      const int type = next<int>("$Elements");
      const int nn = nodes_per_element(type);
      if (nn < 0) fail("element id " + std::to_string(tag) + " has unknown Gmsh type " + std::to_string(type));
      const int ntags = next<int>("$Elements");
      for (int k = 0; k < ntags; ++k) next<long>("$Elements tags");
      std::vector<std::size_t> nodes(nn);
      for (auto& v : nodes) v = whole("$Elements node ids");
      add_element(tag, type, nodes);
    }
  }

  void read_elements_v4() {
    const auto blocks = whole("$Elements header");
    for (int k = 0; k < 3; ++k) whole("$Elements header");
    for (std::size_t b = 0; b < blocks; ++b) {
      next<int>("$Elements block header");
      next<int>("$Elements block header");
      const int type = next<int>("$Elements block header");
      const auto n = whole("$Elements block header");
      const int nn = nodes_per_element(type);
      if (nn < 0) fail("element block " + std::to_string(b) + " has unknown Gmsh type " + std::to_string(type));
      std::vector<std::size_t> nodes(nn);
      for (std::size_t i = 0; i < n; ++i) {
        const auto tag = whole("$Elements");
        for (auto& v : nodes) v = whole("$Elements node ids");
        add_element(tag, type, nodes);
      }
    }
  }

  /// Mesh of the triangles, with only the nodes they use (in file order) and promoted 3-node triangles.
  Mesh assemble() {
    if (triangles_.empty()) fail("has no triangles (Gmsh element type 2 or 9)");
    // Gmsh node positions (file order) of every triangle node; unknown ids are an error.
    std::vector<std::vector<std::size_t>> pos(triangles_.size());
    std::vector<int> index(coords_.size(), -1);  // -1: no triangle uses the node
    for (std::size_t e = 0; e < triangles_.size(); ++e)
      for (std::size_t gmsh_node : triangles_[e].nodes) {
        const auto it = node_index_.find(gmsh_node);
        if (it == node_index_.end())
          fail("element " + std::to_string(e) + " (gmsh id " + std::to_string(triangles_[e].tag) +
               ") references unknown node id " + std::to_string(gmsh_node));
        pos[e].push_back(it->second);
        index[it->second] = 0;  // used by a triangle; numbered below
      }
    // Keep the used nodes in file order.
    Mesh mesh;
    MeshIds ids;
    for (std::size_t p = 0; p < coords_.size(); ++p)
      if (index[p] == 0) {
        index[p] = static_cast<int>(mesh.nodes.size());
        mesh.nodes.push_back(coords_[p]);
        ids.nodes.push_back(node_tags_[p]);
      }
    auto key = [](int a, int b) { return (std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b)); };
    std::unordered_map<std::uint64_t, int> midpoint;  // mid-side nodes of the 6-node triangles
    for (std::size_t e = 0; e < triangles_.size(); ++e) {
      std::array<int, 6> el{};
      for (std::size_t k = 0; k < pos[e].size(); ++k) el[k] = index[pos[e][k]];
      if (triangles_[e].nodes.size() == 6)
        for (int k = 0; k < 3; ++k) midpoint.emplace(key(el[k], el[(k + 1) % 3]), el[3 + k]);
      mesh.elements.push_back(el);
      ids.elements.push_back(triangles_[e].tag);
    }
    for (std::size_t e = 0; e < triangles_.size(); ++e) {
      if (triangles_[e].nodes.size() != 3) continue;
      auto& el = mesh.elements[e];
      for (int k = 0; k < 3; ++k) {
        const int a = el[k], b = el[(k + 1) % 3];
        auto [it, inserted] = midpoint.emplace(key(a, b), static_cast<int>(mesh.nodes.size()));
        if (inserted) mesh.nodes.push_back(0.5 * (mesh.nodes[a] + mesh.nodes[b]));  // no Gmsh id
        el[3 + k] = it->second;
      }
    }
    orient_outward_if_finite(mesh);
    validate_closed_mesh(mesh, echoed(label_), ids);
    return mesh;
  }

  static void orient_outward_if_finite(Mesh& mesh) {
    for (const auto& x : mesh.nodes)
      if (!isfinite(x)) return;  // validation reports the node
    orient_outward(mesh);
  }

  std::istream& in_;
  const std::string& label_;
  bool v4_ = false;
  std::vector<Vec3> coords_;  // in file order
  std::vector<std::size_t> node_tags_;
  std::unordered_map<std::size_t, std::size_t> node_index_;
  std::vector<RawTriangle> triangles_;
};

}  // namespace

Mesh read_gmsh(std::istream& in, const std::string& label) { return Parser(in, label).parse(); }

Mesh read_gmsh(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("mesh " + echoed(path) + ": cannot open the file: " + std::strerror(errno));
  if (std::filesystem::is_directory(path))
    throw InputError("mesh " + echoed(path) + ": cannot open the file: it is a directory");
  return read_gmsh(in, path);
}

}  // namespace immerse
