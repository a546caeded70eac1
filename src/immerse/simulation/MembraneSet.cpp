#include "immerse/simulation/MembraneSet.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "immerse/contact/CellPacking.hpp"
#include "immerse/contact/MembraneClearance.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/GmshReader.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/MeshValidation.hpp"
#include "immerse/membrane/NeoHookean.hpp"
#include "immerse/membrane/Shape.hpp"
#include "immerse/membrane/Skalak.hpp"
#include "immerse/membrane/Yeoh.hpp"
#include "immerse/simulation/ConfigSetup.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

std::string membrane_name(std::size_t m) { return "membrane[" + std::to_string(m) + "]"; }

namespace {

Shape shape_of(const io::Config& m, bool reference) {
  Shape s;
  if (reference && m.get<std::string>("reference") == "sphere") {
    s.form = Sphere{m.get<double>("reference_radius")};
  } else {
    const std::string kind = m.get<std::string>("shape");
    if (kind == "sphere") s.form = Sphere{m.get<double>("radius")};
    else if (kind == "ellipsoid") {
      const Vec3 ax = m.get<Vec3>("semi_axes");
      s.form = Ellipsoid{ax.x, ax.y, ax.z};
    } else if (kind == "oblate") {
      s.form = OblateSpheroid{m.get<double>("radius"), m.get<double>("aspect_ratio"), m.get<double>("inclination")};
    } else {
      BiconcaveCell rbc;
      rbc.R0 = m.get<double>("R0");
      s.form = rbc;
    }
  }
  const Vec3 axis = m.get<Vec3>("rotation_axis");
  const double angle = m.get<double>("rotation_angle");
  if (angle != 0.0) {
    require(norm(axis) > 0, "rotation_axis", "a non-zero vector");
    s.placement.rotation = rotation_about(axis, angle);
  }
  s.placement.translation = m.get<Vec3>("center");
  return s;
}

MaterialLaw in_plane_law_of(const io::Config& m) {
  const std::string law = m.get<std::string>("law");
  if (law == "neo_hookean") return NeoHookean(m.get<double>("Es"));
  if (law == "yeoh") return Yeoh(m.get<double>("C10"), m.get<double>("C30"));
  return Skalak(m.get<double>("C11"), m.get<double>("C21"));
}

MaterialLaw law_of(const io::Config& m) {
  return with_area_dilation(in_plane_law_of(m), m.get<double>("dilation_modulus"));
}

// mesh.reference_file must be mesh.file in another shape: the same nodes joined into the same elements.
void check_same_elements(const Mesh& reference, const Mesh& mesh) {
  const std::string same = ": must be the mesh of mesh.file in another shape (the same nodes and elements)";
  const auto count = [](std::size_t n, const char* what) { return std::to_string(n) + " " + what; };
  if (reference.num_nodes() != mesh.num_nodes())
    throw InputError("mesh.reference_file: has " + count(reference.num_nodes(), "nodes") + ", mesh.file " +
                     count(mesh.num_nodes(), "nodes") + same);
  if (reference.num_elements() != mesh.num_elements())
    throw InputError("mesh.reference_file: has " + count(reference.num_elements(), "elements") + ", mesh.file " +
                     count(mesh.num_elements(), "elements") + same);
  for (std::size_t e = 0; e < mesh.num_elements(); ++e)
    if (reference.elements[e] != mesh.elements[e]) {
      const auto nodes = [](const std::array<int, 6>& el) {
        std::string s;
        for (int n : el) s += (s.empty() ? "" : " ") + std::to_string(n);
        return s;
      };
      throw InputError("mesh.reference_file: element " + std::to_string(e) + " joins nodes " +
                       nodes(reference.elements[e]) + ", in mesh.file " + nodes(mesh.elements[e]) + same);
    }
}

// For a mesh read from a file, the likely reason it does not fit the box: another length unit.
std::string unit_hint(const io::Config& config, std::size_t m) {
  return config.get<std::string>(membrane_name(m) + ".mesh.family") == "file"
             ? " (is the mesh file in another unit? mesh.scale converts it to metres, e.g. 1e-6 for micrometres)"
             : "";
}

// The construction steps, each adding to or checking the membranes built so far.
class Builder {
 public:
  Builder(const io::Config& config, const Grid& grid, std::shared_ptr<const WallGeometry> walls,
          const std::function<bool()>& stop_requested)
      : config_(config), grid_(grid), walls_(std::move(walls)), stop_requested_(stop_requested) {}
  MembraneSet build() {
    build_membranes();
    pack_membranes();
    check_geometry();
    return {std::move(meshes_),           std::move(references_),      std::move(initial_),
            std::move(membranes_),        std::move(corrected_volume_), std::move(viscosity_ratio_),
            std::move(packing_summary_)};
  }

