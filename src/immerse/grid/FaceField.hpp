#pragma once
// A vector field on the staggered faces of a Grid: component d on the faces normal to axis d
// (see Grid.hpp for the layout). Velocity and the spread force both use it.
#include <array>

#include "immerse/core/Array3.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

class FaceField {
 public:
  FaceField() = default;
  explicit FaceField(const Grid& g) {
    for (int d = 0; d < 3; ++d) {
      const auto s = g.face_shape(d);
      c_[d] = Array3(s[0], s[1], s[2]);
    }
  }
  Array3& operator[](int d) { return c_[d]; }
  const Array3& operator[](int d) const { return c_[d]; }
  void fill(double v) {
    for (auto& a : c_) a.fill(v);
  }

 private:
  std::array<Array3, 3> c_;
};

}  // namespace immerse
