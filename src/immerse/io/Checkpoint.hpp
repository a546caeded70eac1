#pragma once
// A restart checkpoint: a generic container of named double arrays (stored 1D, with a "shape" attribute),
// int64 scalars, doubles and strings (e.g. the resolved configuration TOML) that the simulation fills.
// It is written as one HDF5 file, atomically, with a format version and an FNV-1a-64 checksum over all
// entries in canonical order. Reading verifies both and refuses, with one line, anything else:
//   checkpoint run/ck.h5 is corrupted: checksum mismatch
//   checkpoint run/ck.h5 was written by format version 3, this program reads version 1
//   checkpoint run/ck.h5 is truncated or not an HDF5 file
// so that no partial or damaged data is ever returned.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace immerse::io {

class Checkpoint {
 public:
  static constexpr std::int64_t kFormatVersion = 1;

  /// Names are unique across all kinds and may not contain '/'. `shape` defaults to {values.size()};
  /// its product must equal values.size().
  void put_array(const std::string& name, std::vector<double> values, std::vector<std::size_t> shape = {});
  void put_int(const std::string& name, std::int64_t value);
  void put_double(const std::string& name, double value);
  void put_string(const std::string& name, std::string value);

  /// Removes an entry of any kind (nothing if there is none).
  void erase(const std::string& name);

  bool has(const std::string& name) const;
  /// Throws InputError "checkpoint <source>: <name> <what>", for entries that are present but unusable.
  [[noreturn]] void invalid(const std::string& name, const std::string& what) const;
  /// The getters throw InputError "checkpoint <source>: no <kind> named <name>" for a missing entry.
  const std::vector<double>& array(const std::string& name) const;
  const std::vector<std::size_t>& shape(const std::string& name) const;
  std::int64_t get_int(const std::string& name) const;
  double get_double(const std::string& name) const;
  const std::string& get_string(const std::string& name) const;

  /// String attributes written on the file's root beside the entries (the run's provenance); not entries: they
  /// are neither checksummed nor compared, and reading does not return them.
  void set_attributes(std::vector<std::pair<std::string, std::string>> attributes) {
    attributes_ = std::move(attributes);
  }

  /// The file it was read from ("(in memory)" for one built by the program).
  const std::string& source() const { return source_; }

  /// FNV-1a-64 over every entry in canonical order (kind, then name).
  std::uint64_t checksum() const;
  /// Bitwise equality of all entries.
  bool operator==(const Checkpoint& other) const;

  /// Writes the whole checkpoint to `path` atomically (InputError "cannot write <path>: ..." on failure).
  void write(const std::filesystem::path& path) const;
  /// Reads and verifies a checkpoint (InputError on any problem, see above).
  static Checkpoint read(const std::filesystem::path& path);

 private:
  struct Array {
    std::vector<double> values;
    std::vector<std::size_t> shape;
  };
  void check_new_name(const std::string& name) const;
  [[noreturn]] void missing(const std::string& kind, const std::string& name) const;

  std::map<std::string, Array> arrays_;
  std::map<std::string, std::int64_t> ints_;
  std::map<std::string, double> doubles_;
  std::map<std::string, std::string> strings_;
  std::vector<std::pair<std::string, std::string>> attributes_;
  std::string source_ = "(in memory)";
};

}  // namespace immerse::io
