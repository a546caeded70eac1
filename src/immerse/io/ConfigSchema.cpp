#include "immerse/io/ConfigSchema.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <toml++/toml.h>

#include "immerse/core/Error.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/io/TomlFormat.hpp"

namespace immerse::io {

// ---------------------------------------------------------------------------------------------- Range, KeySpec

bool Range::contains(double v) const {
  const bool lo_ok = lo_open_ ? v > lo_ : v >= lo_;
  const bool hi_ok = hi_open_ ? v < hi_ : v <= hi_;
  return lo_ok && hi_ok;
}

std::string Range::describe() const {
  const bool has_lo = lo_ > -kInf, has_hi = hi_ < kInf;
  if (has_lo && has_hi)
    return std::string("in ") + (lo_open_ ? "(" : "[") + format_number(lo_) + ", " + format_number(hi_) +
           (hi_open_ ? ")" : "]");
  if (has_lo) return (lo_open_ ? "> " : ">= ") + format_number(lo_);
  if (has_hi) return (hi_open_ ? "< " : "<= ") + format_number(hi_);
  return "";
}

std::string KeySpec::allowed() const {
  const std::string r = range.describe();
  switch (kind) {
    case Kind::Double: return r.empty() ? "a finite number" : "a finite number " + r;
    case Kind::Int: return r.empty() ? "an integer" : "an integer " + r;
    case Kind::Bool: return "true or false";
    case Kind::String: {
      if (choices.empty()) return "a string";
      std::string s = "one of ";
      for (std::size_t i = 0; i < choices.size(); ++i) s += (i ? ", " : "") + format_toml(choices[i]);
      return s;
    }
    case Kind::DoubleList: return r.empty() ? "a list of finite numbers" : "a list of finite numbers, each " + r;
    case Kind::Vec3: return r.empty() ? "3 finite numbers [x, y, z]" : "3 finite numbers [x, y, z], each " + r;
  }
  return "";
}

bool KeySpec::valid(const ConfigValue& v) const {
  const auto num_ok = [&](double x) { return std::isfinite(x) && range.contains(x); };
  switch (kind) {
    case Kind::Double: return std::holds_alternative<double>(v) && num_ok(std::get<double>(v));
    case Kind::Int:
      return std::holds_alternative<std::int64_t>(v) && range.contains(static_cast<double>(std::get<std::int64_t>(v)));
    case Kind::Bool: return std::holds_alternative<bool>(v);
    case Kind::String:
      return std::holds_alternative<std::string>(v) &&
             (choices.empty() || std::find(choices.begin(), choices.end(), std::get<std::string>(v)) != choices.end());
    case Kind::DoubleList: {
      const auto* l = std::get_if<std::vector<double>>(&v);
      return l && std::all_of(l->begin(), l->end(), num_ok);
    }
    case Kind::Vec3: {
      const auto* p = std::get_if<Vec3>(&v);
      return p && num_ok(p->x) && num_ok(p->y) && num_ok(p->z);
    }
  }
  return false;
}

// ---------------------------------------------------------------------------------------------- declarations

void ConfigSchema::check_new_name(const std::string& name) const {
  bool ok = !name.empty() && name.front() != '.' && name.back() != '.' && name.find("..") == std::string::npos;
  for (const char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.');
  if (!ok) throw std::logic_error("config schema: bad key name '" + name + "'");
  const auto clash = [&](const std::string& other) {
    return other == name || other.starts_with(name + ".") || name.starts_with(other + ".");
  };
  for (const auto& k : keys_)
    if (clash(k.key)) throw std::logic_error("config schema: key '" + name + "' clashes with '" + k.key + "'");
  for (const auto& a : arrays_)
    if (clash(a.name)) throw std::logic_error("config schema: key '" + name + "' clashes with '" + a.name + "'");
}

ConfigSchema& ConfigSchema::add(KeySpec spec) {
  check_new_name(spec.key);
  if (!spec.valid(spec.default_value))
    throw std::logic_error("config schema: default of '" + spec.key + "' is not " + spec.allowed());
  keys_.push_back(std::move(spec));
  return *this;
}

ConfigSchema& ConfigSchema::add_double(std::string key, double def, Range range, std::string doc) {
  return add({std::move(key), KeySpec::Kind::Double, def, range, {}, std::move(doc)});
}
ConfigSchema& ConfigSchema::add_int(std::string key, std::int64_t def, Range range, std::string doc) {
  return add({std::move(key), KeySpec::Kind::Int, def, range, {}, std::move(doc)});
}
ConfigSchema& ConfigSchema::add_bool(std::string key, bool def, std::string doc) {
  return add({std::move(key), KeySpec::Kind::Bool, def, Range::any(), {}, std::move(doc)});
}
ConfigSchema& ConfigSchema::add_string(std::string key, std::string def, std::vector<std::string> choices,
                                       std::string doc) {
  return add({std::move(key), KeySpec::Kind::String, std::move(def), Range::any(), std::move(choices), std::move(doc)});
}
ConfigSchema& ConfigSchema::add_path(std::string key, std::string doc) {
  KeySpec spec{std::move(key), KeySpec::Kind::String, std::string(), Range::any(), {}, std::move(doc)};
  spec.path = true;
  return add(std::move(spec));
}
ConfigSchema& ConfigSchema::add_double_list(std::string key, std::vector<double> def, Range range, std::string doc) {
  return add({std::move(key), KeySpec::Kind::DoubleList, std::move(def), range, {}, std::move(doc)});
}
ConfigSchema& ConfigSchema::add_vec3(std::string key, Vec3 def, Range range, std::string doc) {
  return add({std::move(key), KeySpec::Kind::Vec3, def, range, {}, std::move(doc)});
}
ConfigSchema& ConfigSchema::add_table_array(std::string name, ConfigSchema entry, std::size_t min_count,
                                            std::string doc) {
  check_new_name(name);
  if (!entry.arrays_.empty())
    throw std::logic_error("config schema: [[" + name + "]] entries may not hold repeated tables");
  arrays_.push_back({std::move(name), std::make_shared<const ConfigSchema>(std::move(entry)), min_count, std::move(doc)});
  return *this;
}

const KeySpec* ConfigSchema::find(std::string_view key) const {
  for (const auto& k : keys_)
    if (k.key == key) return &k;
  return nullptr;
}

const ConfigSchema::TableArraySpec* ConfigSchema::find_table_array(std::string_view name) const {
  for (const auto& a : arrays_)
    if (a.name == name) return &a;
  return nullptr;
}

// ---------------------------------------------------------------------------------------------- resolution

namespace {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string last_segment(std::string_view k) {
  const auto dot = k.rfind('.');
  return std::string(dot == std::string_view::npos ? k : k.substr(dot + 1));
}

// " (did you mean fluid.mu?)": a declared name ending in the same key of another table ([time] mu -> fluid.mu), else
// the closest declared name, or "" if none is close.
std::string suggestion(const ConfigSchema& s, const std::string& key, const std::string& display) {
  std::vector<std::string> names;
  for (const auto& k : s.keys()) names.push_back(k.key);
  for (const auto& a : s.table_arrays()) names.push_back(a.name);
  for (const auto& n : names)
    if (last_segment(n) == last_segment(key)) return " (did you mean " + display + n + "?)";
  std::string best;
  std::size_t best_d = std::string::npos;
  for (const auto& n : names) {
    const std::size_t d = edit_distance(key, n);
    if (d < best_d) best_d = d, best = n;
  }
  if (best_d <= std::max<std::size_t>(2, key.size() / 4)) return " (did you mean " + display + best + "?)";
  return "";
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

std::string where(const std::string& source, const toml::source_region& r) {
  return "config " + source + ":" + std::to_string(r.begin.line) + ":" + std::to_string(r.begin.column);
}

// The value as it was written, for messages.
std::string given(const toml::node& n) {
  if (n.is_table()) return "a table";
  if (n.is_array_of_tables()) return "an array of tables";
  if (const auto* str = n.as_string()) return format_toml(str->get());
  std::ostringstream os;
  n.visit([&](const auto& v) { os << v; });
  return one_line(os.str());
}

bool as_number(const toml::node& n, double& out) {
  if (const auto* f = n.as_floating_point()) return out = f->get(), true;
  if (const auto* i = n.as_integer()) return out = static_cast<double>(i->get()), true;
  return false;
}

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return "";
  return std::string(s.substr(b, s.find_last_not_of(" \t") - b + 1));
}

}  // namespace

// Walks parsed TOML and "--set" assignments into a Config (friend of Config).
class ConfigResolver {
 public:
  [[noreturn]] static void reject(const std::string& origin, const std::string& name, const std::string& given_text,
                                  const KeySpec& spec) {
    throw InputError(origin + ": " + name + " = " + echoed(given_text) + ": must be " + spec.allowed());
  }

  static ConfigValue convert(const KeySpec& spec, const toml::node& node, const std::string& name,
                             const std::string& origin, const std::string& given_text) {
    const auto fail = [&] { reject(origin, name, given_text, spec); };
    ConfigValue v;
    double x = 0;
    switch (spec.kind) {
      case KeySpec::Kind::Double:
        if (!as_number(node, x)) fail();
        v = x;
        break;
      case KeySpec::Kind::Int:
        if (!node.is_integer()) fail();
        v = node.as_integer()->get();
        break;
      case KeySpec::Kind::Bool:
        if (!node.is_boolean()) fail();
        v = node.as_boolean()->get();
        break;
      case KeySpec::Kind::String:
        if (!node.is_string()) fail();
        v = node.as_string()->get();
        break;
      case KeySpec::Kind::DoubleList:
      case KeySpec::Kind::Vec3: {
        const toml::array* a = node.as_array();
        if (!a) fail();
        std::vector<double> l;
        for (const auto& e : *a) {
          if (!as_number(e, x)) fail();
          l.push_back(x);
        }
        if (spec.kind == KeySpec::Kind::DoubleList) {
          v = std::move(l);
        } else {
          if (l.size() != 3) fail();
          v = Vec3{l[0], l[1], l[2]};
        }
        break;
      }
    }
    if (!spec.valid(v)) fail();
    return v;
  }

  // `folder`: of the configuration file, against which relative file names are resolved (empty: none).
  static void walk(const toml::table& t, const std::string& prefix, const ConfigSchema& s, Config& out,
                   const std::string& display, const std::string& source, const std::filesystem::path& folder) {
    for (const auto& [k, node] : t) {
      const std::string key = prefix + std::string(k.str());
      const std::string name = display + key;
      if (const KeySpec* spec = s.find(key)) {
        ConfigValue v = convert(*spec, node, name, where(source, node.source()), given(node));
        if (const auto* file = std::get_if<std::string>(&v);
            spec->path && !folder.empty() && !file->empty() && std::filesystem::path(*file).is_relative())
          v = (folder / *file).lexically_normal().string();
        out.values_[key] = std::move(v);
        out.given_.insert(key);
      } else if (const auto* ta = s.find_table_array(key)) {
        const toml::array* a = node.as_array();
        if (!a || !(a->empty() || a->is_array_of_tables()))
          throw InputError(where(source, node.source()) + ": " + name + " = " + echoed(given(node)) +
                           ": must be an array of tables [[" + name + "]]");
        auto& entries = out.tables_[key];
        entries.clear();
        for (std::size_t i = 0; i < a->size(); ++i) {
          Config e(ta->entry);
          walk(*a->get(i)->as_table(), "", *ta->entry, e, name + "[" + std::to_string(i) + "].", source, folder);
          entries.push_back(std::move(e));
        }
      } else if (node.is_table() && declares_prefix(s, key)) {
        walk(*node.as_table(), key + ".", s, out, display, source, folder);
      } else {
        // Name an unknown table by its first key ([fluidd] mu = 1 -> fluidd.mu) so that it can be matched.
        std::string full = key;
        toml::source_region at = k.source();
        for (const toml::node* n = &node; n->is_table() && !n->as_table()->empty();) {
          const auto it = n->as_table()->cbegin();
          full.append(".").append(it->first.str());
          at = it->first.source();
          n = &it->second;
        }
        throw InputError(where(source, at) + ": unknown key " + display + echoed(full) + suggestion(s, full, display));
      }
    }
  }

  static bool declares_prefix(const ConfigSchema& s, const std::string& key) {
    const std::string p = key + ".";
    for (const auto& k : s.keys())
      if (k.key.starts_with(p)) return true;
    for (const auto& a : s.table_arrays())
      if (a.name.starts_with(p)) return true;
    return false;
  }

  static void set(const ConfigSchema& s, Config& cfg, const std::string& assignment, bool given) {
    const auto eq = assignment.find('=');
    if (eq == std::string::npos) throw InputError("--set " + echoed(assignment) + ": must be KEY=VALUE");
    const std::string key = trim(std::string_view(assignment).substr(0, eq));
    const std::string text = trim(std::string_view(assignment).substr(eq + 1));
    if (key.empty())
      throw InputError("--set " + echoed(assignment) + ": must be KEY=VALUE (no key given; see --help-config)");

    const ConfigSchema* schema = &s;
    Config* target = &cfg;
    std::string display, rel = key;
    if (const auto br = key.find('['); br != std::string::npos) {
      const std::string name = key.substr(0, br);
      const auto close = key.find(']', br);
      const auto* ta = s.find_table_array(name);
      if (!ta || close == std::string::npos || close + 2 > key.size() || key[close + 1] != '.')
        throw InputError("--set: unknown key " + echoed(key) + suggestion(s, name, ""));
      const std::string idx_text = key.substr(br + 1, close - br - 1);
      auto& entries = cfg.tables_[name];
      std::size_t idx = 0;
      const bool digits = !idx_text.empty() && idx_text.size() < 10 &&
                          std::all_of(idx_text.begin(), idx_text.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (digits) idx = std::stoul(idx_text);
      if (!digits || idx > entries.size())
        throw InputError("--set: " + echoed(key) + ": index " + echoed(idx_text) + " given: must be in [0, " +
                         std::to_string(entries.size()) + "] (" + std::to_string(entries.size()) +
                         " adds an entry)");
      if (idx == entries.size()) entries.emplace_back(Config(ta->entry));
      target = &entries[idx];
      schema = ta->entry.get();
      display = name + "[" + idx_text + "].";
      rel = key.substr(close + 2);
    }
    const KeySpec* spec = schema->find(rel);
    if (!spec) throw InputError("--set: unknown key " + echoed(key) + suggestion(*schema, rel, display));

    // String keys take bare text (--set time.scheme=jfnk) as well as TOML strings.
    if (spec->kind == KeySpec::Kind::String && (text.empty() || (text[0] != '"' && text[0] != '\''))) {
      if (!spec->valid(text)) reject("--set", key, format_toml(text), *spec);
      target->values_[rel] = text;
      if (given) target->given_.insert(rel);
      return;
    }
    toml::table parsed;
    try {
      parsed = toml::parse("v = " + text);
    } catch (const toml::parse_error&) {
      reject("--set", key, text, *spec);
    }
    const toml::node* node = parsed.get("v");
    if (!node || parsed.size() != 1) reject("--set", key, text, *spec);
    target->values_[rel] = convert(*spec, *node, key, "--set", text);
    if (given) target->given_.insert(rel);
  }

  // set() writes its value only once it is valid, but for a table array's new entry it adds the entry first: that
  // entry is removed again when the assignment fails, so one assignment either applies or leaves cfg as it was.
  static void set_or_leave(const ConfigSchema& s, Config& cfg, const std::string& assignment, bool given) {
    std::map<std::string, std::size_t> sizes;
    for (const auto& [name, entries] : cfg.tables_) sizes[name] = entries.size();
    try {
      set(s, cfg, assignment, given);
    } catch (...) {
      std::erase_if(cfg.tables_, [&](const auto& t) { return !sizes.contains(t.first); });
      for (auto& [name, entries] : cfg.tables_)
        entries.erase(entries.begin() + static_cast<std::ptrdiff_t>(sizes[name]), entries.end());
      throw;
    }
  }

  static void check_counts(const ConfigSchema& s, const Config& cfg, const std::string& origin) {
    for (const auto& a : s.table_arrays()) {
      const std::size_t n = cfg.count(a.name);
      if (n < a.min_count)
        throw InputError(origin + ": [[" + a.name + "]] given " + std::to_string(n) + " times: must be at least " +
                         std::to_string(a.min_count));
    }
  }
};

Config ConfigSchema::defaults() const { return Config(std::make_shared<const ConfigSchema>(*this)); }

void ConfigSchema::apply_overrides(Config& config, std::span<const std::string> overrides) const {
  Config updated = config;
  for (const auto& o : overrides) ConfigResolver::set(*this, updated, o, true);
  config = std::move(updated);
}

void ConfigSchema::apply_derived(Config& config, std::span<const std::string> assignments) const {
  // One assignment (Config::derive, once per derived key: a copy each time would make deriving N cells O(N^2)).
  if (assignments.size() == 1) return ConfigResolver::set_or_leave(*this, config, assignments[0], false);
  Config updated = config;
  for (const auto& a : assignments) ConfigResolver::set(*this, updated, a, false);
  config = std::move(updated);
}

Config ConfigSchema::parse_string(std::string_view toml, const std::string& source,
                                  std::span<const std::string> overrides) const {
  return parse(toml, source, {}, overrides);
}

Config ConfigSchema::parse(std::string_view toml, const std::string& source, const std::filesystem::path& folder,
                           std::span<const std::string> overrides) const {
  toml::table table;
  try {
    table = toml::parse(toml, source);
  } catch (const toml::parse_error& e) {
    throw InputError(where(source, e.source()) + ": " + one_line(std::string(e.description())));
  }
  Config cfg = defaults();
  ConfigResolver::walk(table, "", *this, cfg, "", source, folder);
  apply_overrides(cfg, overrides);
  ConfigResolver::check_counts(*this, cfg, "config " + source);
  return cfg;
}

Config ConfigSchema::parse_file(const std::filesystem::path& file, std::span<const std::string> overrides) const {
  const auto unreadable = [&](int err) {
    return InputError("config " + file.string() + ": cannot read: " + std::strerror(err));
  };
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw unreadable(errno);
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw unreadable(err);
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > kMaxFileBytes) {
      ::close(fd);
      throw InputError("config " + file.string() + ": larger than " + std::to_string(kMaxFileBytes >> 20) +
                       " MiB: not a configuration file");
    }
  }
  ::close(fd);
  return parse(text, file.string(), std::filesystem::absolute(file).parent_path(), overrides);
}

void ConfigSchema::print_help(std::ostream& os) const {
  const auto key_help = [&](const KeySpec& k, const std::string& prefix) {
    os << "  " << prefix << k.key << " = " << format_toml(k.default_value) << "\n      " << k.doc << "; "
       << k.allowed() << "\n";
  };
  for (const auto& k : keys_) key_help(k, "");
  for (const auto& a : arrays_) {
    os << "  [[" << a.name << "]]  repeated table, " << a.doc << " (at least " << a.min_count << " entries)\n";
    for (const auto& k : a.entry->keys()) key_help(k, a.name + "[i].");
  }
}

}  // namespace immerse::io
