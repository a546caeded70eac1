// Writes the configuration reference (docs/reference/configuration.md) from the schema's declarations:
// every key of `immerse run`, grouped by table, with its default, what is allowed and its doc string.
//
//   build/release/immerse-config-reference > docs/reference/configuration.md
//
// The test docs.configuration_reference fails when the committed page differs from this program's output.
#include <iostream>
#include <string>
#include <string_view>

#include "immerse/io/ConfigSchema.hpp"
#include "immerse/io/TomlFormat.hpp"
#include "immerse/simulation/Parameters.hpp"

namespace {

// Markdown table cells: a '|' would end the cell.
std::string cell(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

// Plain text in a cell: '*' would start emphasis ("10*4^l").
std::string text_cell(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '*') out += '\\';
    out += c;
  }
  return cell(out);
}

std::string code(std::string_view text) {
  std::string out(1, '`');
  out.append(text);
  out.push_back('`');
  return out;
}

void table_head(std::ostream& os) {
  os << "| key | default | allowed | meaning |\n| --- | --- | --- | --- |\n";
}

void row(std::ostream& os, const immerse::io::KeySpec& k, const std::string& prefix) {
  os << "| " << cell(code(prefix + k.key)) << " | " << cell(code(immerse::io::format_toml(k.default_value))) << " | "
     << text_cell(k.allowed()) << " | " << text_cell(k.doc) << " |\n";
}

std::string table_of(const std::string& key) {
  const auto dot = key.find('.');
  return dot == std::string::npos ? std::string() : key.substr(0, dot);
}

}  // namespace

int main() {
  const immerse::io::ConfigSchema schema = immerse::run_schema();
  std::ostream& os = std::cout;
  os << "# Configuration reference\n\n"
        "Every key of an `immerse run` configuration file, with its default, what is allowed and its meaning\n"
        "(SI units unless the key says otherwise). This page is generated from the program's schema by\n"
        "`build/release/immerse-config-reference > docs/reference/configuration.md`; the test\n"
        "`docs.configuration_reference` fails when it differs from the program. The same list, as plain text, is\n"
        "printed by `immerse run FILE --help-config`. How the file is written, how `--set` works and what bad input\n"
        "gives: [Configuration](../configuration.md).\n";
  std::string current = "\x01";
  for (const auto& k : schema.keys()) {
    const std::string t = table_of(k.key);
    if (t != current) {
      current = t;
      os << "\n## " << (t.empty() ? std::string("Top level") : "`[" + t + "]`") << "\n\n";
      table_head(os);
    }
    row(os, k, "");
  }
  for (const auto& a : schema.table_arrays()) {
    os << "\n## `[[" << a.name << "]]`\n\nA repeated table: " << a.doc << " (";
    if (a.min_count == 0)
      os << "any number of entries";
    else
      os << "at least " << a.min_count << (a.min_count == 1 ? " entry" : " entries");
    os << "). Each entry takes these keys; on the command line entry i is `" << a.name << "[i].KEY`.\n\n";
    table_head(os);
    for (const auto& k : a.entry->keys()) row(os, k, "");
  }
  return 0;
}
