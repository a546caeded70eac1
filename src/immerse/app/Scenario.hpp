#pragma once
// Former path of immerse/scenario/Scenario.hpp, kept for programs that include it (docs/library.md); include the
// new path instead.
#include "immerse/scenario/Scenario.hpp"
