#include "util/atomic_file.hpp"

#include <unistd.h>

#include <system_error>

#include "util/error.hpp"

namespace stipplot {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  require_writable_dir(target_);
  temp_ = target_;
  temp_ += ".tmp-" + std::to_string(::getpid());
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) throw UserError("cannot write " + target_.string() + ": " + ec.message());
  committed_ = true;
}

void write_file_atomic(const fs::path& target, const std::string& contents) {
  AtomicFile f(target);
  {
    std::ofstream out(f.temp_path(), std::ios::binary);
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.close();
    if (!out) throw UserError("cannot write " + target.string());
  }
  f.commit();
}

void require_writable_dir(const fs::path& target) {
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw UserError("cannot write " + target.string() + ": directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw UserError("cannot write " + target.string() + ": directory " + dir.string() + " is not writable");
}

}  // namespace stipplot
