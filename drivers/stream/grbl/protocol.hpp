#pragma once
// grbl 1.1's serial protocol as the host sees it (grbl's protocol.c): every line sent
// gets exactly one answer, `ok` or `error:N`, in the order sent; everything else grbl
// prints (status reports `<...>`, messages `[...]`, `ALARM:N`, the start-up banner)
// answers no line. So the host keeps the lines it sent and has no answer for yet, and
// each answer retires the oldest of them.
#include <cstddef>
#include <deque>
#include <string>

namespace stipplot::io::grbl {

enum class Mode { CharacterCounting, SendAndWait };
Mode parse_mode(const std::string& s);  // "counting" | "wait"

// The lines sent and not yet answered. Character counting keeps their bytes within
// grbl's RX buffer, so grbl always has the next line when its planner has room;
// send-and-wait sends a line only when the previous one is answered.
class LineWindow {
 public:
  struct Line {
    size_t item;   // the streamer's numbering of what it sends
    size_t bytes;  // with its '\n'
  };
  LineWindow(Mode mode, size_t rx_buffer) : mode_(mode), rx_buffer_(rx_buffer) {}
  // A line longer than the whole buffer goes alone (grbl will answer error:11).
  bool fits(size_t bytes) const;
  void sent(size_t item, size_t bytes);
  // The oldest line, now answered. Requires !empty().
  Line answered();
  const Line& oldest() const { return lines_.front(); }
  bool empty() const { return lines_.empty(); }
  size_t size() const { return lines_.size(); }
  void clear();

 private:
  Mode mode_;
  size_t rx_buffer_;
  std::deque<Line> lines_;
  size_t bytes_ = 0;
};

// What a line from grbl is.
enum class ReplyKind {
  Ok,       // the oldest line was done
  Error,    // error:N, the oldest line was rejected
  Alarm,    // ALARM:N
  Status,   // <State|MPos:...>
  Banner,   // "Grbl 1.1h ['$' for help]": grbl (re)started
  Message,  // [MSG:...], [GC:...], ...
  Other,
};
struct Reply {
  ReplyKind kind = ReplyKind::Other;
  int code = 0;  // N of error:N and ALARM:N
  bool answers_a_line() const { return kind == ReplyKind::Ok || kind == ReplyKind::Error; }
};
Reply classify_reply(const std::string& line);

struct Status {
  std::string state;  // Idle, Run, Hold:0, Alarm, Check, ...
  double x = 0, y = 0, z = 0;
  int blocks_free = -1, bytes_free = -1;
  double feed = 0, spindle = 0;
};
bool parse_status(const std::string& line, Status& s);

}  // namespace stipplot::io::grbl
