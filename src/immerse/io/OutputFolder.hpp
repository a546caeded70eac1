#pragma once
// The output folder of one run. Opening it creates the folder if missing and takes an exclusive lock on it
// (flock on the folder itself, so no lock file is written), held until destruction: a second run into the same
// folder is refused while the first one writes. The files a run writes (config.resolved.toml, diagnostics.csv,
// stretch.csv, checkpoint.h5, unstable_state.h5, membranes.xdmf, fluid.xdmf, fields_NNNNNN.h5, and the copies of
// mesh files mesh_membraneN.msh, mesh_membraneN_reference.msh, mesh_wallN.stl and mesh_wallN.msh) are "run files";
// the temporaries of interrupted atomic writes are "NAME.tmp.PID" of a run file. Other files in the folder are never
// touched.
#include <filesystem>
#include <string>
#include <vector>

namespace immerse::io {

class OutputFolder {
 public:
  /// Creates and locks `dir`. WriteError "cannot write DIR: REASON" if it cannot be created or opened;
  /// InputError "--out DIR is in use by another immerse run (...)" if another process holds the lock.
  explicit OutputFolder(std::filesystem::path dir);
  /// Releases the lock; a folder this object created that is still empty is removed.
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  const std::filesystem::path& path() const { return dir_; }
  /// Whether this object created the folder (it did not exist before).
  bool created() const { return created_; }
  /// Names of the run files in the folder, sorted.
  std::vector<std::string> run_files() const;
  /// Removes the run files (WriteError naming the file on failure).
  void remove_run_files() const;
  /// Removes the temporaries left by a writer that was killed; returns how many.
  int remove_temporaries() const;
  /// Keeps the run files now in the folder, as hard links (copies where the file system has none) in
  /// DIR/.immerse_kept.PID, so that restore_kept() can put the folder back as it was (WriteError on failure).
  void keep_run_files();
  /// Removes the run files and puts the kept ones back (best effort: this undoes a failed write).
  void restore_kept();
  /// Removes the kept files: the run has written its first files.
  void drop_kept();

  static bool is_run_file(const std::string& name);
  static bool is_temporary(const std::string& name);

 private:
  std::filesystem::path dir_, kept_;
  int fd_ = -1;
  bool created_ = false;
};

}  // namespace immerse::io
