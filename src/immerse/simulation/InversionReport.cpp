#include "immerse/simulation/InversionReport.hpp"

#include <charconv>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

#include "immerse/membrane/Geometry.hpp"

namespace immerse {

std::optional<std::size_t> inverted_element(std::string_view what) {
  constexpr std::string_view head = "element ", tail = ": Jacobian <= 0";
  if (!what.starts_with(head)) return std::nullopt;
  std::size_t element = 0;
  const char* first = what.data() + head.size();
  const auto [end, ec] = std::from_chars(first, what.data() + what.size(), element);
  if (ec != std::errc() || end == first || !std::string_view(end, what.data() + what.size() - end).starts_with(tail))
    return std::nullopt;
  return element;
}

void NearestMembrane::consider(const Grid& grid, std::span<const Vec3> nodes, std::span<const Vec3> other,
                               std::size_t index) {
  double closest = std::numeric_limits<double>::infinity();
  for (const Vec3& p : other)
    for (const Vec3& q : nodes) {
      Vec3 d = p - q;
      for (int a = 0; a < 3; ++a)
        if (grid.periodic(a)) d[a] -= grid.length(a) * std::nearbyint(d[a] / grid.length(a));
      closest = std::fmin(closest, norm(d));
    }
  if (closest < distance || (closest == distance && index < membrane)) *this = {closest, index};
}

std::array<Vec3, 6> nodes_of_element(const ElasticMembrane& membrane, std::span<const Vec3> X, std::size_t element) {
  std::array<Vec3, 6> x;
  for (int k = 0; k < 6; ++k) x[k] = X[static_cast<std::size_t>(membrane.elements()[element][k])];
  return x;
}

std::string inversion_details(const Grid& grid, const ElasticMembrane& membrane, std::span<const Vec3> X,
                              std::size_t element, const NearestMembrane& nearest) {
  const Mesh mesh{{}, membrane.elements()};
  const auto reference = membrane.reference_element_areas();
  const std::vector<double> areas = element_areas(mesh, X);
  const double ratio = areas[element] / reference[element];
  const LeastAreaRatio least = least_area_ratio(areas, reference);
  std::ostringstream s;
  s.precision(3);
  s << "; area ratio " << ratio << " (least of the membrane " << least.ratio << ", element " << least.element << ")";
  double wall = std::numeric_limits<double>::infinity();
  int axis = -1;
  double at = 0;
  for (const Vec3& x : nodes_of_element(membrane, X, element))
    for (int a = 0; a < 3; ++a) {
      if (grid.periodic(a)) continue;
      const double lo = grid.origin()[a], hi = lo + grid.length(a);
      if (x[a] - lo < wall) wall = x[a] - lo, axis = a, at = lo;
      if (hi - x[a] < wall) wall = hi - x[a], axis = a, at = hi;
    }
  if (axis >= 0) s << ", " << wall << " m from the wall " << axis_name(axis) << " = " << std::setprecision(10) << at
                   << std::setprecision(3);
  if (std::isfinite(nearest.distance))
    s << ", " << nearest.distance << " m from membrane[" << nearest.membrane << "]";
  return s.str();
}

}  // namespace immerse
