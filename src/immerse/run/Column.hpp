#pragma once
// A column of a CSV table of a run, and the table of columns written beside the table (NAME.columns.csv).
#include <string>
#include <vector>

namespace immerse {

/// A column of a CSV table: its name, its unit (UDUNITS form, "1" for a pure number) and what it holds.
struct Column {
  std::string name, unit, description;
};

/// The table of columns that is written beside a CSV file (NAME.columns.csv): column,unit,description.
std::string column_table(const std::vector<Column>& columns);

/// The names of `columns`, in order.
std::vector<std::string> column_names(const std::vector<Column>& columns);

}  // namespace immerse
