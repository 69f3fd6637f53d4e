#pragma once
// The EiBotBoard's own firmware (v3.0.2) as a test oracle: ebb_sim, built from
// ../shared/validators/ebb/build.sh into the build tree, runs the firmware's command
// parser and 25 kHz motion interrupt on a simulated clock and logs every motor step and
// pen change. Here: feeding it a job as a command file, or relaying it to a pty that
// `stipplot plot` opens as the board's port (the link can be dropped while the firmware
// runs on, as a board with its own power does), and reading the pen-down paths back from
// its event log.
#include <sys/types.h>

#include <atomic>
#include <deque>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace ebbtest {

struct Pt {
  double x = 0, y = 0;
};
using Path = std::vector<Pt>;

// Builds ebb_sim once (flock-serialised) into the build tree; returns the binary's path.
// Throws std::runtime_error with the build log's tail.
std::string ensure_ebb_sim();

// What the firmware did, from its event log (machine mm: x = (m1 + m2) / 2, y = (m1 - m2) / 2
// over steps_per_mm): each pen-down interval's path (where it went down, then the position
// after every step), the times of the first and last step, and the final motor position.
// A reset (RB) ends a pen-down interval (the mark drawn up to it is kept) and the position
// restarts at 0, as the rebooted firmware's counters do.
struct SimLog {
  std::vector<Path> marks;
  double first_step_s = -1, last_step_s = -1, first_command_s = -1;
  int64_t m1 = 0, m2 = 0;
  size_t steps = 0, down_steps = 0;  // all motor steps, and those with the pen down
};
SimLog read_log(const std::string& path, double steps_per_mm);

// Sends the job's device lines (not its '#' host lines) to a fresh ebb_sim as one input,
// logging to `log`; returns what the firmware answered.
std::string run_job_file(const std::string& job_path, const std::string& log);

// The strokes of a planned SVG (`stipplot export ... -o plan.svg`): each <path>'s points and
// each <circle>'s centre (a one-point stroke), in document order. Page mm.
std::vector<Path> planned_strokes(const std::string& svg_path);

// The pen-down paths a job commands: where each SP,0 puts the pen down, then the end of
// every SM or LM until the SP,1 (machine mm).
std::vector<Path> job_marks(const std::string& job_path, double steps_per_mm);
// The motor steps the job's SMs and LMs make with the pen down (|motor 1| + |motor 2|).
size_t job_down_steps(const std::string& job_path);

// Every plan stroke drawn once, in order, within `tol` mm: the firmware's marks and the
// plan's strokes pair up one to one; every point of a mark lies within tol of its stroke
// and every vertex of the stroke within tol of the mark. `worst` is the largest distance.
struct Comparison {
  bool ok = false;
  size_t plan_marks = 0, drawn_marks = 0;
  double worst = 0;
  std::string why;
};
Comparison compare_marks(const std::vector<Path>& plan, const std::vector<Path>& drawn, double tol);

// Marks drawn in pieces (a plot resumed after a reset splits a stroke and may draw a
// little twice), judged as ink: the largest distance from a point of `a` (its vertices
// and a point every `step` mm along it) to the nearest such point of `b`, capped at `cap`
// (`where` is that point of `a`). Grid-hashed: O(points).
struct Gap {
  double worst = 0;
  Pt where;
};
Gap farthest(const std::vector<Path>& a, const std::vector<Path>& b, double step, double cap);

// ebb_sim behind a pty: a relay thread copies bytes between the pty a client opens and the
// firmware's stdin/stdout. The firmware lives until finish() (its input closed, it exits
// once idle).
class EbbBoard {
 public:
  // realtime: simulated time paced to the wall clock (ebb_sim -r), as a real board runs;
  // otherwise as fast as the CPU allows, about 80 times the wall clock. flash: the board's
  // persistent flash image (ebb_sim -f; the ST nickname lives there), none if empty.
  explicit EbbBoard(const std::string& log, bool realtime = false, const std::string& flash = "");
  ~EbbBoard();
  EbbBoard(const EbbBoard&) = delete;
  EbbBoard& operator=(const EbbBoard&) = delete;
  const std::string& port() const { return port_; }
  // The link drops right after the client's n-th command ('\r') reached the firmware:
  // later bytes are lost, the client's pty hangs up; the firmware runs on.
  void drop_after_commands(size_t n) { drop_after_ = n; }
  // The board reboots right after the client's n-th command reached the firmware: the
  // firmware gets the board's own `RB` (ebb_sim re-executes itself: step counters at 0,
  // FIFO and RAM gone, the pen up, time monotonic, the log appended) and the link drops
  // as above, as a real board's USB port goes away when it resets. The sim's carriage is
  // its counters, so the carriage is back home after it: what `plot --resume` takes a
  // reset board to be (on a real one the operator brings it home by hand).
  void reset_after_commands(size_t n) {
    reset_ = true;
    drop_after_ = n;
  }
  // The board is reset while no host talks to it (between two plots): its own RB, as
  // above. Only while no client sends (its bytes could split the command).
  void reboot();
  // The board's PRG button is pressed once the client's n-th command reached the firmware.
  // ebb_sim reads its buttons as released (its README), so the rig stands in for the
  // press, openly: the firmware's own answer to the next QB after it ("0", legacy replies)
  // reaches the client as "1". The relay pairs each answer with its command to find it.
  void press_button_after_commands(size_t n) { press_after_ = n; }
  bool button_reported() const { return pressed_; }
  bool dropped() const { return dropped_; }
  size_t commands() const { return commands_; }
  std::string reconnect();  // a new pty to the same firmware
  void finish();            // closes the firmware's input and waits for it to exit

 private:
  void open_pty();
  void relay();
  pid_t pid_ = -1;
  int to_fw_ = -1, from_fw_ = -1, master_ = -1;
  std::string port_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, dropped_{false}, reset_{false};
  std::atomic<size_t> drop_after_{0}, commands_{0}, press_after_{0};
  std::atomic<bool> pressed_{false};
  // The relay's pairing of answers with commands: the names sent and not yet answered
  // (an answer ends with its "OK" line; V's is its version line alone), the command being
  // sent, and the answer line being read.
  std::deque<std::string> unanswered_;
  std::string sending_, reading_;
  void forward_from_firmware(char* buf, size_t n);
  std::mutex mu_;  // master_ and port_ between the relay and reconnect()
};

}  // namespace ebbtest
