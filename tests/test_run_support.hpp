#pragma once
// Shared by the tests/test_run_*.cpp programs: the real `immerse` program of this build tree started as a child
// process (exit status and output captured), a scratch directory, a small oscillating-membrane configuration
// (16^3 grid, 66-node membrane: fast also under AddressSanitizer) and readers of the run's outputs.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "immerse/membrane/Mesh.hpp"

extern char** environ;

namespace immerse::testing {

namespace fs = std::filesystem;

/// build/<preset>/immerse, next to the tests/ folder holding this test program.
inline fs::path immerse_program() { return fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "immerse"; }

inline fs::path scenario_file(const std::string& name) { return fs::path(IMMERSE_SOURCE_DIR) / "scenarios" / name; }

/// A fresh empty directory, removed with everything in it at the end of the test.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "immerse_" + tag + "_" + (info ? std::string(info->name()) : "suite") + "_" +
                       std::to_string(getpid());
    for (char& c : name)
      if (c == '/') c = '_';
    path_ = fs::temp_directory_path() / name;
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() { fs::remove_all(path_); }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

/// The index of column `name` in a CSV header row (a test failure, and the row's length, if it is not there).
inline std::size_t column(const std::vector<std::string>& head, const std::string& name) {
  const auto it = std::find(head.begin(), head.end(), name);
  EXPECT_NE(it, head.end()) << name;
  return static_cast<std::size_t>(it - head.begin());
}

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A started `immerse ARGS...` with its stdout and stderr going to files.
/// Whether process `pid` catches SIGTERM (its handler is installed: SigCgt of /proc/PID/status has bit 15).
inline bool catches_sigterm(pid_t pid) {
  std::istringstream status(read_text("/proc/" + std::to_string(pid) + "/status"));
  for (std::string line; std::getline(status, line);)
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (SIGTERM - 1)) & 1u;
  return false;
}

class ImmerseProcess {
 public:
  /// `env`: NAME=VALUE entries set for the child (replacing inherited ones of the same name); a bare NAME removes it.
  /// `stdout_fd` >= 0: the child's standard output goes there (e.g. a pipe) instead of the log file.
  ImmerseProcess(const std::vector<std::string>& args, const fs::path& log_prefix,
                 const std::vector<std::string>& env = {}, int stdout_fd = -1)
      : out_(log_prefix.string() + ".stdout"), err_(log_prefix.string() + ".stderr") {
    std::vector<std::string> argv_s{immerse_program().string()};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    // The child starts PETSc and OpenMPI, whose plugins leak at exit: LeakSanitizer (sanitizer build) would turn
    // every exit status into its own. The rest of the inherited environment is kept.
    std::vector<std::string> env_s;
    std::string asan = "ASAN_OPTIONS=detect_leaks=0";
    auto overridden = [&](const std::string& v) {
      for (const auto& e : env) {
        const auto eq = e.find('=');
        if (v.rfind(eq == std::string::npos ? e + "=" : e.substr(0, eq + 1), 0) == 0) return true;
      }
      return false;
    };
    for (char** e = environ; *e; ++e) {
      const std::string v = *e;
      if (v.rfind("ASAN_OPTIONS=", 0) == 0) asan = v + ":detect_leaks=0";
      else if (!overridden(v)) env_s.push_back(v);
    }
    env_s.push_back(asan);
    for (const auto& e : env)
      if (e.find('=') != std::string::npos) env_s.push_back(e);
    std::vector<char*> envp;
    for (auto& v : env_s) envp.push_back(v.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    if (stdout_fd >= 0)
      posix_spawn_file_actions_adddup2(&actions, stdout_fd, STDOUT_FILENO);
    else
      posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int rc = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + argv_s[0]);
  }
  ~ImmerseProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  ImmerseProcess(const ImmerseProcess&) = delete;
  ImmerseProcess& operator=(const ImmerseProcess&) = delete;

  void signal(int sig) const { kill(pid_, sig); }
  pid_t pid() const { return pid_; }
  /// Waits for the end: the exit status, or 128 + the signal that killed it.
  int wait() {
    int st = 0;
    waitpid(pid_, &st, 0);
    pid_ = -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  }
  /// The status as wait() gives it if the program has ended, -1 while it runs.
  int try_wait() {
    int st = 0;
    if (waitpid(pid_, &st, WNOHANG) != pid_) return -1;
    pid_ = -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  }
  std::string out() const { return read_text(out_); }
  std::string err() const { return read_text(err_); }

 private:
  pid_t pid_ = -1;
  fs::path out_, err_;
};

