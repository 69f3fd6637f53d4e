#include "drivers/stream/journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <zlib.h>

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

constexpr const char* kCrcMark = " *";

std::string crc_hex(const std::string& body) {
  const uLong c = crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()));
  char b[16];
  std::snprintf(b, sizeof b, "%08lx", static_cast<unsigned long>(c));
  return b;
}

// The body of a record whose CRC checks, or false.
bool checked_body(const std::string& line, std::string& body) {
  const size_t mark = line.rfind(kCrcMark);
  if (mark == std::string::npos || line.size() != mark + 2 + 8) return false;
  body = line.substr(0, mark);
  return line.compare(mark + 2, 8, crc_hex(body)) == 0;
}

// Cuts a torn last record (no newline) off the end, so that appended records start on
// a line of their own.
void drop_torn_tail(int fd, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (all.empty() || all.back() == '\n') return;
  const size_t keep = all.rfind('\n') == std::string::npos ? 0 : all.rfind('\n') + 1;
  if (::ftruncate(fd, static_cast<off_t>(keep)) != 0)
    throw UserError("cannot repair the journal " + path + ": " + std::strerror(errno));
}

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
    if (st.torn) drop_torn_tail(fd_, path_);
    last_ = last_written_ = st.last_acked;
    append_record("session resume", true);
  } else {
    nlohmann::json j = {{"stipplot_journal", 2},   {"job", h.job_path}, {"hash", h.job_hash},
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

std::string Journal::record(const std::string& body) { return body + kCrcMark + crc_hex(body); }

void Journal::append_record(const std::string& rec, bool force_sync) {
  std::string line = record(rec) + "\n";
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

// Every acknowledgement is written at once (a killed host loses none: the kernel has
// them), and made durable every sync interval (a power loss may repeat that much).
void Journal::ack(size_t line) {
  last_ = static_cast<long>(line);
  append_record("ack " + std::to_string(last_), false);
  last_written_ = last_;
}

void Journal::proven(const ProvenPoint& p) {
  char b[128];
  std::snprintf(b, sizeof b, "pos %ld %.4f %.4f %.4f", p.line, p.x, p.y, p.z);
  append_record(b, false);
}

void Journal::device_cleared() { append_record("stopped", true); }

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

namespace {

// One line of the journal: its body if the CRC checks. The last line, without its
// newline, may be a record a crash cut short: torn, not damaged.
bool read_record(const std::string& path, const std::string& line, size_t number, bool last_unterminated,
                 std::string& body, JournalState& st) {
  if (checked_body(line, body)) return true;
  if (last_unterminated) {
    st.torn = true;
    return false;
  }
  throw UserError("journal " + path + " is damaged: line " + std::to_string(number) +
                  " fails its checksum; refusing to resume from it (plot the job anew, or remove the journal)");
}

// "pos N X Y Z": N a line of the job, three finite numbers.
ProvenPoint parse_pos(const std::string& path, const std::string& body, size_t number, size_t total_lines) {
  ProvenPoint p;
  char tail = 0;
  const int n = std::sscanf(body.c_str(), "pos %ld %lf %lf %lf %c", &p.line, &p.x, &p.y, &p.z, &tail);
  if (n != 4 || p.line < 0 || p.line >= static_cast<long>(total_lines) || !std::isfinite(p.x) || !std::isfinite(p.y) ||
      !std::isfinite(p.z))
    throw UserError("journal " + path + " is damaged: line " + std::to_string(number) + " `" + body +
                    "` is not a position on a line of the job (it has " + std::to_string(total_lines) + " lines)");
  return p;
}

}  // namespace

JournalState Journal::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("no journal " + path + " (was the job started with stipplot plot?)");
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (all.empty()) throw UserError("journal " + path + " is empty");
  JournalState st;
  size_t pos = 0, number = 0;
  while (pos < all.size()) {
    const size_t eol = all.find('\n', pos);
    const bool unterminated = eol == std::string::npos;
    std::string line = all.substr(pos, unterminated ? std::string::npos : eol - pos);
    pos = unterminated ? all.size() : eol + 1;
    ++number;
    std::string body;
    if (!read_record(path, line, number, unterminated, body, st)) {
      if (number == 1) throw UserError("journal " + path + " has a torn header (the plot never got going)");
      break;
    }
    if (number == 1) {
      try {
        auto j = nlohmann::json::parse(body);
        st.header.job_path = j.at("job").get<std::string>();
        st.header.job_hash = j.at("hash").get<std::string>();
        st.header.dialect = j.at("dialect").get<std::string>();
        st.header.profile = j.value("profile", "");
        st.header.port = j.value("port", "");
        st.header.total_lines = j.at("lines").get<size_t>();
      } catch (const std::exception& e) {
        throw UserError("journal " + path + " has a malformed header: " + e.what());
      }
    } else if (body.rfind("ack ", 0) == 0) {
      char* end = nullptr;
      const long v = std::strtol(body.c_str() + 4, &end, 10);
      if (!end || *end != '\0' || v < -1 || v >= static_cast<long>(st.header.total_lines))
        throw UserError("journal " + path + " is damaged: line " + std::to_string(number) + " `" + body +
                        "` is not a line of the job (it has " + std::to_string(st.header.total_lines) + " lines)");
      st.last_acked = v;
      st.stopped = false;
    } else if (body.rfind("pos ", 0) == 0) {
      st.proven = parse_pos(path, body, number, st.header.total_lines);
    } else if (body == "stopped") {
      st.stopped = true;
    } else if (body == "done") {
      st.complete = true;
    } else if (body != "session resume") {
      throw UserError("journal " + path + " is damaged: line " + std::to_string(number) + " `" + body +
                      "` is no journal record");
    }
  }
  return st;
}

void Journal::check_belongs(const JournalState& st, const std::string& path, const std::string& job_hash,
                            const std::string& dialect, size_t lines, const std::string& profile) {
  const std::string j = path_for(path);
  if (st.header.job_hash != job_hash)
    throw UserError("job " + path + " changed since it was started (its journal " + j + " belongs to another version)");
  if (st.header.dialect != dialect || st.header.total_lines != lines)
    throw UserError("journal " + j + " is for a " + st.header.dialect + " job of " + std::to_string(st.header.total_lines) +
                    " lines, not this " + dialect + " job of " + std::to_string(lines));
  if (!st.header.profile.empty() && !profile.empty() && st.header.profile != profile)
    throw UserError("journal " + j + " was written plotting with profile " + st.header.profile + ", not " + profile +
                    " (resume with --profile " + st.header.profile + ")");
}

}  // namespace stipplot::io
