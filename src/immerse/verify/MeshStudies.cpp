#include "immerse/verify/MeshStudies.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/MeshValidation.hpp"
#include "immerse/membrane/Shape.hpp"
#include "immerse/verify/Convergence.hpp"

namespace immerse::verify {
namespace {

constexpr double pi = std::numbers::pi;

std::vector<Check> mesh_counts(bool quick) {
  struct Expected {
    Mesh (*generate)(int);
    const char* family;
    int level;
    std::size_t nodes, elements;
  };
  std::vector<Expected> cases{
      {icosahedral_sphere, "icosahedral", 2, 642, 320},    {icosahedral_sphere, "icosahedral", 3, 2562, 1280},
      {icosahedral_sphere, "icosahedral", 4, 10242, 5120}, {octahedral_sphere, "octahedral", 2, 258, 128},
      {octahedral_sphere, "octahedral", 3, 1026, 512},     {octahedral_sphere, "octahedral", 4, 4098, 2048},
      {octahedral_sphere, "octahedral", 5, 16386, 8192}};
  if (!quick) {  // the finest meshes of both families: 10·4^(k+1) + 2 and 4·4^(k+1) + 2 nodes
    cases.push_back({icosahedral_sphere, "icosahedral", 6, 163842, 81920});
    cases.push_back({octahedral_sphere, "octahedral", 7, 262146, 131072});
  }
  double count_mismatches = 0, invalid = 0;
  for (const auto& c : cases) {
    const Mesh m = c.generate(c.level);
    count_mismatches += (m.num_nodes() != c.nodes) + (m.num_elements() != c.elements);
    try {
      validate_closed_mesh(m, std::string(c.family) + " level " + std::to_string(c.level));
    } catch (const InputError&) {
      invalid += 1;
    }
  }
  return {{"node and element count mismatches (" + std::to_string(cases.size()) + " meshes)", count_mismatches,
           "<=", 0},
          {"generated meshes failing validate_closed_mesh", invalid, "<=", 0}};
}

std::vector<Check> sphere_geometry(bool quick) {
  std::vector<Check> checks;
  const int finest = quick ? 3 : 5;
  using Generator = Mesh (*)(int);
  for (auto [generate, family] : {std::pair<Generator, const char*>{icosahedral_sphere, "icosahedral"},
                                  {octahedral_sphere, "octahedral"}}) {
    std::vector<double> area_err, vol_err;
    double weight_err = 0;
    for (int level = 1; level <= finest; ++level) {
      const Mesh m = generate(level);
      const MembraneGeometry g = measure(m, m.nodes);
      area_err.push_back(std::fabs(g.area - 4 * pi));
      vol_err.push_back(std::fabs(g.volume - 4 * pi / 3));
      const auto w = node_area_weights(m, m.nodes);
      weight_err = std::fmax(weight_err, std::fabs(std::accumulate(w.begin(), w.end(), 0.0) - g.area) / g.area);
    }
    const std::string levels = " (levels 1-" + std::to_string(finest) + ")";
    checks.push_back({std::string(family) + " unit sphere: order of the area error" + levels,
                      min_observed_order(area_err), ">=", 3.0});
    checks.push_back({std::string(family) + " unit sphere: order of the volume error" + levels,
                      min_observed_order(vol_err), ">=", 3.0});
    checks.push_back({std::string(family) + ": |sum of node area weights - area| / area", weight_err, "<=", 1e-12});
  }

  // Ellipsoid of §4.1 (eq. 43), rotated and translated: volume and equivalent-ellipsoid semi-axes.
  const Mesh fine_ico = icosahedral_sphere(quick ? 3 : 5);
  const Ellipsoid ell{0.25, 0.22, 0.2};
  const Shape ellipsoid{ell, {rotation_about({1, 2, 3}, 0.7), {0.5, 0.45, 0.55}}};
  const MembraneGeometry ge = measure(fine_ico, map_sphere(ellipsoid, fine_ico.nodes));
  const double v_ell = 4 * pi / 3 * ell.a * ell.b * ell.c;
  checks.push_back({"ellipsoid (0.25,0.22,0.2): relative volume error", std::fabs(ge.volume - v_ell) / v_ell, "<=", 1e-3});
  double axis_err = 0;
  for (int k = 0; k < 3; ++k) axis_err = std::fmax(axis_err, std::fabs(ge.semi_axes[k] - std::array{ell.a, ell.b, ell.c}[k]));
  checks.push_back({"ellipsoid (0.25,0.22,0.2): max semi-axis error", axis_err, "<=", 1e-3});

  // Biconcave red blood cell of eq. (45), R0 = 3.91 µm: volume 94.09 µm³, area 134.09 µm² (notes).
  const Mesh fine_oct = octahedral_sphere(quick ? 4 : 5);
  const MembraneGeometry gr = measure(fine_oct, map_sphere(Shape{BiconcaveCell{}, {}}, fine_oct.nodes));
  checks.push_back({"red blood cell: relative volume error vs 94.09 um^3", std::fabs(gr.volume - 94.09) / 94.09, "<=", 1e-3});
  checks.push_back({"red blood cell: relative area error vs 134.09 um^2", std::fabs(gr.area - 134.09) / 134.09, "<=", 1e-3});
  return checks;
}

}  // namespace

std::vector<Study> mesh_studies() {
  return {
      {"mesh_counts", "node/element counts of the icosahedral and octahedral sphere meshes; all meshes valid",
       mesh_counts},
      {"sphere_geometry",
       "curved-element area/volume order on the unit sphere; ellipsoid volume and axes; RBC (eq. 45) volume and area",
       sphere_geometry},
  };
}

}  // namespace immerse::verify
