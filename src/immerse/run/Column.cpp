#include "immerse/run/Column.hpp"

#include <stdexcept>

namespace immerse {

std::string column_table(const std::vector<Column>& columns) {
  std::string out = "column,unit,description\n";
  for (const auto& c : columns) {
    if ((c.name + c.unit + c.description).find_first_of(",\"\n") != std::string::npos)
      throw std::logic_error("column_table: column " + c.name + " has a comma, quote or line break in its text");
    out += c.name + "," + c.unit + "," + c.description + "\n";
  }
  return out;
}

std::vector<std::string> column_names(const std::vector<Column>& columns) {
  std::vector<std::string> names;
  for (const auto& c : columns) names.push_back(c.name);
  return names;
}

}  // namespace immerse
