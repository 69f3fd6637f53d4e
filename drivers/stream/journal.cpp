#include "drivers/stream/journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "util/error.hpp"

namespace stipplot::io {

uint64_t fnv1a64(const std::string& data) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : data) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

namespace {
int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

Journal::Journal(std::string path, const JournalHeader& h, bool append, int sync_interval_ms)
    : path_(std::move(path)), sync_ms_(sync_interval_ms) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (append ? O_APPEND : O_TRUNC), 0644);
  if (fd_ < 0) throw UserError("cannot write the journal " + path_ + ": " + std::strerror(errno));
  if (append) {
    JournalState st = load(path_);
    last_ = last_written_ = st.last_acked;
    append_record("session resume", true);
  } else {
    nlohmann::json j = {{"stipplot_journal", 1},   {"job", h.job_path}, {"hash", h.job_hash},
                        {"dialect", h.dialect},    {"profile", h.profile}, {"port", h.port},
                        {"lines", h.total_lines}};
    append_record(j.dump(), true);
  }
}

Journal::~Journal() {
  try {
    sync();
  } catch (...) {
  }
  if (fd_ >= 0) ::close(fd_);
}

void Journal::append_record(const std::string& rec, bool force_sync) {
  std::string line = rec + "\n";
  const char* p = line.data();
  size_t left = line.size();
  while (left) {
    ssize_t w = ::write(fd_, p, left);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw UserError("cannot write the journal " + path_ + ": " + std::strerror(errno));
    }
    p += w;
    left -= static_cast<size_t>(w);
  }
  int64_t t = now_ns();
  if (force_sync || t - last_sync_ns_ >= int64_t(sync_ms_) * 1000000) {
    ::fdatasync(fd_);
    last_sync_ns_ = t;
  }
}

void Journal::ack(size_t line) {
  last_ = static_cast<long>(line);
  if (now_ns() - last_sync_ns_ >= int64_t(sync_ms_) * 1000000) {
    append_record("ack " + std::to_string(last_), false);
    last_written_ = last_;
  }
}

void Journal::rollback_to(long line) {
  last_ = line;
  append_record("ack " + std::to_string(last_), true);
  last_written_ = last_;
}

void Journal::sync() {
  if (fd_ < 0) return;
  if (last_ != last_written_) {
    append_record("ack " + std::to_string(last_), true);
    last_written_ = last_;
  } else {
    ::fdatasync(fd_);
  }
}

void Journal::done() {
  sync();
  append_record("done", true);
}

JournalState Journal::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw UserError("no journal " + path + " (was the job started with stipplot plot?)");
  JournalState st;
  std::string line;
  if (!std::getline(in, line)) throw UserError("journal " + path + " is empty");
  try {
    auto j = nlohmann::json::parse(line);
    st.header.job_path = j.at("job").get<std::string>();
    st.header.job_hash = j.at("hash").get<std::string>();
    st.header.dialect = j.at("dialect").get<std::string>();
    st.header.profile = j.value("profile", "");
    st.header.port = j.value("port", "");
    st.header.total_lines = j.at("lines").get<size_t>();
  } catch (const std::exception& e) {
    throw UserError("journal " + path + " has a malformed header: " + e.what());
  }
  while (std::getline(in, line)) {
    if (line.rfind("ack ", 0) == 0) {
      char* end = nullptr;
      long v = std::strtol(line.c_str() + 4, &end, 10);
      if (end && *end == '\0') st.last_acked = v;  // a torn last record is ignored
    } else if (line == "done") {
      st.complete = true;
    }
  }
  return st;
}

}  // namespace stipplot::io
