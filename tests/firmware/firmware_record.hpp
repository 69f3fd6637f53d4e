#pragma once
// What the real firmware did, read from grbl-sim's own logs and the relay's transcript.
// What each source proves:
//
// Block log (grbl_sim -b; build.sh patch 5): one line per planner block in the order
//   grbl PLANNED them: end position (steps), entry_speed_sqr as first planned (grbl may
//   raise it later), condition flags (1 rapid, 16 spindle CW, 32 CCW), spindle speed, and
//   the block's remaining mm when it was logged (less than its length when the stepper had
//   already begun it, so lengths come from the positions). "# reset at T pos x, y, z" at
//   every boot and soft reset: its only time stamps. "# rx drop" when the host overfilled
//   grbl's RX buffer. A block here was accepted, which proves nothing about it having run:
//   a reset or a power cut empties the planner.
// Step log (grbl_sim's stderr, with -r R): the position (steps) and spindle PWM every R
//   simulated seconds while the planner has a block being prepared, a line at every change
//   of that block the simulator notices, and "# block number N" after it. No line while
//   the planner is empty (dwells, pen changes, idle), so a pause longer than R between two
//   lines is the planner running dry: the first line is where the machine was then, the
//   second where it moved off again (exactly at rest, if it had stopped). The headers are
//   no block index: the simulator looks once a tick and grbl's main loop (a thread) can
//   prepare several short blocks in between, so which block ran, and how far, is read
//   from the positions along the planned path. The moment motion stops is the planner's
//   emptying plus the deceleration over the distance still left (a few ms of kinematics).
// Transcript (the relay): every line grbl received and its reply, in order. "ok" for a
//   move means planned; for M3/M5/G4 it means done (grbl empties its planner first), so a
//   servo pen's dots, which make no planner block, are proved by the transcript alone.
#include <limits>
#include <string>
#include <vector>

#include "firmware/gcode_model.hpp"

