#pragma once
// Where a membrane element that inverted stands, for the message that stops or rejects a step: ElasticMembrane names
// the element ("element N: Jacobian <= 0 ..."), the operators add its area ratio against the stress-free reference,
// the least of its membrane, and its distance to the nearest wall and to the nearest node of another membrane.
// Computed only once a force evaluation has failed, so a run that does not fail computes nothing more.
#include <array>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "immerse/core/Vec3.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"

namespace immerse {

/// The element an ElasticMembrane inversion message names ("element N: Jacobian ..."), if `what` is one.
std::optional<std::size_t> inverted_element(std::string_view what);

/// The closest node of another membrane: its distance (m) and that membrane's index; infinite when there is none.
struct NearestMembrane {
  double distance = std::numeric_limits<double>::infinity();
  std::size_t membrane = 0;

  /// Takes the closest of `other`'s nodes (membrane `index`) to `nodes` if it is closer (the minimum image along
  /// periodic axes; at equal distance the lower index).
  void consider(const Grid& grid, std::span<const Vec3> nodes, std::span<const Vec3> other, std::size_t index);
};

/// The six nodes of `element` of `membrane` at positions X.
std::array<Vec3, 6> nodes_of_element(const ElasticMembrane& membrane, std::span<const Vec3> X, std::size_t element);

/// "; area ratio R (least of the membrane L, element K), D m from the wall z = W, D2 m from membrane[J]" for element
/// `element` of `membrane` at positions X (the wall part without walls, the last part when `nearest` is infinite).
std::string inversion_details(const Grid& grid, const ElasticMembrane& membrane, std::span<const Vec3> X,
                              std::size_t element, const NearestMembrane& nearest);

}  // namespace immerse
