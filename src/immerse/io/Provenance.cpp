#include "immerse/io/Provenance.hpp"

#include <unistd.h>

#include <array>
#include <cctype>
#include <ctime>
#include <string_view>

namespace immerse::io {

Provenance Provenance::now(std::string command_line, std::string threads) {
  Provenance p;
  p.version = IMMERSE_VERSION;
  p.commit = build_commit();
  p.command_line = std::move(command_line);
  const std::time_t t = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&t, &utc);
  std::array<char, 32> when{};
  std::strftime(when.data(), when.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
  p.start_time = when.data();
  std::array<char, 256> host{};
  p.host = gethostname(host.data(), host.size() - 1) == 0 ? host.data() : "unknown";
  p.threads = std::move(threads);
  return p;
}

std::string Provenance::quote_command_line(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    bool plain = !a.empty();
    for (const char c : a)
      plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || std::string_view("-_./=:,+@%").find(c) != std::string_view::npos);
    std::string quoted;
    if (plain) {
      quoted = a;
    } else {  // single quotes, each ' written as '\''
      quoted.push_back('\'');
      for (const char c : a) quoted.append(c == '\'' ? "'\\''" : std::string_view(&c, 1));
      quoted.push_back('\'');
    }
    line += (i ? " " : "") + quoted;
  }
  return line;
}

std::vector<std::pair<std::string, std::string>> Provenance::attributes() const {
  std::vector<std::pair<std::string, std::string>> a{{"immerse_version", version}, {"commit", commit},
                                                      {"command_line", command_line}, {"start_time", start_time},
                                                      {"host", host}, {"threads", threads}};
  if (!restarted_from.empty()) a.emplace_back("restarted_from", restarted_from);
  return a;
}

std::string Provenance::toml_comments() const {
  std::string out;
  for (const auto& [name, value] : attributes()) {
    std::string v;  // a comment is one line
    for (const char c : value) v += c == '\n' || c == '\r' ? ' ' : c;
    out += "# " + name + ": " + v + "\n";
  }
  return out;
}

}  // namespace immerse::io
