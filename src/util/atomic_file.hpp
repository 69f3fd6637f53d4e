#pragma once
// Output files appear whole or not at all: written to a temporary beside the target
// and renamed over it on commit(). A failure (exception) leaves no partial file.
#include <filesystem>
#include <fstream>
#include <string>

namespace stipplot {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();  // removes the temporary unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  // Renames the temporary onto the target; throws UserError on failure.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  bool committed_ = false;
};

// Convenience: write a whole string atomically.
void write_file_atomic(const std::filesystem::path& target, const std::string& contents);

// Fails early, before any work, when the directory of an output path does not exist.
void require_writable_dir(const std::filesystem::path& target);

}  // namespace stipplot
