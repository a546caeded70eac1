#include "immerse/grid/Grid.hpp"

#include <cmath>
#include <sstream>

#include "immerse/core/Error.hpp"

namespace immerse {

std::string to_string(Boundary b) { return b == Boundary::Periodic ? "periodic" : "wall"; }

Grid::Grid(std::array<int, 3> n, std::array<double, 3> lengths, std::array<Boundary, 3> bc, Vec3 origin)
    : n_(n), h_(0), origin_(origin), bc_(bc) {
  for (int d = 0; d < 3; ++d) {
    require(n[d] >= 2, std::string("grid.n") + axis_name(d), n[d], "an integer >= 2");
    require(std::isfinite(lengths[d]) && lengths[d] > 0, std::string("domain.L") + axis_name(d), lengths[d],
            "a finite length > 0");
  }
  h_ = lengths[0] / n[0];
  for (int d = 1; d < 3; ++d) {
    const double hd = lengths[d] / n[d];
    if (std::abs(hd - h_) > 1e-10 * h_) {
      std::ostringstream s;
      s.precision(10);
      s << "grid: cells must be cubic, but Lx/nx = " << h_ << " and L" << axis_name(d) << "/n" << axis_name(d) << " = "
        << hd << " (choose counts proportional to the lengths)";
      throw InputError(s.str());
    }
  }
}

std::array<int, 3> Grid::face_shape(int d) const {
  std::array<int, 3> s = n_;
  if (!periodic(d)) s[d] += 1;
  return s;
}

Vec3 Grid::face_position(int d, int i, int j, int k) const {
  Vec3 p = cell_position(i, j, k);
  p[d] = face(d, d == 0 ? i : (d == 1 ? j : k));
  return p;
}

Vec3 Grid::cell_position(int i, int j, int k) const {
  return {cell_center(0, i), cell_center(1, j), cell_center(2, k)};
}

}  // namespace immerse
