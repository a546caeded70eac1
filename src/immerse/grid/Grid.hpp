#pragma once
// Uniform staggered MAC grid (Kim & Moin arrangement), paper §2.2.
//
// The box [origin, origin + L] is cut into n[0] x n[1] x n[2] cubic cells of size h.
// Pressure lives at cell centres  x_c(i) = origin + (i + 1/2) h,  i = 0..n-1.
// Velocity component d lives on the faces normal to axis d:
//   along axis d:      x_f(i) = origin + i h, with
//                        periodic axis: i = 0..n-1       (face n is face 0)
//                        wall axis:     i = 0..n         (faces 0 and n lie on the walls)
//   along axes e != d: cell-centred, i = 0..n_e-1.
// Each axis is either periodic or bounded by two no-slip walls with prescribed wall velocities.
#include <array>
#include <string>

#include "immerse/core/Vec3.hpp"

namespace immerse {

/// "x", "y" or "z": the name of axis d (0, 1, 2) in keys and messages.
inline const char* axis_name(int d) { return d == 0 ? "x" : d == 1 ? "y" : "z"; }

enum class Boundary { Periodic, Wall };

std::string to_string(Boundary b);

class Grid {
 public:
  /// Validates its input (positive counts, positive lengths, cubic cells) and throws InputError otherwise.
  Grid(std::array<int, 3> n, std::array<double, 3> lengths, std::array<Boundary, 3> bc, Vec3 origin = {});

  const std::array<int, 3>& n() const { return n_; }
  int n(int axis) const { return n_[axis]; }
  double h() const { return h_; }
  double length(int axis) const { return n_[axis] * h_; }
  const Vec3& origin() const { return origin_; }
  Boundary bc(int axis) const { return bc_[axis]; }
  bool periodic(int axis) const { return bc_[axis] == Boundary::Periodic; }
  double cell_volume() const { return h_ * h_ * h_; }

  /// Shape of the array holding velocity component d (faces normal to d).
  std::array<int, 3> face_shape(int d) const;
  /// Shape of cell-centred arrays (pressure).
  const std::array<int, 3>& cell_shape() const { return n_; }

  /// Coordinate along `axis` of a cell centre with index i.
  double cell_center(int axis, int i) const { return origin_[axis] + (i + 0.5) * h_; }
  /// Coordinate along `axis` of a face with index i.
  double face(int axis, int i) const { return origin_[axis] + i * h_; }
  /// Position of the point carrying velocity component d at index (i, j, k).
  Vec3 face_position(int d, int i, int j, int k) const;
  /// Position of the cell centre (i, j, k).
  Vec3 cell_position(int i, int j, int k) const;

 private:
  std::array<int, 3> n_;
  double h_;
  Vec3 origin_;
  std::array<Boundary, 3> bc_;
};

}  // namespace immerse
