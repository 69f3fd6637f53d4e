#include "drivers/stream/grbl/protocol.hpp"

#include <cstdio>
#include <cstdlib>

#include "util/error.hpp"

namespace stipplot::io::grbl {

Mode parse_mode(const std::string& s) {
  if (s == "counting" || s == "character-counting" || s == "cc") return Mode::CharacterCounting;
  if (s == "wait" || s == "send-and-wait" || s == "simple") return Mode::SendAndWait;
  throw UserError("--stream must be counting or wait, got '" + s + "'");
}

bool LineWindow::fits(size_t bytes) const {
  if (mode_ == Mode::SendAndWait) return lines_.empty();
  return bytes_ + bytes <= rx_buffer_ || (lines_.empty() && bytes > rx_buffer_);
}

void LineWindow::sent(size_t item, size_t bytes) {
  lines_.push_back({item, bytes});
  bytes_ += bytes;
}

LineWindow::Line LineWindow::answered() {
  Line l = lines_.front();
  lines_.pop_front();
  bytes_ -= l.bytes;
  return l;
}

void LineWindow::clear() {
  lines_.clear();
  bytes_ = 0;
}

Reply classify_reply(const std::string& line) {
  if (line == "ok") return {ReplyKind::Ok};
  if (line.rfind("error:", 0) == 0) return {ReplyKind::Error, std::atoi(line.c_str() + 6)};
  if (line.rfind("ALARM:", 0) == 0) return {ReplyKind::Alarm, std::atoi(line.c_str() + 6)};
  if (!line.empty() && line.front() == '<') return {ReplyKind::Status};
  if (line.rfind("Grbl ", 0) == 0) return {ReplyKind::Banner};
  if (!line.empty() && line.front() == '[') return {ReplyKind::Message};
  return {ReplyKind::Other};
}

bool parse_status(const std::string& line, Status& s) {
  if (line.size() < 3 || line.front() != '<' || line.back() != '>') return false;
  std::string body = line.substr(1, line.size() - 2);
  size_t pos = 0;
  int field = 0;
  while (pos <= body.size()) {
    size_t bar = body.find('|', pos);
    std::string f = body.substr(pos, bar == std::string::npos ? std::string::npos : bar - pos);
    if (field == 0) s.state = f;
    else if (f.rfind("MPos:", 0) == 0 || f.rfind("WPos:", 0) == 0)
      std::sscanf(f.c_str() + 5, "%lf,%lf,%lf", &s.x, &s.y, &s.z);
    else if (f.rfind("Bf:", 0) == 0)
      std::sscanf(f.c_str() + 3, "%d,%d", &s.blocks_free, &s.bytes_free);
    else if (f.rfind("FS:", 0) == 0)
      std::sscanf(f.c_str() + 3, "%lf,%lf", &s.feed, &s.spindle);
    else if (f.rfind("F:", 0) == 0)
      std::sscanf(f.c_str() + 2, "%lf", &s.feed);
    ++field;
    if (bar == std::string::npos) break;
    pos = bar + 1;
  }
  return !s.state.empty();
}

}  // namespace stipplot::io::grbl
