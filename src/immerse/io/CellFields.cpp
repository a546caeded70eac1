#include "immerse/io/CellFields.hpp"

#include <cmath>

#include "immerse/io/CellFields_K.hpp"

namespace immerse::io {

CellFields CellFields::from_faces(const Grid& grid, const FaceField& u) {
  const auto& n = grid.n();
  CellFields out;
  for (int d = 0; d < 3; ++d) out.velocity[d] = Array3(n[0], n[1], n[2]);
  out.vorticity_magnitude = Array3(n[0], n[1], n[2]);

#pragma omp parallel for
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (int d = 0; d < 3; ++d)
          out.velocity[d](i, j, k) = face_to_cell_K(u[d], d, n[d], grid.periodic(d), i, j, k);

  const auto& c = out.velocity;
  const double h = grid.h();
  const auto D = [&](int comp, int axis, int i, int j, int k) {
    return cell_derivative_K(c[comp], axis, n[axis], grid.periodic(axis), h, i, j, k);
  };
#pragma omp parallel for
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const double wx = D(2, 1, i, j, k) - D(1, 2, i, j, k);
        const double wy = D(0, 2, i, j, k) - D(2, 0, i, j, k);
        const double wz = D(1, 0, i, j, k) - D(0, 1, i, j, k);
        out.vorticity_magnitude(i, j, k) = std::sqrt(wx * wx + wy * wy + wz * wz);
      }
  return out;
}

}  // namespace immerse::io
