#include "immerse/coupling/DeltaKernel.hpp"

#include "immerse/core/Error.hpp"

namespace immerse {

DeltaKernel delta_kernel(const std::string& name) {
  if (name == RomaPeskin3::name) return RomaPeskin3{};
  if (name == Peskin4::name) return Peskin4{};
  throw InputError("coupling.kernel = '" + name + "': must be one of roma3, peskin4");
}

}  // namespace immerse
