#pragma once
// What the grbl and HPGL streamers share: progress reports, the controls another thread
// or a signal handler sets, and what a streaming session did.
#include <atomic>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace stipplot::io {

struct StreamProgress {
  size_t lines_total = 0, lines_sent = 0, lines_acked = 0;
  double elapsed_s = 0, eta_s = -1;
  std::string state;  // device state when known ("Run", "Idle", "Hold:0", ...)
  double x = 0, y = 0;
};
using ProgressFn = std::function<void(const StreamProgress&)>;

// Asked from another thread or a signal handler; the streamer acts on them in its loop.
struct StreamControls {
  std::atomic<bool> pause{false};   // feed hold, lift the pen
  std::atomic<bool> resume{false};  // cycle start
  std::atomic<bool> abort{false};   // stop the job (journal keeps what was done)
};

// A pause the job asks for (JobLine::pause: a G-code M0, HPGL's reload comment): the
// streamer stops there once the device has done everything before it, and asks.
struct PauseRequest {
  long line = -1;    // the job line of the pause
  std::string note;  // what the operator is to do ("Change pen: pen 2 red #ff0000")
};
enum class PauseAnswer {
  go,          // done: continue the job
  stop,        // stop before the pause (resume asks again)
  stop_after,  // stop, the pause counted as done: the operator does it before resuming
};
using PauseFn = std::function<PauseAnswer(const PauseRequest&)>;

struct StreamResult {
  bool completed = false;
  size_t lines_acked = 0;   // this session
  long last_acked = -1;     // job line index
  size_t errors_skipped = 0;
  std::vector<std::pair<long, int>> errors;  // (job line, device error code) skipped or checked
  double seconds = 0;
  std::vector<std::string> warnings;
  size_t pauses = 0;        // pauses the job made (operator waits)
  double paused_s = 0;      // wall time spent in them
};

}  // namespace stipplot::io
