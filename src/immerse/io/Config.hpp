#pragma once
// A fully resolved configuration: every key its schema declares is present (defaults filled in), each value
// already validated. Built by ConfigSchema::parse_file / parse_string / defaults.
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "immerse/io/ConfigSchema.hpp"

namespace immerse::io {

class Config {
 public:
  /// Typed value of a declared key: "fluid.mu", or "membrane[1].law.Es" inside a repeated table.
  /// T is the declared type: double, std::int64_t (or int), bool, std::string, std::vector<double>, Vec3.
  /// An undeclared key or another type is a programming error (std::logic_error).
  template <class T>
  T get(std::string_view key) const;

  /// The value of a declared key as TOML text ("0.001", "\"yeoh\"", "[1.0, 2.0, 3.0]"), ready for an override.
  std::string value_text(std::string_view key) const;

  /// Number of entries of the repeated table `name` ([[name]]).
  std::size_t count(std::string_view name) const;
  /// Entry i of the repeated table `name`, itself a Config of the entry schema.
  const Config& entry(std::string_view name, std::size_t i) const;

  /// The resolved configuration as TOML, each key preceded by its doc string, allowed values and default.
  /// Parsing it with the same schema gives back an equal Config, up to the keys left out (leave_out).
  std::string to_toml_string() const;
  /// Writes to_toml_string() to `path` atomically (e.g. DIR/config.resolved.toml).
  void save(const std::filesystem::path& path) const;

  /// Whether the user gave `key` (in the file or with --set), as opposed to a default or a derived value.
  bool given(std::string_view key) const;
  /// How a derived key got its value ("scenario.kind = \"capsule_shear\" from scenario.G, ..."), empty if it was
  /// not derived. Written as a comment above the key by to_toml_string().
  std::string derivation(std::string_view key) const;
  /// Sets a key to a derived value (TOML text, as an override) and records how it was derived; the key does not
  /// count as given. InputError ("KEY = VALUE: must be ... (derived: HOW)") if the value is out of range.
  void derive(const std::string& key, const std::string& value_text, const std::string& how);

  /// Marks a key of a [[table]] entry that does not apply (as "membrane[0].radius" to a mesh read from a file):
  /// to_toml_string() names it in a comment instead of writing a value that would read as if it applied.
  void leave_out(std::string_view key);
  bool left_out(std::string_view key) const;

  const ConfigSchema& schema() const { return *schema_; }
  /// Equal values (whether given or derived does not count).
  bool operator==(const Config& other) const;

 private:
  friend class ConfigSchema;
  friend class ConfigResolver;
  explicit Config(std::shared_ptr<const ConfigSchema> schema);
  const ConfigValue& value(std::string_view key) const;
  ConfigValue& value_ref(const std::string& key);
  /// The entry config and the key inside it of "name[i].key"; this and `key` for a plain key.
  std::pair<const Config*, std::string_view> locate(std::string_view key) const;
  void write_toml(std::string& out, const std::string& section) const;

  std::shared_ptr<const ConfigSchema> schema_;
  std::map<std::string, ConfigValue, std::less<>> values_;
  std::map<std::string, std::vector<Config>, std::less<>> tables_;
  std::set<std::string, std::less<>> given_;                        // keys of this table the user gave
  std::map<std::string, std::string, std::less<>> derivations_;     // derived keys of this table: how
  std::set<std::string, std::less<>> left_out_;                     // keys of this table that do not apply
};

template <> double Config::get<double>(std::string_view key) const;
template <> std::int64_t Config::get<std::int64_t>(std::string_view key) const;
template <> int Config::get<int>(std::string_view key) const;
template <> bool Config::get<bool>(std::string_view key) const;
template <> std::string Config::get<std::string>(std::string_view key) const;
template <> std::vector<double> Config::get<std::vector<double>>(std::string_view key) const;
template <> Vec3 Config::get<Vec3>(std::string_view key) const;

}  // namespace immerse::io
