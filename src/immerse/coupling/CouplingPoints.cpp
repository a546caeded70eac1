#include "immerse/coupling/CouplingPoints.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace immerse {

CouplingPoints::CouplingPoints(std::size_t num_nodes) {
  for (std::size_t i = 0; i < num_nodes; ++i) {
    point_node_.push_back(i);
    col_.push_back(i);
    w_.push_back(1.0);
    row_.push_back(col_.size());
  }
}

CouplingPoints::CouplingPoints(const Mesh& fine, const Mesh& coarse) {
  // The points: the fine node at each coarse node's position (found among the fine nodes sorted by x).
  std::vector<std::size_t> by_x(fine.num_nodes());
  for (std::size_t i = 0; i < by_x.size(); ++i) by_x[i] = i;
  std::ranges::sort(by_x, [&](std::size_t a, std::size_t b) { return fine.nodes[a].x < fine.nodes[b].x; });
  std::vector<std::ptrdiff_t> point_of_node(fine.num_nodes(), -1);
  constexpr double kSame = 1e-10;  // on the unit sphere
  for (const auto& p : coarse.nodes) {
    auto it = std::ranges::lower_bound(by_x, p.x - kSame, {}, [&](std::size_t i) { return fine.nodes[i].x; });
    std::ptrdiff_t found = -1;
    for (; it != by_x.end() && fine.nodes[*it].x <= p.x + kSame; ++it)
      if (norm(fine.nodes[*it] - p) <= kSame) found = static_cast<std::ptrdiff_t>(*it);
    if (found < 0 || point_of_node[static_cast<std::size_t>(found)] >= 0)
      throw std::invalid_argument("coupling points: a node of the coarse mesh is not a node of the fine mesh");
    point_of_node[static_cast<std::size_t>(found)] = static_cast<std::ptrdiff_t>(point_node_.size());
    point_node_.push_back(static_cast<std::size_t>(found));
  }
  // Each other node: the coarse element whose flat corner triangle the ray from the centre through the node crosses
  // (the one with the largest smallest barycentric coordinate, for nodes on an edge), then its shape functions.
  for (std::size_t i = 0; i < fine.num_nodes(); ++i) {
    if (point_of_node[i] >= 0) {
      col_.push_back(static_cast<std::size_t>(point_of_node[i]));
      w_.push_back(1.0);
      row_.push_back(col_.size());
      continue;
    }
    const Vec3 p = fine.nodes[i];
    double best = -std::numeric_limits<double>::infinity();
    std::array<double, 3> lambda{};
    std::size_t element = 0;
    for (std::size_t e = 0; e < coarse.num_elements(); ++e) {
      const auto& el = coarse.elements[e];
      const Vec3 a = coarse.nodes[el[0]], b = coarse.nodes[el[1]], c = coarse.nodes[el[2]];
      const Vec3 n = cross(b - a, c - a);
      const double pn = dot(p, n);
      if (pn <= 0.5 * norm(n)) continue;  // a triangle of the unit sphere's far side, or seen edge-on
      const Vec3 q = (dot(a, n) / pn) * p;  // where the ray meets the triangle's plane
      const double l0 = dot(cross(b - q, c - q), n), l1 = dot(cross(c - q, a - q), n), l2 = dot(cross(a - q, b - q), n);
      const double s = dot(n, n);  // l0 + l1 + l2 in exact arithmetic
      const double worst = std::min({l0, l1, l2}) / s;
      const double sum = l0 + l1 + l2;
      if (worst > best) best = worst, element = e, lambda = {l0 / sum, l1 / sum, l2 / sum};
    }
    if (best < -1e-9) throw std::invalid_argument("coupling points: a node lies in no element of the coarse mesh");
    const auto& el = coarse.elements[element];
    const auto [l0, l1, l2] = lambda;
    // Quadratic triangle: vertices λ(2λ − 1), mid-side nodes 4 λa λb (Mesh.hpp's order).
    const std::array<double, 6> N{l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
                                  4 * l0 * l1,       4 * l1 * l2,       4 * l2 * l0};
    for (int k = 0; k < 6; ++k) {
      const auto point = point_of_node[static_cast<std::size_t>(el[k])];
      if (point < 0) throw std::invalid_argument("coupling points: a coarse element's node is not a point");
      col_.push_back(static_cast<std::size_t>(point));
      w_.push_back(N[k]);
    }
    row_.push_back(col_.size());
  }
  every_node_ = false;
}

CouplingPoints CouplingPoints::concatenate(std::span<const CouplingPoints* const> parts) {
  CouplingPoints all;
  for (const CouplingPoints* part : parts) {
    const std::size_t node0 = all.num_nodes(), point0 = all.num_points();
    all.every_node_ = all.every_node_ && part->every_node_;
    for (const auto n : part->point_node_) all.point_node_.push_back(node0 + n);
    for (std::size_t i = 0; i < part->num_nodes(); ++i) {
      for (const auto k : part->columns(i)) all.col_.push_back(point0 + k);
      for (const auto w : part->weights(i)) all.w_.push_back(w);
      all.row_.push_back(all.col_.size());
    }
  }
  return all;
}

void CouplingPoints::gather(std::span<const Vec3> X, std::span<Vec3> Xc) const {
  for (std::size_t k = 0; k < point_node_.size(); ++k) Xc[k] = X[point_node_[k]];
}

void CouplingPoints::restrict_forces(std::span<const Vec3> F, std::span<Vec3> Fc) const {
  std::fill(Fc.begin(), Fc.end(), Vec3{0, 0, 0});
  for (std::size_t i = 0; i + 1 < row_.size(); ++i)
    for (std::size_t j = row_[i]; j < row_[i + 1]; ++j) Fc[col_[j]] += w_[j] * F[i];
}

void CouplingPoints::prolong(std::span<const Vec3> Uc, std::span<Vec3> U) const {
  const std::size_t n = num_nodes();
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 u{0, 0, 0};
    for (std::size_t j = row_[i]; j < row_[i + 1]; ++j) u += w_[j] * Uc[col_[j]];
    U[i] = u;
  }
}

}  // namespace immerse
