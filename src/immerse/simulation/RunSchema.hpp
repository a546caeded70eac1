#pragma once
// Former path of immerse/simulation/Parameters.hpp, kept for programs that include it (docs/library.md); include
// the new path instead.
#include "immerse/simulation/Parameters.hpp"
