#include "immerse/io/Config.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "immerse/core/Error.hpp"
#include "immerse/io/AtomicFile.hpp"
#include "immerse/io/TomlFormat.hpp"

namespace immerse::io {

Config::Config(std::shared_ptr<const ConfigSchema> schema) : schema_(std::move(schema)) {
  for (const auto& k : schema_->keys()) values_.emplace(k.key, k.default_value);
  for (const auto& a : schema_->table_arrays()) tables_.emplace(a.name, std::vector<Config>{});
}

std::string Config::value_text(std::string_view key) const { return format_toml(value(key)); }

std::pair<const Config*, std::string_view> Config::locate(std::string_view key) const {
  if (const auto br = key.find('['); br != std::string_view::npos) {
    const auto close = key.find(']', br);
    if (close == std::string_view::npos || close + 2 > key.size() || key[close + 1] != '.')
      throw std::logic_error("config: malformed key '" + std::string(key) + "'");
    const std::size_t i = std::stoul(std::string(key.substr(br + 1, close - br - 1)));
    return {&entry(key.substr(0, br), i), key.substr(close + 2)};
  }
  return {this, key};
}

bool Config::given(std::string_view key) const {
  const auto [c, k] = locate(key);
  c->value(k);  // declared
  return c->given_.contains(k);
}

std::string Config::derivation(std::string_view key) const {
  const auto [c, k] = locate(key);
  const auto it = c->derivations_.find(k);
  return it == c->derivations_.end() ? std::string() : it->second;
}

void Config::derive(const std::string& key, const std::string& value_text, const std::string& how) {
  const std::string assignment = key + "=" + value_text;
  try {
    schema_->apply_derived(*this, {&assignment, 1});
  } catch (const InputError& e) {
    std::string m = e.what();
    if (m.rfind("--set: ", 0) == 0) m = m.substr(7);
    throw InputError(m + " (derived: " + how + ")");
  }
  const auto [c, k] = locate(key);
  const_cast<Config*>(c)->derivations_[std::string(k)] = how;
}

void Config::leave_out(std::string_view key) {
  const auto [c, k] = locate(key);
  c->value(k);  // declared
  const_cast<Config*>(c)->left_out_.emplace(k);
}

bool Config::left_out(std::string_view key) const {
  const auto [c, k] = locate(key);
  return c->left_out_.contains(k);
}

const ConfigValue& Config::value(std::string_view key) const {
  const auto [c, k] = locate(key);
  const auto it = c->values_.find(k);
  if (it == c->values_.end()) throw std::logic_error("config: key '" + std::string(key) + "' is not declared");
  return it->second;
}

namespace {

template <class T>
const T& typed(const ConfigValue& v, std::string_view key) {
  const T* p = std::get_if<T>(&v);
  if (!p) throw std::logic_error("config: key '" + std::string(key) + "' is read with a type other than declared");
  return *p;
}

bool same(const ConfigValue& a, const ConfigValue& b) {
  if (a.index() != b.index()) return false;
  return std::visit(
      [&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        const T& y = std::get<T>(b);
        if constexpr (std::is_same_v<T, Vec3>)
          return x.x == y.x && x.y == y.y && x.z == y.z;
        else
          return x == y;
      },
      a);
}

}  // namespace

template <> double Config::get<double>(std::string_view key) const { return typed<double>(value(key), key); }
template <> std::int64_t Config::get<std::int64_t>(std::string_view key) const {
  return typed<std::int64_t>(value(key), key);
}
template <> int Config::get<int>(std::string_view key) const {
  const std::int64_t v = typed<std::int64_t>(value(key), key);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    throw InputError(std::string(key) + " = " + std::to_string(v) + ": must be a 32-bit integer");
  return static_cast<int>(v);
}
template <> bool Config::get<bool>(std::string_view key) const { return typed<bool>(value(key), key); }
template <> std::string Config::get<std::string>(std::string_view key) const {
  return typed<std::string>(value(key), key);
}
template <> std::vector<double> Config::get<std::vector<double>>(std::string_view key) const {
  return typed<std::vector<double>>(value(key), key);
}
template <> Vec3 Config::get<Vec3>(std::string_view key) const { return typed<Vec3>(value(key), key); }

std::size_t Config::count(std::string_view name) const {
  const auto it = tables_.find(name);
  if (it == tables_.end()) throw std::logic_error("config: [[" + std::string(name) + "]] is not declared");
  return it->second.size();
}

const Config& Config::entry(std::string_view name, std::size_t i) const {
  if (i >= count(name))
    throw std::logic_error("config: " + std::string(name) + "[" + std::to_string(i) + "] does not exist");
  return tables_.find(name)->second[i];
}

bool Config::operator==(const Config& other) const {
  if (values_.size() != other.values_.size() || tables_ != other.tables_) return false;
  for (const auto& [k, v] : values_) {
    const auto it = other.values_.find(k);
    if (it == other.values_.end() || !same(v, it->second)) return false;
  }
  return true;
}

void Config::write_toml(std::string& out, const std::string& section) const {
  // Keys "a.b.c" go to section [a] as the dotted key "b.c"; undotted keys come first (before any header).
  // Inside a [[table]] entry (section non-empty) every key is written as it is declared.
  const auto line = [&](const KeySpec& k, const std::string& written_key) {
    out += "# " + k.doc + "; " + k.allowed() + "; default " + format_toml(k.default_value) + "\n";
    if (const auto d = derivations_.find(k.key); d != derivations_.end()) out += "# derived: " + d->second + "\n";
    out += written_key + " = " + format_toml(values_.find(k.key)->second) + "\n";
  };
  if (!section.empty()) {
    std::string omitted;
    for (const auto& k : schema_->keys()) {
      if (left_out_.contains(k.key)) omitted += (omitted.empty() ? "" : ", ") + k.key;
      else line(k, k.key);
    }
    if (!omitted.empty()) out += "# left out, as they do not apply to this entry: " + omitted + "\n";
    return;
  }
  std::vector<std::string> sections;
  for (const auto& k : schema_->keys()) {
    const auto dot = k.key.find('.');
    if (dot == std::string::npos) {
      line(k, k.key);
    } else if (std::find(sections.begin(), sections.end(), k.key.substr(0, dot)) == sections.end()) {
      sections.push_back(k.key.substr(0, dot));
    }
  }
  for (const auto& s : sections) {
    out += "\n[" + s + "]\n";
    for (const auto& k : schema_->keys())
      if (k.key.starts_with(s + ".")) line(k, k.key.substr(s.size() + 1));
  }
  for (const auto& a : schema_->table_arrays()) {
    const auto& entries = tables_.find(a.name)->second;
    out += "\n# [[" + a.name + "]]: " + a.doc + " (" + std::to_string(entries.size()) + " given, at least " +
           std::to_string(a.min_count) + ")\n";
    for (const auto& e : entries) {
      out += "[[" + a.name + "]]\n";
      e.write_toml(out, a.name);
    }
  }
}

std::string Config::to_toml_string() const {
  std::string out = "# immerse configuration, fully resolved: every key with its value.\n";
  write_toml(out, "");
  return out;
}

void Config::save(const std::filesystem::path& path) const { AtomicFile::write(path, to_toml_string()); }

}  // namespace immerse::io
