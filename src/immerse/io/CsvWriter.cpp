#include "immerse/io/CsvWriter.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"

namespace immerse::io {

namespace {

std::string header_line(const std::vector<std::string>& columns) {
  std::string h;
  for (std::size_t c = 0; c < columns.size(); ++c) h += (c ? "," : "") + columns[c];
  return h;
}

[[noreturn]] void cannot_write(const std::filesystem::path& p, int err) {
  throw WriteError("cannot write " + p.string() + ": " + std::strerror(err));
}

}  // namespace

bool CsvWriter::check_continuable(const std::filesystem::path& path, const std::vector<std::string>& columns) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return false;
  const std::string header = header_line(columns);
  std::ifstream in(path);
  std::string found;
  if (!in || !std::getline(in, found))
    throw InputError("cannot continue " + path.string() + ": " + (in ? "file is empty" : std::strerror(errno)));
  if (found != header)
    throw InputError("cannot continue " + path.string() + ": header is \"" + found + "\", this run writes \"" +
                     header + "\"");
  return true;
}

CsvWriter::CsvWriter(std::filesystem::path path, std::vector<std::string> columns, Mode mode)
    : path_(std::move(path)), columns_(std::move(columns)) {
  if (columns_.empty()) throw std::logic_error("CsvWriter " + path_.string() + ": no columns");
  for (const auto& c : columns_)
    if (c.empty() || c.find_first_of(",\"\n\r") != std::string::npos)
      throw std::logic_error("CsvWriter " + path_.string() + ": bad column name '" + c + "'");
  if (mode != Mode::Append || !check_continuable(path_, columns_))
    AtomicFile::write(path_, header_line(columns_) + "\n");
  fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) cannot_write(path_, errno);
}

CsvWriter::~CsvWriter() {
  if (fd_ >= 0) ::close(fd_);
}

void CsvWriter::row(std::span<const double> values) {
  if (values.size() != columns_.size())
    throw std::logic_error("CsvWriter " + path_.string() + ": row has " + std::to_string(values.size()) +
                           " values, header has " + std::to_string(columns_.size()) + " columns");
  std::string line;
  char buf[32];
  for (std::size_t c = 0; c < values.size(); ++c) {
    std::snprintf(buf, sizeof buf, "%.17g", values[c]);
    if (c) line += ',';
    line += buf;
  }
  line += '\n';
  // One write() per row: the row reaches the file whole, and is visible to readers at once.
  const char* p = line.data();
  std::size_t left = line.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) cannot_write(path_, errno);
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

}  // namespace immerse::io
