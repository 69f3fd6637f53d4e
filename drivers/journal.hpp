#pragma once
// A plot job as the streamers see it (text lines plus what each line does to the pen,
// parsed from the G-code or HPGL itself), the resume journal kept next to the job
// file, and the progress/control types shared by the grbl and HPGL streamers.
#include <atomic>
#include <cstdint>
#include <functional>
#include <utility>
#include <string>
#include <vector>

namespace stipplot::io {

enum class Dialect { GCode, Hpgl };
const char* to_string(Dialect d);

struct JobLine {
  std::string text;       // one G-code line / one HPGL instruction, no terminator
  bool motion = false;    // moves the tool
  bool pen_down = false;  // pen state after the line
  double x = 0, y = 0;    // position after the line (mm for G-code, plotter units for HPGL)
  double est_s = 0;       // rough duration (distance / feed), for the ETA
};

struct Segment {
  double x0, y0, x1, y1;
  int pen = 1;  // HPGL pen number (1 for G-code)
  friend bool operator==(const Segment&, const Segment&) = default;
};

struct Job {
  Dialect dialect = Dialect::GCode;
  std::vector<JobLine> lines;
  double est_total_s = 0;
};

// How a G-code job puts its pen down: servo or laser (M3/M4 with S > 0 down, M5 or S0
// up; a servo whose "up" is M3 S<servo_up_s> is up at that S) or a Z axis (Z below
// `z_down_below` down).
struct GcodePenRule {
  double z_down_below = 0;
  double servo_up_s = 0;  // 0: no "up" S value (up is M5 or S0)
};
bool gcode_pen_down(bool spindle_on, double s, double z, const GcodePenRule& rule);

// Splits G-code into lines (comments and blank lines dropped) and tracks pen state and
// position per line. O(text length).
Job parse_gcode_job(const std::string& text, const GcodePenRule& rule = {});
// Splits HPGL into instructions (at ';' and before each new mnemonic) and tracks the
// pen (PU/PD, SP) and position (PA/PR). O(text length).
Job parse_hpgl_job(const std::string& text);

// The pen-down segments the job draws, in order (what a plotter's record must equal).
std::vector<Segment> job_segments(const Job& job);

// Where and how to continue after line `next - 1` was the last one done: restore
// units/modes and the feed, lift the pen, travel to where that line ended, and put the
// pen in the state it had. A resume point just after a pen-down that has not moved
// yet is moved: past the pen-up of a dot (the lift finished it), or back to the
// pen-down of a stroke. Throws UserError for a job it cannot resume (G91).
struct ResumePlan {
  size_t next = 0;                    // first job line to send after the preamble
  std::vector<std::string> preamble;  // lines to send first
};
// What the device reports about its pen, when it can (grbl: spindle speed and Z from a
// status report). If the pen is already where and as it should be (the device kept
// running after the link dropped), nothing is lifted or moved.
struct DevicePen {
  bool known = false, down = false;
  double x = 0, y = 0;
};
ResumePlan plan_resume(const Job& job, size_t next, const DevicePen& device = {});

uint64_t fnv1a64(const std::string& data);

// ---- journal ------------------------------------------------------------------
struct JournalHeader {
  std::string job_path, job_hash, dialect, profile, port;
  size_t total_lines = 0;
};

struct JournalState {
  JournalHeader header;
  long last_acked = -1;  // index of the last line the device acknowledged
  bool complete = false;
};

// Append-only file JOB.journal: a JSON header line, then "ack N" records and "done".
// Records are fsync'd at most every `sync_interval_ms` while streaming (a host crash
// may repeat that much), and always on sync() / close (device faults lose nothing).
class Journal {
 public:
  static std::string path_for(const std::string& job_path) { return job_path + ".journal"; }
  // Creates (or, with append, continues) the journal.
  Journal(std::string path, const JournalHeader& h, bool append = false, int sync_interval_ms = 100);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;
  void ack(size_t line);
  // Moves the acknowledged point back (after an abort: acked lines the device
  // discarded from its buffer).
  void rollback_to(long line);
  void done();
  void sync();
  long last_acked() const { return last_; }
  const std::string& path() const { return path_; }
  // Throws UserError if missing or malformed.
  static JournalState load(const std::string& path);

 private:
  void append_record(const std::string& rec, bool force_sync);
  std::string path_;
  int fd_ = -1;
  long last_ = -1, last_written_ = -1;
  int sync_ms_;
  int64_t last_sync_ns_ = 0;
};

// ---- streaming ------------------------------------------------------------------
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

struct StreamResult {
  bool completed = false;
  size_t lines_acked = 0;   // this session
  long last_acked = -1;     // job line index
  size_t errors_skipped = 0;
  std::vector<std::pair<long, int>> errors;  // (job line, device error code) skipped or checked
  double seconds = 0;
  std::vector<std::string> warnings;
};

}  // namespace stipplot::io