struct RunResult {
  int status;
  std::string out, err;
};

/// Runs `immerse ARGS...` to its end (`env` as for ImmerseProcess).
inline RunResult run_immerse(const std::vector<std::string>& args, const fs::path& log_prefix,
                             const std::vector<std::string>& env = {}) {
  ImmerseProcess p(args, log_prefix, env);
  const int status = p.wait();
  return {status, p.out(), p.err()};
}

/// `--set` arguments turning oscillating_membrane_quick.toml (or file_membrane_toml) into a small run of `steps` steps
/// of dt (default 0.125; 16^3 grid, unit box) whose membrane is not generated.
inline std::vector<std::string> small_run_sets(int steps, double dt = 0.125) {
  return {"grid.nx=16", "grid.ny=16", "grid.nz=16", "time.dt=" + std::to_string(dt),
          "time.end=" + std::to_string(dt * steps), "output.fields_every=0", "output.checkpoint_every=0"};
}

/// small_run_sets with the generated octahedral level-1 membrane of 66 nodes.
inline std::vector<std::string> small_membrane_sets(int steps, double dt = 0.125) {
  auto sets = small_run_sets(steps, dt);
  sets.insert(sets.begin() + 3, "membrane[0].mesh.level=1");
  return sets;
}

/// Writes `mesh` as a Gmsh 2.2 file of 6-node triangles, the coordinates of its nodes multiplied by `scale` (x, y, z).
inline void write_gmsh(const fs::path& path, const Mesh& mesh, const Vec3& scale = {1, 1, 1}) {
  std::ofstream f(path);
  f.precision(17);
  f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << mesh.nodes.size() << "\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    f << i + 1 << " " << scale.x * mesh.nodes[i].x << " " << scale.y * mesh.nodes[i].y << " "
      << scale.z * mesh.nodes[i].z << "\n";
  f << "$EndNodes\n$Elements\n" << mesh.elements.size() << "\n";
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    f << e + 1 << " 9 2 0 1";
    for (int n : mesh.elements[e]) f << " " << n + 1;
    f << "\n";
  }
  f << "$EndElements\n";
}

/// oscillating_membrane_quick.toml with its [[membrane]] read from the Gmsh file `mesh` (a relative name is taken from
/// the configuration's folder), centred in the unit box, instead of generated; `extra`: further lines of the entry.
inline std::string file_membrane_toml(const std::string& mesh, const std::string& extra = "") {
  const std::string base = read_text(scenario_file("oscillating_membrane_quick.toml"));
  return base.substr(0, base.find("[[membrane]]")) + "[[membrane]]\nmesh.family = \"file\"\nmesh.file = \"" + mesh +
         "\"\ncenter = [0.5, 0.5, 0.5]\nEs = 0.1\n" + extra;
}

/// The words of a command line as a POSIX shell splits it, for the lines the program quotes (plain words and single
/// quotes, each ' inside written as '\'').
inline std::vector<std::string> shell_words(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ' ') {
      if (in_word) words.push_back(word), word.clear();
      in_word = false;
    } else if (c == '\'') {
      const std::size_t end = line.find('\'', i + 1);
      word += line.substr(i + 1, end - i - 1);
      i = end;
      in_word = true;
    } else if (c == '\\' && i + 1 < line.size()) {
      word += line[++i];
      in_word = true;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (in_word) words.push_back(word);
  return words;
}

/// The command line `run FILE --out DIR --set ...`.
inline std::vector<std::string> run_args(const fs::path& file, const fs::path& out, const std::vector<std::string>& sets,
                                         const fs::path& restart = {}) {
  std::vector<std::string> a{"run", file.string(), "--out", out.string()};
  for (const auto& s : sets) a.insert(a.end(), {"--set", s});
  if (!restart.empty()) a.insert(a.end(), {"--restart", restart.string()});
  return a;
}

/// diagnostics.csv split into cells: the header, then one vector per row.
inline std::vector<std::vector<std::string>> read_csv(const fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

/// The rows of a diagnostics table with the wall-clock column removed (the only one that may differ between
/// two runs of the same configuration).
inline std::vector<std::vector<std::string>> without_wall_clock(std::vector<std::vector<std::string>> rows) {
  if (rows.empty()) return rows;
  std::size_t wall = 0;
  while (wall < rows[0].size() && rows[0][wall] != "wall_s") ++wall;
  for (auto& r : rows)
    if (wall < r.size()) r.erase(r.begin() + static_cast<std::ptrdiff_t>(wall));
  return rows;
}

}  // namespace immerse::testing
