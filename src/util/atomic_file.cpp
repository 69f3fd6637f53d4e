#include "util/atomic_file.hpp"

#include <unistd.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <system_error>
#include <thread>

#include "util/error.hpp"

namespace stipplot {

namespace fs = std::filesystem;

namespace {

// The temporaries that exist right now, for the signal handler to remove: fixed slots of
// C strings, so the handler touches nothing but atomics and unlink (async-signal-safe).
constexpr size_t kTempSlots = 64;
std::array<std::atomic<char*>, kTempSlots> g_temps{};
constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};
struct sigaction g_previous[std::size(kCleanupSignals)];
std::mutex g_registry_mutex;  // registration only, never taken in the handler
size_t g_registered = 0;

extern "C" void remove_temps_and_die(int sig) {
  for (auto& slot : g_temps)
    if (char* p = slot.load()) ::unlink(p);
  // Die of the signal as if the handler had not been there (or pass it to the old one).
  for (size_t i = 0; i < std::size(kCleanupSignals); ++i)
    if (kCleanupSignals[i] == sig) ::sigaction(sig, &g_previous[i], nullptr);
  ::raise(sig);
}

// Slot index, or kTempSlots when all are taken (the file is then only removed on errors).
size_t register_temp(const fs::path& temp) {
  std::lock_guard<std::mutex> lock(g_registry_mutex);
  for (size_t i = 0; i < kTempSlots; ++i) {
    if (g_temps[i].load()) continue;
    g_temps[i].store(::strdup(temp.c_str()));
    if (g_registered++ == 0) {
      struct sigaction sa {};
      sa.sa_handler = remove_temps_and_die;
      sigemptyset(&sa.sa_mask);
      for (size_t k = 0; k < std::size(kCleanupSignals); ++k)
        ::sigaction(kCleanupSignals[k], &sa, &g_previous[k]);
    }
    return i;
  }
  return kTempSlots;
}

void unregister_temp(size_t slot) {
  if (slot >= kTempSlots) return;
  std::lock_guard<std::mutex> lock(g_registry_mutex);
  char* p = g_temps[slot].exchange(nullptr);
  std::free(p);
  if (--g_registered == 0)
    for (size_t k = 0; k < std::size(kCleanupSignals); ++k) ::sigaction(kCleanupSignals[k], &g_previous[k], nullptr);
}

size_t slot_of(const fs::path& temp) {
  for (size_t i = 0; i < kTempSlots; ++i)
    if (char* p = g_temps[i].load(); p && temp == p) return i;
  return kTempSlots;
}

std::atomic<OutputBatch*> g_batch{nullptr};

}  // namespace

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  require_writable_dir(target_);
  temp_ = target_;
  temp_ += ".tmp-" + std::to_string(::getpid());
  register_temp(temp_);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
    unregister_temp(slot_of(temp_));
  }
}

void AtomicFile::commit() {
  OutputBatch* batch = g_batch.load();
  if (batch && batch->stages_this_thread()) {  // the batch renames or removes it
    committed_ = true;
    for (const auto& s : batch->staged_)
      if (s.temp == temp_) {  // written again (a run that redid its output): the newer contents stand
        unregister_temp(slot_of(temp_));
        return;
      }
    batch->staged_.push_back({temp_, target_});
    return;
  }
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) throw UserError("cannot write " + target_.string() + ": " + ec.message());
  committed_ = true;
  unregister_temp(slot_of(temp_));
}

OutputBatch::OutputBatch() {
  OutputBatch* none = nullptr;
  if (!g_batch.compare_exchange_strong(none, this)) throw std::logic_error("one OutputBatch at a time");
}

OutputBatch::~OutputBatch() {
  for (const Staged& s : staged_) {
    std::error_code ec;
    fs::remove(s.temp, ec);
    unregister_temp(slot_of(s.temp));
  }
  g_batch.store(nullptr);
}

void OutputBatch::commit() {
  // Every target's directory was writable when its temporary was made beside it, so a
  // rename fails only if the directory changed under us.
  while (!staged_.empty()) {
    const Staged s = staged_.front();
    std::error_code ec;
    fs::rename(s.temp, s.target, ec);
    if (ec) throw UserError("cannot write " + s.target.string() + ": " + ec.message());
    unregister_temp(slot_of(s.temp));
    staged_.erase(staged_.begin());
  }
}

void commit_staged_outputs() {
  OutputBatch* batch = g_batch.load();
  if (batch && batch->stages_this_thread()) batch->commit();
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
  if (fs::is_directory(target, ec))
    throw UserError("cannot write " + target.string() + ": it is a directory");
  if (!fs::is_directory(dir, ec))
    throw UserError("cannot write " + target.string() + ": directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw UserError("cannot write " + target.string() + ": directory " + dir.string() + " is not writable");
}

}  // namespace stipplot
