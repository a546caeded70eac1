#pragma once
// Declaration of every configuration key: its dotted name, type, default, allowed values and a doc string
// (with units). A schema parses a TOML file plus "--set key=value" overrides into a fully resolved Config and
// rejects bad input with one line naming the key, what was given and what is allowed (immerse::InputError):
//
//   config run.toml:12:5: fluid.mu = -1: must be a finite number > 0
//   config run.toml:3:1: unknown key fluid.muu (did you mean fluid.mu?)
//   --set: time.scheme = "rk4": must be one of "euler", "rk2", "jfnk", "bfgs", "lbfgs", "anderson"
//
// Repeated items are arrays of tables ([[membrane]]): each entry is validated against its own schema and named
// membrane[i] in messages, getters and overrides (--set membrane[0].mesh.level=3).
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "immerse/core/Vec3.hpp"

namespace immerse::io {

class Config;

/// Allowed interval of a number (or of every component of a list / vector).
class Range {
 public:
  static Range any() { return {}; }
  static Range positive() { return greater_than(0); }
  static Range non_negative() { return at_least(0); }
  static Range greater_than(double a) { return {a, kInf, true, false}; }
  static Range at_least(double a) { return {a, kInf, false, false}; }
  static Range less_than(double b) { return {-kInf, b, false, true}; }
  static Range at_most(double b) { return {-kInf, b, false, false}; }
  static Range closed(double a, double b) { return {a, b, false, false}; }      // [a, b]
  static Range open(double a, double b) { return {a, b, true, true}; }          // (a, b)
  static Range closed_open(double a, double b) { return {a, b, false, true}; }  // [a, b)
  static Range open_closed(double a, double b) { return {a, b, true, false}; }  // (a, b]

  bool contains(double v) const;
  /// "> 0", ">= 1", "in [0, 1)", or "" for any.
  std::string describe() const;

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  Range() = default;
  Range(double lo, double hi, bool lo_open, bool hi_open) : lo_(lo), hi_(hi), lo_open_(lo_open), hi_open_(hi_open) {}
  double lo_ = -kInf, hi_ = kInf;
  bool lo_open_ = false, hi_open_ = false;
};

using ConfigValue = std::variant<double, std::int64_t, bool, std::string, std::vector<double>, Vec3>;

/// One declared key.
struct KeySpec {
  enum class Kind { Double, Int, Bool, String, DoubleList, Vec3 };
  std::string key;  // dotted name relative to its schema, e.g. "fluid.mu" or (in [[membrane]]) "mesh.level"
  Kind kind;
  ConfigValue default_value;
  Range range = Range::any();
  std::vector<std::string> choices;  // allowed strings (empty: any string)
  std::string doc;
  bool path = false;  // a file name: a relative one in a configuration file is taken from that file's folder

  /// What is allowed, as it reads after "must be": "a finite number > 0", "one of \"a\", \"b\"", ...
  std::string allowed() const;
  bool valid(const ConfigValue& v) const;
};

class ConfigSchema {
 public:
  ConfigSchema& add_double(std::string key, double def, Range range, std::string doc);
  ConfigSchema& add_int(std::string key, std::int64_t def, Range range, std::string doc);
  ConfigSchema& add_bool(std::string key, bool def, std::string doc);
  /// `choices` empty: any string.
  ConfigSchema& add_string(std::string key, std::string def, std::vector<std::string> choices, std::string doc);
  /// A file name (a string): relative names in a configuration file are resolved against the file's folder by
  /// parse_file; elsewhere (--set, parse_string) they stay as given, relative to the current folder.
  ConfigSchema& add_path(std::string key, std::string doc);
  /// A list of numbers, each within `range`.
  ConfigSchema& add_double_list(std::string key, std::vector<double> def, Range range, std::string doc);
  /// Three numbers [x, y, z], each within `range`.
  ConfigSchema& add_vec3(std::string key, Vec3 def, Range range, std::string doc);
  /// A repeated table [[name]] whose entries follow `entry` (which may not itself hold repeated tables).
  ConfigSchema& add_table_array(std::string name, ConfigSchema entry, std::size_t min_count, std::string doc);

  /// Every key at its default, no repeated-table entries.
  Config defaults() const;
  /// Largest configuration file read (a few kB is usual): beyond it the file is refused, not read to its end.
  static constexpr std::size_t kMaxFileBytes = std::size_t{1} << 20;

  /// Reads and validates a TOML file, then applies the overrides ("key=value", value in TOML syntax; string
  /// keys also take bare text). Relative file names (add_path) written in the file become names under its folder.
  /// Throws InputError on any bad input.
  Config parse_file(const std::filesystem::path& file, std::span<const std::string> overrides = {}) const;
  /// As parse_file, from TOML text; `source` names it in messages ("config <source>:line:col: ...").
  Config parse_string(std::string_view toml, const std::string& source,
                      std::span<const std::string> overrides = {}) const;
  /// Applies "key=value" overrides to a resolved configuration (messages start with "--set: "); the keys count as
  /// given by the user.
  void apply_overrides(Config& config, std::span<const std::string> overrides) const;
  /// As apply_overrides, for values derived from others (the keys do not count as given).
  void apply_derived(Config& config, std::span<const std::string> assignments) const;

  /// Every key with its default, what is allowed and its doc string (for --help-config).
  void print_help(std::ostream& os) const;

  struct TableArraySpec {
    std::string name;
    std::shared_ptr<const ConfigSchema> entry;
    std::size_t min_count;
    std::string doc;
  };
  const std::vector<KeySpec>& keys() const { return keys_; }
  const std::vector<TableArraySpec>& table_arrays() const { return arrays_; }
  const KeySpec* find(std::string_view key) const;
  const TableArraySpec* find_table_array(std::string_view name) const;

 private:
  ConfigSchema& add(KeySpec spec);
  Config parse(std::string_view toml, const std::string& source, const std::filesystem::path& folder,
               std::span<const std::string> overrides) const;
  void check_new_name(const std::string& name) const;

  std::vector<KeySpec> keys_;
  std::vector<TableArraySpec> arrays_;
};

}  // namespace immerse::io
