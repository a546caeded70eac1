#pragma once
// A CSV table of a run (NAME.csv) with its table of columns (NAME.columns.csv). A run continued in its folder keeps
// the rows written before its checkpoint and appends after them.
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "immerse/io/CsvWriter.hpp"
#include "immerse/run/Column.hpp"

namespace immerse {

class OutputTable {
 public:
  /// keep(row, first value of the row): whether a row written before the checkpoint stays when the run is continued
  /// in its folder (rows count from 0).
  OutputTable(std::string name, std::vector<Column> columns, std::function<bool(long, double)> keep);

  /// Continuing in `dir`: checks the table's header and reads the rows to keep (InputError if the file is damaged).
  /// Reads only.
  void read_kept_rows(const std::filesystem::path& dir);
  /// Writes back the rows read_kept_rows read, if any.
  void write_kept_rows(const std::filesystem::path& dir) const;
  void write_column_table(const std::filesystem::path& dir) const;
  /// Opens NAME.csv for the rows of this run.
  void open(const std::filesystem::path& dir, io::CsvWriter::Mode mode);

  /// Appends a row (after open).
  void row(std::span<const double> values) { writer_->row(values); }
  void row(std::initializer_list<double> values) { writer_->row(values); }

 private:
  std::filesystem::path file(const std::filesystem::path& dir) const { return dir / (name_ + ".csv"); }

  std::string name_;
  std::vector<Column> columns_;
  std::function<bool(long, double)> keep_;
  std::optional<std::string> kept_;
  std::optional<io::CsvWriter> writer_;
};

}  // namespace immerse