 private:
  void build_membranes();
  void add_membrane(const io::Config& m, Mesh mesh, std::vector<Vec3> initial, std::vector<Vec3> reference);
  void pack_membranes();
  void check_geometry() const;

  const io::Config& config_;
  const Grid& grid_;
  std::shared_ptr<const WallGeometry> walls_;  // null without [[wall]]
  const std::function<bool()>& stop_requested_;
  std::vector<Mesh> meshes_;
  std::vector<std::vector<Vec3>> references_, initial_;
  std::vector<std::unique_ptr<ElasticMembrane>> membranes_;
  std::vector<std::optional<double>> corrected_volume_;
  std::vector<double> viscosity_ratio_;
  std::string packing_summary_;
};

void Builder::build_membranes() {
  for (std::size_t i = 0; i < config_.count("membrane"); ++i) {
    const io::Config& m = config_.entry("membrane", i);
    const std::string name = membrane_name(i);
    try {
      const std::string family = m.get<std::string>("mesh.family");
      const int level = m.get<int>("mesh.level");
      Mesh mesh;
      std::vector<Vec3> initial, reference;
      if (family == "file") {
        // A user's mesh is the initial shape itself, its length unit times mesh.scale, placed by center and rotation;
        // its reference is the same shape, the reference sphere over the directions of its nodes (for star-shaped
        // meshes), or the shape of mesh.reference_file, scaled and placed alike.
        const std::string file = m.get<std::string>("mesh.file");
        require(!file.empty(), "mesh.file", "a Gmsh file name when mesh.family = \"file\"");
        const double scale = m.get<double>("mesh.scale");
        const RigidTransform place = shape_of(m, false).placement;
        const auto placed = [&](const Mesh& read) {
          std::vector<Vec3> X;
          for (const auto& p : read.nodes) X.push_back(place.rotation * (scale * p) + place.translation);
          return X;
        };
        mesh = read_gmsh(file);
        initial = placed(mesh);
        const std::string kind = m.get<std::string>("reference");
        if (kind == "sphere") {
          if (!encloses(mesh, mesh.nodes, Vec3{0, 0, 0}))
            throw InputError("reference = \"sphere\": the origin of mesh.file must lie inside the mesh (the reference "
                             "sphere maps each node's direction from it: the mesh must be star-shaped about its origin)");
          std::vector<Vec3> unit;
          for (const auto& p : mesh.nodes) unit.push_back(normalized(p));
          reference = map_sphere(shape_of(m, true), unit);
        } else if (kind == "file") {
          const std::string reference_file = m.get<std::string>("mesh.reference_file");
          require(!reference_file.empty(), "mesh.reference_file", "a Gmsh file name when reference = \"file\"");
          const Mesh stress_free = read_gmsh(reference_file);
          check_same_elements(stress_free, mesh);
          reference = placed(stress_free);
        } else {
          reference = initial;
        }
      } else {
        mesh = family == "icosahedral" ? icosahedral_sphere(level) : octahedral_sphere(level);
        initial = map_sphere(shape_of(m, false), mesh.nodes);
        reference = map_sphere(shape_of(m, true), mesh.nodes);
      }
      mesh.nodes = initial;
      validate_closed_mesh(mesh, name);
      add_membrane(m, std::move(mesh), std::move(initial), std::move(reference));
    } catch (const InputError& e) {
      // A key of the entry becomes membrane[i].key; the membrane's own "membrane reference element 3" becomes
      // "membrane[i] reference element 3".
      const std::string what = e.what();
      throw InputError(what.rfind("membrane ", 0) == 0 ? name + what.substr(8) : name + "." + what);
    }
  }
}

void Builder::add_membrane(const io::Config& m, Mesh mesh, std::vector<Vec3> initial, std::vector<Vec3> reference) {
  Bending bending{m.get<double>("kappa_B"), m.get<std::string>("bending_reference") == "rest"
                                                 ? ReferenceCurvature::RestShape
                                                 : ReferenceCurvature::Zero};
  membranes_.push_back(std::make_unique<ElasticMembrane>(
      mesh, reference, law_of(m), bending,
      m.get<std::string>("force") == "energy" ? ForceMethod::Energy : ForceMethod::Contour,
      ConstraintModuli{m.get<double>("volume_modulus"), m.get<double>("area_modulus")}));
  corrected_volume_.push_back(m.get<std::string>("volume_correction") == "normal_shift"
                                  ? std::optional<double>(volume(mesh, initial))
                                  : std::nullopt);
  viscosity_ratio_.push_back(m.get<double>("viscosity_ratio"));
  meshes_.push_back(std::move(mesh));
  references_.push_back(std::move(reference));
  initial_.push_back(std::move(initial));
}

// [packing]: membrane[0] is the template; its copies replace it, placed by CellPacking.
void Builder::pack_membranes() {
  const double fraction = config_.get<double>("packing.volume_fraction");
  const auto count = config_.get<std::int64_t>("packing.count");
  if (fraction == 0 && count == 0) return;
  if (fraction > 0 && count > 0)
    throw InputError("packing.count = " + std::to_string(count) + " and packing.volume_fraction = " +
                     config_.value_text("packing.volume_fraction") + ": give only one of them");
  const char* key = count > 0 ? "packing.count" : "packing.volume_fraction";
  if (config_.count("membrane") != 1)
    throw InputError(std::string(key) + ": packs copies of one [[membrane]] entry, the template; " +
                     std::to_string(config_.count("membrane")) + " are given");
  // The template's placement must be the default one (as config.resolved.toml records it): the packer's replaces it.
  const io::Config& t = config_.entry("membrane", 0);
  Vec3 box_centre;
  for (int a = 0; a < 3; ++a) box_centre[a] = grid_.origin()[a] + 0.5 * grid_.length(a);
  const Vec3 centre = t.get<Vec3>("center");
  for (const auto& [k, placed] : {std::pair{"center", norm(centre - box_centre) > 1e-9 * grid_.h()},
                                  std::pair{"rotation_angle", t.get<double>("rotation_angle") != 0}})
    if (placed)
      throw InputError(std::string("membrane[0].") + k + " = " + t.value_text(k) + ": does not apply with " + key +
                       " (the packer places and turns the copies)");
  const Mesh tmpl = meshes_[0];
  const MembraneGeometry g = measure(tmpl, initial_[0]);
  std::vector<Vec3> shape, reference;
  for (const auto& p : initial_[0]) shape.push_back(p - g.centroid);
  for (const auto& p : references_[0]) reference.push_back(p - g.centroid);
  double spacing = 0;  // along the element edges, vertex to mid-side node
  for (const auto& e : tmpl.elements)
    for (const auto& [a, b] : {std::pair{0, 3}, {3, 1}, {1, 4}, {4, 2}, {2, 5}, {5, 0}})
      spacing = std::max(spacing, norm(shape[e[a]] - shape[e[b]]));
  PackingRequest request;
  request.walls = walls_;
  double box = 1;  // the fluid's volume
  for (int a = 0; a < 3; ++a) box *= grid_.length(a);
  if (request.walls) box = request.walls->fluid_volume(grid_);
  request.count = count > 0 ? static_cast<std::size_t>(count) : static_cast<std::size_t>(std::llround(fraction * box / g.volume));
  if (request.count == 0)
    throw InputError("packing.volume_fraction = " + config_.value_text("packing.volume_fraction") +
                     ": less than one cell of volume " + io::format_number(g.volume) + " m^3 in this box");
  request.seed = static_cast<std::uint64_t>(config_.get<std::int64_t>("packing.seed"));
  const double clearance = config_.get<double>("packing.clearance");
  request.clearance = clearance > 0 ? clearance : 1.1 * grid_.h();
  request.stop_requested = stop_requested_;
  const auto t0 = std::chrono::steady_clock::now();
  const CellPacking packing(grid_, shape, spacing, request, key);
  std::ostringstream summary;
  summary << "packing: " << request.count << " copies of membrane[0], volume fraction " << (request.walls ? "of the fluid " : "")
          << static_cast<double>(request.count) * g.volume / box << " (seed " << request.seed << "), in "
          << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s";
  packing_summary_ = summary.str();
  const io::Config& m = config_.entry("membrane", 0);
  meshes_.clear();
  references_.clear();
  initial_.clear();
  membranes_.clear();
  corrected_volume_.clear();
  viscosity_ratio_.clear();
  for (const auto& place : packing.placements()) {
    Mesh mesh = tmpl;
    std::vector<Vec3> X, R;
    for (const auto& p : shape) X.push_back(place.rotation * p + place.translation);
    for (const auto& p : reference) R.push_back(place.rotation * p + place.translation);
    mesh.nodes = X;
    add_membrane(m, std::move(mesh), std::move(X), std::move(R));
  }
}

void Builder::check_geometry() const {
  const double h = grid_.h();
  for (std::size_t m = 0; m < initial_.size(); ++m) {
    const auto& X = initial_[m];
    try {
      check_nodes_in_domain(grid_, X);
    } catch (const SimulationError& e) {
      throw InputError(membrane_name(m) + " lies outside the box: " + e.what() + unit_hint(config_, m));
    }
    for (int a = 0; a < 3; ++a) {
      if (!grid_.periodic(a)) continue;  // between walls the nodes are checked against the walls
      const auto [lo, hi] =
          std::minmax_element(X.begin(), X.end(), [&](const Vec3& p, const Vec3& q) { return p[a] < q[a]; });
      if ((*hi)[a] - (*lo)[a] >= grid_.length(a)) {
        std::ostringstream s;
        s << membrane_name(m) << " spans " << (*hi)[a] - (*lo)[a] << " m along " << axis_name(a)
          << ": must be shorter than the periodic box (" << grid_.length(a) << " m)" << unit_hint(config_, m);
        throw InputError(s.str());
      }
    }
    if (const auto pair = self_intersection(meshes_[m], X))
      throw InputError(membrane_name(m) + ": its surface intersects itself (elements " + std::to_string(pair->first) +
                       " and " + std::to_string(pair->second) + ")");
    const double d = min_wall_distance(grid_, X);
    if (d < h) {
      std::ostringstream s;
      s << membrane_name(m) << " comes within " << d << " m of a wall: must keep at least one cell (" << h
        << " m) clear for the delta function" << unit_hint(config_, m);
      throw InputError(s.str());
    }
  }
  if (walls_) {
    const std::shared_ptr<const WallGeometry>& walls = walls_;
    for (std::size_t m = 0; m < initial_.size(); ++m) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Vec3& x : initial_[m]) nearest = std::min(nearest, walls->distance(x));
      if (nearest < h) {
        std::ostringstream s;
        s << membrane_name(m) << (nearest <= 0 ? " starts inside a [[wall]] (a node " : " comes within ")
          << std::abs(nearest) << (nearest <= 0 ? " m deep" : " m of a [[wall]]")
          << "): must keep at least one cell (" << h << " m) clear of the walls" << unit_hint(config_, m);
        throw InputError(s.str());
      }
    }
  }
  if (const auto gap = closest_foreign_nodes(grid_, initial_, h)) {
    std::ostringstream s;
    s << membrane_name(gap->membrane_a) << " overlaps or touches " << membrane_name(gap->membrane_b) << ": its node "
      << gap->node_a << " is " << gap->distance << " m from node " << gap->node_b << " of "
      << membrane_name(gap->membrane_b) << ", closer than one cell (" << h << " m)";
    throw InputError(s.str());
  }
  // Without close nodes two closed surfaces are apart or nested: test one node of each against the other.
  std::vector<std::pair<Vec3, Vec3>> boxes;
  for (const auto& X : initial_) {
    Vec3 lo = X[0], hi = X[0];
    for (const auto& p : X)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    boxes.emplace_back(lo, hi);
  }
  auto nested = [&](std::size_t inner, std::size_t outer) {
    const auto& [lo, hi] = boxes[outer];
    const Vec3 mid = 0.5 * (lo + hi), p = mid + minimum_image(grid_, initial_[inner][0], mid);
    for (int k = 0; k < 3; ++k)
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
    return encloses(meshes_[outer], initial_[outer], p);
  };
  for (std::size_t m = 0; m < initial_.size(); ++m)
    for (std::size_t o = 0; o < m; ++o) {
      if (nested(m, o)) throw InputError(membrane_name(m) + " lies inside " + membrane_name(o));
      if (nested(o, m)) throw InputError(membrane_name(o) + " lies inside " + membrane_name(m));
    }
}

}  // namespace

MembraneSet build_membrane_set(const io::Config& config, const Grid& grid, std::shared_ptr<const WallGeometry> walls,
                               const std::function<bool()>& stop_requested) {
  return Builder(config, grid, std::move(walls), stop_requested).build();
}

}  // namespace immerse
