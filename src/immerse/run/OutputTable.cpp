#include "immerse/run/OutputTable.hpp"

#include <cstdlib>
#include <fstream>
#include <utility>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"

namespace immerse {

namespace {

// The header and the data rows r = 0, 1, ... of a CSV file for which keep(r, first number of the row) holds;
// nothing if the file does not exist. Reads only.
std::optional<std::string> rows_to_keep(const std::filesystem::path& path,
                                        const std::function<bool(long, double)>& keep) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::string line, kept;
  for (long r = -1; std::getline(in, line); ++r) {
    if (r >= 0) {
      char* end = nullptr;
      const double first = std::strtod(line.c_str(), &end);
      if (end == line.c_str() || (*end != ',' && *end != '\0'))
        throw InputError("cannot continue " + path.string() + ": line " + std::to_string(r + 2) +
                         " is not a row of numbers (damaged file)");
      if (!keep(r, first)) continue;
    }
    kept += line + "\n";
  }
  return kept;
}

}  // namespace

OutputTable::OutputTable(std::string name, std::vector<Column> columns, std::function<bool(long, double)> keep)
    : name_(std::move(name)), columns_(std::move(columns)), keep_(std::move(keep)) {}

void OutputTable::read_kept_rows(const std::filesystem::path& dir) {
  io::CsvWriter::check_continuable(file(dir), column_names(columns_));
  kept_ = rows_to_keep(file(dir), keep_);
}

void OutputTable::write_kept_rows(const std::filesystem::path& dir) const {
  if (kept_) io::AtomicFile::write(file(dir), *kept_);
}

void OutputTable::write_column_table(const std::filesystem::path& dir) const {
  io::AtomicFile::write(dir / (name_ + ".columns.csv"), column_table(columns_));
}

void OutputTable::open(const std::filesystem::path& dir, io::CsvWriter::Mode mode) {
  writer_.emplace(file(dir), column_names(columns_), mode);
}

}  // namespace immerse
