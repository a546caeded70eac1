#pragma once
// Diagnostics table as CSV: a header line, then one row of numbers per call, each written at full precision
// (%.17g, so a row re-reads to the same doubles) and flushed to the file at once.
//
// Mode::Create replaces any existing file (atomically, with just the header); Mode::Append continues a
// restarted run: the existing file must start with the same header (otherwise InputError naming the file, the
// header found and the header expected); a missing file is created as in Create.
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace immerse::io {

class CsvWriter {
 public:
  enum class Mode { Create, Append };

  CsvWriter(std::filesystem::path path, std::vector<std::string> columns, Mode mode = Mode::Create);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  /// Appends one row; `values` must have one entry per column (std::logic_error otherwise).
  void row(std::span<const double> values);
  void row(std::initializer_list<double> values) { row(std::span<const double>(values.begin(), values.size())); }

  /// Whether `path` exists with the header of `columns` (false: it does not exist; InputError as for Mode::Append
  /// if it exists with another header or none). Reads only.
  static bool check_continuable(const std::filesystem::path& path, const std::vector<std::string>& columns);

  const std::filesystem::path& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }

 private:
  std::filesystem::path path_;
  std::vector<std::string> columns_;
  int fd_ = -1;
};

}  // namespace immerse::io
