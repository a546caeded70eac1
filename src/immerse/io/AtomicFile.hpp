#pragma once
// Atomic file replacement: the content goes to "<name>.tmp.<pid>" in the same directory, is fsync'ed and then
// renamed over <name>, so readers see either the old file or the complete new one, never a partial file.
// On any failure the temporary is removed and a WriteError "cannot write <path>: <errno text>" is thrown.
#include <filesystem>
#include <string>
#include <string_view>

namespace immerse::io {

class AtomicFile {
 public:
  /// Prepares the temporary name; nothing is created yet. Write the content to temp_path() (directly, or through
  /// a library such as HDF5), then call commit().
  explicit AtomicFile(std::filesystem::path final_path);
  ~AtomicFile();  // removes the temporary unless commit() succeeded
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& path() const { return path_; }
  const std::filesystem::path& temp_path() const { return temp_; }

  /// fsyncs the temporary, renames it over path() and fsyncs the directory.
  void commit();
  /// Removes the temporary and throws "cannot write <path>: <strerror(err)>".
  [[noreturn]] void fail(int err);
  /// Removes the temporary and throws "cannot write <path>: <why>".
  [[noreturn]] void fail(const std::string& why);

  /// Writes `contents` to `path` atomically.
  static void write(const std::filesystem::path& path, std::string_view contents);

 private:
  std::filesystem::path path_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

}  // namespace immerse::io
