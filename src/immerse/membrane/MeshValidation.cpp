#include "immerse/membrane/MeshValidation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshElement.hpp"

namespace immerse {
namespace {

class Namer {
 public:
  Namer(const std::string& label, const MeshIds& ids) : label_(label), ids_(ids) {}
  std::string element(std::size_t e) const { return named("element", e, ids_.elements); }
  std::string node(std::size_t n) const { return named("node", n, ids_.nodes); }
  [[noreturn]] void fail(const std::string& what) const { throw InputError("mesh " + label_ + ": " + what); }

 private:
  static std::string named(const char* kind, std::size_t i, const std::vector<std::size_t>& ids) {
    std::string s = std::string(kind) + " " + std::to_string(i);
    if (i < ids.size()) s += " (gmsh id " + std::to_string(ids[i]) + ")";
    return s;
  }
  const std::string& label_;
  const MeshIds& ids_;
};

std::string format(const Vec3& x) {
  std::ostringstream s;
  s << "(" << x.x << ", " << x.y << ", " << x.z << ")";
  return s.str();
}

void check_nodes_and_indices(const Mesh& mesh, const Namer& name) {
  if (mesh.elements.empty()) name.fail("has no elements");
  for (std::size_t n = 0; n < mesh.num_nodes(); ++n)
    if (!isfinite(mesh.nodes[n])) name.fail(name.node(n) + " has non-finite coordinates " + format(mesh.nodes[n]));
  std::vector<char> used(mesh.num_nodes(), 0);
  for (std::size_t e = 0; e < mesh.num_elements(); ++e)
    for (int i : mesh.elements[e]) {
      if (i < 0 || static_cast<std::size_t>(i) >= mesh.num_nodes())
        name.fail(name.element(e) + " references unknown node " + std::to_string(i));
      used[i] = 1;
    }
  for (std::size_t n = 0; n < mesh.num_nodes(); ++n)
    if (!used[n]) name.fail(name.node(n) + " is not used by any element");
}

void check_element_shapes(const Mesh& mesh, const Namer& name) {
  for (std::size_t e = 0; e < mesh.num_elements(); ++e) {
    const auto& el = mesh.elements[e];
    for (int i = 0; i < 6; ++i)
      for (int j = i + 1; j < 6; ++j)
        if (el[i] == el[j]) name.fail(name.element(e) + " is degenerate: it uses node " + std::to_string(el[i]) + " twice");
    MeshElement::Nodes x;
    for (int i = 0; i < 6; ++i) x[i] = mesh.nodes[el[i]];
    const Vec3 n = cross(x[1] - x[0], x[2] - x[0]);
    const double longest = std::max({dot(x[1] - x[0], x[1] - x[0]), dot(x[2] - x[1], x[2] - x[1]),
                                     dot(x[0] - x[2], x[0] - x[2])});
    if (!(0.5 * norm(n) > 1e-12 * longest)) name.fail(name.element(e) + " has zero area");
    auto inverted = [&](double xi, double eta) { return !(dot(MeshElement::jacobian(x, xi, eta), n) > 0); };
    bool bad = false;
    for (const auto& p : MeshElement::node_coordinates) bad = bad || inverted(p[0], p[1]);
    for (const auto& q : MeshElement::quadrature) bad = bad || inverted(q.xi, q.eta);
    if (bad) name.fail(name.element(e) + " is inverted: its curved surface folds back (misplaced mid-side node)");
  }
}

void check_edges(const Mesh& mesh, const Namer& name) {
  struct Use {
    std::size_t element;
    int from, mid;  // directed start vertex and the element's mid-side node on this edge
  };
  std::unordered_map<std::uint64_t, std::vector<Use>> edges;
  auto key = [](int a, int b) { return (std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b)); };
  for (std::size_t e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 3; ++k) {
      const auto& el = mesh.elements[e];
      edges[key(el[k], el[(k + 1) % 3])].push_back({e, el[k], el[3 + k]});
    }
  // Report the defect at the lowest-numbered element so that messages do not depend on hashing order.
  std::vector<std::pair<std::size_t, std::string>> defects;
  for (const auto& [k, uses] : edges) {
    const auto a = static_cast<int>(k >> 32), b = static_cast<int>(k & 0xffffffffu);
    const std::string edge = "edge " + std::to_string(a) + "-" + std::to_string(b);
    if (uses.size() == 1)
      defects.emplace_back(uses[0].element, name.element(uses[0].element) + " has " + edge +
                                                " used by no other element: the surface is open");
    else if (uses.size() > 2)
      defects.emplace_back(uses[0].element, name.element(uses[0].element) + " shares " + edge + " with " +
                                                std::to_string(uses.size() - 1) +
                                                " other elements: the surface is non-manifold");
    else if (uses[0].from == uses[1].from)
      defects.emplace_back(uses[1].element, name.element(uses[1].element) + " is oriented inconsistently with " +
                                                name.element(uses[0].element) + " across " + edge);
    else if (uses[0].mid != uses[1].mid)
      defects.emplace_back(uses[1].element, name.element(uses[1].element) + " and " +
                                                name.element(uses[0].element) + " have different mid-side nodes on " +
                                                edge + ": the mesh is not conforming");
  }
  if (!defects.empty()) name.fail(std::min_element(defects.begin(), defects.end())->second);
}

// Elements sharing a vertex belong to one surface; a Gmsh file holding two cells is two surfaces.
void check_one_surface(const Mesh& mesh, const Namer& name) {
  std::vector<std::size_t> parent(mesh.num_nodes());
  for (std::size_t n = 0; n < parent.size(); ++n) parent[n] = n;
  const auto root = [&](std::size_t n) {
    while (parent[n] != n) n = parent[n] = parent[parent[n]];
    return n;
  };
  for (const auto& el : mesh.elements)
    for (int k = 1; k < 6; ++k) parent[root(std::size_t(el[k]))] = root(std::size_t(el[0]));
  std::size_t surfaces = 0;
  for (std::size_t n = 0; n < parent.size(); ++n) surfaces += root(n) == n;
  if (surfaces > 1)
    name.fail("holds " + std::to_string(surfaces) +
              " separate closed surfaces: must be one (give each its own [[membrane]] and file)");
}

}  // namespace

void validate_closed_mesh(const Mesh& mesh, const std::string& label, const MeshIds& ids) {
  const Namer name(label, ids);
  check_nodes_and_indices(mesh, name);
  check_element_shapes(mesh, name);
  check_edges(mesh, name);
  check_one_surface(mesh, name);
  const double v = volume(mesh, mesh.nodes);
  if (!(v > 0))
    name.fail("encloses volume " + std::to_string(v) + ": elements must be counter-clockwise seen from outside");
}

void orient_outward(Mesh& mesh) {
  if (volume(mesh, mesh.nodes) >= 0) return;
  for (auto& el : mesh.elements) el = {el[0], el[2], el[1], el[5], el[4], el[3]};
}

}  // namespace immerse
