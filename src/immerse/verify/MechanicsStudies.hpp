#pragma once
// Verification studies of the membrane mechanics (ElasticMembrane): rigid motion, inflation (Laplace law),
// energy gradient, agreement of the two force methods, momentum conservation, bending.
#include <vector>

#include "immerse/verify/Study.hpp"

namespace immerse::verify {

std::vector<Study> mechanics_studies();

}  // namespace immerse::verify