namespace firmware {

// A line the firmware received (grbl ends a line at '\n' or '\r'; real-time bytes are not lines).
struct HostLine {
  enum class Reply { None, Ok, Error, Flushed };  // Flushed: a reset emptied grbl's buffer first
  std::string text;
  int session = 0;               // firmware process (0, 1, ... one per power-on)
  bool from_client = true;       // false: the harness sent it (settings, commands)
  Reply reply = Reply::None;
  int error = 0;                 // N of error:N
  bool reply_forwarded = false;  // the client got the reply
  double t_sent = 0, t_reply = 0;  // wall seconds since the harness started
};

// A line the firmware sent.
struct DeviceLine {
  std::string text;
  int session = 0;
  double t = 0;
  bool forwarded = false;  // a client was connected and got it
};

// ---- block log ----
struct PlannedBlock {
  Steps end;
  double entry_speed_sqr = 0;  // (mm/min)^2
  unsigned condition = 0;
  double spindle = 0;
  double mm_logged = 0;
  bool rapid() const { return condition & 1u; }
  bool spindle_on() const { return condition & 48u; }
};
struct ResetMark {
  double t = 0;
  Steps pos;
};
struct BlockLog {
  std::vector<ResetMark> resets;                  // resets[0]: the boot
  std::vector<std::vector<PlannedBlock>> epochs;  // epochs[i]: blocks planned after resets[i]
  size_t rx_drops = 0;
  size_t zeroed_slots = 0;  // empty ring-buffer slots the logger printed at a reset (not blocks)
};
BlockLog parse_block_log(const std::string& text);  // O(text)

// ---- step log ----
struct StepLine {
  double t = 0;
  Steps pos;
  int spindle_pwm = 0;
};
// The planner ran dry: no line from t_emptied to t_resumed.
struct PlannerEmpty {
  double t_emptied = 0;
  Steps pos_emptied;
  double t_resumed = -1;  // -1: the log ends before motion resumed
  Steps pos_resumed;
};
struct StepLog {
  std::vector<StepLine> lines;
  std::vector<PlannerEmpty> empties;
  bool ends_moving = false;  // the last line was written while a block was being prepared
};
// `moving_at_end`: the log ended mid-motion (a power cut right after the last line).
// `exit_line`: grbl-sim exited cleanly and printed its last position (dropped here).
StepLog parse_step_log(const std::string& text, double sample_s, bool moving_at_end, bool exit_line = false);

// ---- one firmware process ----
struct ExecutedBlock {
  enum class Run { NotRun, Partial, Complete };
  PlannedBlock planned;
  Steps start;       // the previous block's end, or the reset position
  Steps stop;        // where its motion stopped (= planned.end when Complete)
  int epoch = 0;     // index into BlockLog::resets
  Run run = Run::NotRun;
  double t_start = -1;  // when it began, if it began from rest (else -1: mid-motion)
  double t_end = -1;    // when the machine came to rest at its end, if it did (else -1)
  bool rest_after = false;  // the machine stopped at its end: the planner had run dry
};

// The planner ran dry after `block` while more followed in the same epoch.
struct RestEvent {
  size_t block = 0;
  bool full_stop = false;  // the machine stopped; else a new block came before the last segments ran out
  double t_stop = -1;      // when it stopped (full stops)
  double t_resume = -1;    // when the next block began
};

struct SessionEvent {
  enum class Kind { Line, Reset } kind = Kind::Line;
  size_t line = 0;  // index into FirmwareRecord::lines, in reply order
};

struct SessionRecord {
  int index = 0;
  bool power_cut = false;
  double cut_idle_wall_s = 0;  // wall seconds between the step log's last write and the cut
  bool ambiguous_cut = false;  // where the last move stopped could not be told from the log
  BlockLog block_log;
  StepLog step_log;
  std::vector<ExecutedBlock> blocks;  // every planned block, in order
  std::vector<RestEvent> rests;       // planner ran dry with the epoch's next block still to come
  std::vector<SessionEvent> events;   // replies and resets, in grbl's order
};

// One line per block: end (mm), flags, how far it ran, its times. For test failure messages.
std::string describe(const SessionRecord& s, const MachineSettings& m);

// Joins a session's logs: which planned blocks ran, how far, and when.
SessionRecord build_session(const BlockLog& bl, const StepLog& sl, const MachineSettings& s, bool power_cut,
                            double cut_idle_wall_s);

struct FirmwareRecord {
  MachineSettings settings;
  double sample_s = 0.001;
  std::vector<SessionRecord> sessions;
  std::vector<HostLine> lines;
  std::vector<DeviceLine> device;
};

// The transcript replayed against the logs.
struct Interpretation {
  std::vector<Mark> marks;  // what the pen drew, machine steps (plus each session's offset)
  std::vector<std::string> inconsistencies;  // transcript and logs disagree (a harness bug if any)
  std::vector<std::vector<long>> block_line;  // per session, per block: the host line that planned it
  // Times the machine came to rest: at a line that makes grbl empty its planner (pen
  // change, dwell, pause), or starved: the next move had not reached the planner yet.
  size_t rests_at_sync = 0, rests_starved = 0;
  double starved_s = 0;  // standstill of the starved rests, simulated seconds
  struct Starved {
    int session;
    size_t block;          // the block after which the planner ran dry
    size_t since_sync;     // blocks since the machine last rested at a sync (or the session began)
    double standstill_s;
  };
  std::vector<Starved> starved;
};
// `offsets[i]`: where session i's machine zero lies (power cuts: 0 = re-zeroed at the origin).
// O(lines + blocks).
Interpretation interpret(const FirmwareRecord& r, const PenRule& rule, const std::vector<Steps>& offsets = {});

// The firmware's time for the job of `session` (last session with blocks if -1), in
// simulated seconds, comparable with stipplot's estimate: from the start of the first
// block to the start of the final pen-up return to the origin (the estimate leaves it
// out), or to the end of the last block if the job does not return.
double firmware_plot_seconds(const FirmwareRecord& r, const PenRule& rule, int session = -1);
// From the start of the first block to the end of the last one (the final return
// included), simulated seconds: what a whole job's motion took. -1 if the last block's
// end is not known.
double firmware_motion_seconds(const FirmwareRecord& r, int session = -1);

}  // namespace firmware
