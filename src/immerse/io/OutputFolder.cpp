#include "immerse/io/OutputFolder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "immerse/core/Error.hpp"

namespace immerse::io {

namespace {

bool all_digits(const std::string& s, std::size_t from) {
  return from < s.size() && std::all_of(s.begin() + long(from), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

bool OutputFolder::is_run_file(const std::string& name) {
  for (const char* n : {"config.resolved.toml", "diagnostics.csv", "diagnostics.columns.csv", "stretch.csv",
                        "stretch.columns.csv", "checkpoint.h5", "unstable_state.h5", "membranes.xdmf",
                        "fluid.xdmf", "walls.xdmf"})
    if (name == n) return true;
  // mesh_membraneN.msh, mesh_membraneN_reference.msh: the copies of the mesh files
  for (const std::string tail : {".msh", "_reference.msh"}) {
    const std::string head = "mesh_membrane";
    if (name.size() > head.size() + tail.size() && name.rfind(head, 0) == 0 && name.ends_with(tail) &&
        all_digits(name.substr(0, name.size() - tail.size()), head.size()))
      return true;
  }
  // mesh_wallN.stl, mesh_wallN.msh: the copies of the walls' surface files
  for (const std::string tail : {".stl", ".msh"}) {
    const std::string head = "mesh_wall";
    if (name.size() > head.size() + tail.size() && name.rfind(head, 0) == 0 && name.ends_with(tail) &&
        all_digits(name.substr(0, name.size() - tail.size()), head.size()))
      return true;
  }
  // fields_NNNNNN.h5 (at least six digits)
  const std::string head = "fields_", tail = ".h5";
  if (name.size() < head.size() + 6 + tail.size() || name.rfind(head, 0) != 0 ||
      name.compare(name.size() - tail.size(), tail.size(), tail) != 0)
    return false;
  return all_digits(name.substr(0, name.size() - tail.size()), head.size());
}

bool OutputFolder::is_temporary(const std::string& name) {
  const auto at = name.rfind(".tmp.");
  return at != std::string::npos && all_digits(name, at + 5) && is_run_file(name.substr(0, at));
}

OutputFolder::OutputFolder(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code ec;
  created_ = std::filesystem::create_directories(dir_, ec);
  if (ec) throw WriteError("cannot write " + dir_.string() + ": " + ec.message());
  fd_ = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) throw WriteError("cannot write " + dir_.string() + ": " + std::strerror(errno));
  while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    if (errno == EINTR) continue;
    const int err = errno;
    ::close(fd_);
    if (err == EWOULDBLOCK)
      throw InputError("--out " + dir_.string() +
                       " is in use by another immerse run (one run per output folder; wait for it or choose another "
                       "--out)");
    throw WriteError("cannot write " + dir_.string() + ": cannot lock the folder: " + std::strerror(err));
  }
}

OutputFolder::~OutputFolder() {
  if (created_) ::rmdir(dir_.c_str());  // only succeeds while empty
  ::close(fd_);
}

std::vector<std::string> OutputFolder::run_files() const {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec))
    if (is_run_file(e.path().filename().string())) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void OutputFolder::remove_run_files() const {
  for (const auto& name : run_files())
    if (::unlink((dir_ / name).c_str()) != 0 && errno != ENOENT)
      throw WriteError("cannot write " + (dir_ / name).string() + ": cannot remove it: " + std::strerror(errno));
}

int OutputFolder::remove_temporaries() const {
  int removed = 0;
  std::error_code ec;
  std::vector<std::filesystem::path> found;
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec))
    if (is_temporary(e.path().filename().string())) found.push_back(e.path());
  for (const auto& p : found) removed += ::unlink(p.c_str()) == 0;
  return removed;
}

void OutputFolder::keep_run_files() {
  kept_ = dir_ / (".immerse_kept." + std::to_string(::getpid()));
  std::error_code ec;
  std::filesystem::remove_all(kept_, ec);
  if (!std::filesystem::create_directory(kept_, ec) || ec) {
    kept_.clear();
    throw WriteError("cannot write " + dir_.string() + ": " + (ec ? ec.message() : "cannot create a folder in it"));
  }
  for (const auto& name : run_files()) {
    if (::link((dir_ / name).c_str(), (kept_ / name).c_str()) != 0)
      std::filesystem::copy_file(dir_ / name, kept_ / name, ec);
    if (ec) {
      drop_kept();
      throw WriteError("cannot write " + (dir_ / name).string() + ": cannot keep it until the run's first files are " +
                       "written: " + ec.message());
    }
  }
}

void OutputFolder::restore_kept() {
  for (const auto& name : run_files()) ::unlink((dir_ / name).c_str());
  if (kept_.empty()) return;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(kept_, ec))
    ::rename(e.path().c_str(), (dir_ / e.path().filename()).c_str());
  drop_kept();
}

void OutputFolder::drop_kept() {
  std::error_code ec;
  if (!kept_.empty()) std::filesystem::remove_all(kept_, ec);
  kept_.clear();
}

}  // namespace immerse::io
