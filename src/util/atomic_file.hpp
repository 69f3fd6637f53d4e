#pragma once
// Output files appear whole or not at all: written to a temporary beside the target
// and renamed over it on commit(). A failure (exception) leaves no partial file, and
// neither does SIGINT, SIGTERM or SIGHUP: while a temporary exists, those signals remove
// it before the process dies of them.
//
// A command that writes several files holds an OutputBatch: then commit() only stages a
// file, and the batch renames every staged file at its own commit(), after all the work
// succeeded, so a run that fails halfway leaves none of its outputs.
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace stipplot {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();  // removes the temporary unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  // Renames the temporary onto the target (or stages it with the open OutputBatch);
  // throws UserError on failure.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  bool committed_ = false;
};

// The outputs of one run, renamed onto their targets together at commit(); destroying an
// uncommitted batch removes every temporary it holds. One batch at a time, holding the
// files committed on the thread that opened it: a server's worker threads write theirs at
// once.
class OutputBatch {
 public:
  OutputBatch();
  ~OutputBatch();
  OutputBatch(const OutputBatch&) = delete;
  OutputBatch& operator=(const OutputBatch&) = delete;
  // Renames every staged file onto its target, in staging order; UserError on failure.
  void commit();
  size_t staged() const { return staged_.size(); }
  bool stages_this_thread() const { return owner_ == std::this_thread::get_id(); }

 private:
  friend class AtomicFile;
  struct Staged {
    std::filesystem::path temp, target;
  };
  std::vector<Staged> staged_;
  std::thread::id owner_ = std::this_thread::get_id();
};

// Commits the open batch now, if there is one: for a file the run goes on to read (a job
// that is streamed once written).
void commit_staged_outputs();

// Convenience: write a whole string atomically.
void write_file_atomic(const std::filesystem::path& target, const std::string& contents);

// Fails early, before any work, when the directory of an output path does not exist.
void require_writable_dir(const std::filesystem::path& target);

}  // namespace stipplot
