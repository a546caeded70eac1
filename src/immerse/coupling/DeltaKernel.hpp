#pragma once
// A discrete delta kernel chosen at run time ("roma3" or "peskin4"), and the 3D delta function
// D_h(x) = φ(x/h) φ(y/h) φ(z/h) / h³ of paper eq. (7).
// Verified by: the study delta_moments and the tests DeltaKernel.* (selection by name, eq. 7 as the scaled
// tensor product).
#include <string>
#include <variant>

#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/Peskin4.hpp"
#include "immerse/coupling/RomaPeskin3.hpp"

namespace immerse {

using DeltaKernel = std::variant<RomaPeskin3, Peskin4>;

/// "roma3" or "peskin4"; anything else throws
/// InputError("coupling.kernel = 'x': must be one of roma3, peskin4").
DeltaKernel delta_kernel(const std::string& name);

inline std::string kernel_name(const DeltaKernel& k) {
  return std::visit([](const auto& kk) { return std::string(kk.name); }, k);
}
inline int kernel_width(const DeltaKernel& k) {
  return std::visit([](const auto& kk) { return kk.width; }, k);
}
inline double kernel_support(const DeltaKernel& k) {
  return std::visit([](const auto& kk) { return kk.support; }, k);
}
inline double phi(const DeltaKernel& k, double r) {
  return std::visit([r](const auto& kk) { return kk.phi(r); }, k);
}
/// Eq. (7).
inline double delta_h(const DeltaKernel& k, const Vec3& x, double h) {
  return phi(k, x.x / h) * phi(k, x.y / h) * phi(k, x.z / h) / (h * h * h);
}

}  // namespace immerse
