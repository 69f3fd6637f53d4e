#pragma once
// What the real firmware did, read from grbl_avr's step log and the relay's transcript.
// grbl_avr (../shared/validators/grbl-avr) runs grbl 1.1h's AVR binary on simavr, one
// instruction at a time, and logs from the chip's pins with simulated time stamps:
//
// Step log (grbl_avr -s): "P t AXES x y z" at every step pulse's leading edge (the counts
//   after it, = grbl's sys_position), "M t duty=..." whenever the spindle/pen output
//   (PB3, OC2A) changes, "E t x y z" at a clean exit. Every step the motors took is here,
//   so where the machine went, and when, is exact; a power cut (grbl_avr stopped by
//   SIGTERM) leaves the log complete up to the cut.
// Transcript (the relay): every line grbl received and its reply, in order, and grbl's
//   banners (boot and soft reset). "ok" for a move means planned (grbl plans exactly one
//   block per move of at least one step); for M3/M5/G4 it means done (grbl empties its
//   planner first). Replaying the answered lines through grbl's G-code model gives the
//   blocks grbl planned, in order; walking the step log along them tells which ran, how
//   far and when. The log has no block boundaries of its own: a step belongs to the block
//   being walked while it moves towards that block's end within the stepper's Bresenham
//   rounding; a step that does not, or the step where a reset falls (placed by grbl's
//   status reports), ends the walk: a reset or a power cut stopped the block there.
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
  // Not empty: a line grbl answered that the relay never saw start, after a reset that
  // flushed these lines while their bytes were on the wire: grbl ran the tail of one of
  // them, then the whole lines after it. Which, is read from the step log
  // (SessionRecord::fragment_text).
  std::vector<size_t> fragment_of;
};

// A line the firmware sent.
struct DeviceLine {
  std::string text;
  int session = 0;
  double t = 0;
  bool forwarded = false;  // a client was connected and got it
};

// ---- step log ----
struct StepEvent {
  double t = 0;  // simulated seconds since power-on
  Steps pos;     // after the step
};
struct SpindleEvent {
  double t = 0;
  double duty = 0;         // PWM duty while the PWM runs, else the pin level (0 or 1)
  size_t steps_before = 0;  // how many step events came before it
};
struct StepLog {
  std::vector<StepEvent> steps;
  std::vector<SpindleEvent> spindle;
  bool ended = false;  // an "E" line: grbl_avr exited cleanly (SIGTERM included), the log is whole
  double t_end = 0;
  Steps end_pos;
};
StepLog parse_step_log(const std::string& text);  // O(text)
// "<Idle|MPos:1.000,2.000,0.000|..." -> machine steps; false if it is no status report with MPos.
bool status_position(const std::string& status_report, const MachineSettings& s, Steps& out);

// ---- one firmware process ----
// A block grbl planned: one per answered move of at least one step, in order.
struct PlannedBlock {
  Steps end;
  bool rapid = false;
};
struct ExecutedBlock {
  enum class Run { NotRun, Partial, Complete };
  PlannedBlock planned;
  Steps start;       // where the machine stood when grbl planned it to start
  Steps stop;        // where its motion stopped (= planned.end when Complete)
  int epoch = 0;     // resets seen before it in this session, less one (the boot)
  Run run = Run::NotRun;
  double t_start = -1;  // simulated time its motion began (its first step, less the first step's
                        // time from rest when it began at rest); -1 if it never moved
  double t_end = -1;    // when it came to rest at its end, if it did (else -1: it ran on into the next)
  bool rest_after = false;  // the machine stood still between this block and the next
  double duty = -1;         // the pen output while it ran (-1: it never moved)
  size_t steps_from = 0, steps_to = 0;  // its step events [from, to) in the step log
  size_t steps_pen_changed = 0;  // steps taken with the pen output changed since the block began
};

// The machine stood still between `block` and the next block of the same epoch.
struct RestEvent {
  size_t block = 0;
  double t_stop = -1;    // when it stopped
  double t_resume = -1;  // when the next block began
};

struct SessionEvent {
  enum class Kind { Line, Reset } kind = Kind::Line;
  size_t line = 0;    // index into FirmwareRecord::lines, in reply order
  size_t device = 0;  // a reset: its banner's index into FirmwareRecord::device
};

struct SessionRecord {
  int index = 0;
  bool power_cut = false;
  size_t rx_overruns = 0;  // bytes simavr's UART dropped (the host overfilled grbl's RX buffer)
  StepLog step_log;
  std::vector<ExecutedBlock> blocks;  // every planned block, in order
  std::vector<RestEvent> rests;       // the machine stood still with the epoch's next block still to come
  std::vector<SessionEvent> events;   // replies and resets, in grbl's order
  std::vector<Steps> epoch_start;     // where the machine stood at each boot / reset
  std::vector<std::pair<size_t, std::string>> fragment_text;  // line index -> what grbl ran of the flushed lines
  // The text grbl ran for line `index` (its own, or what fragment_text found for it).
  std::string text_ran(size_t index, const std::vector<HostLine>& lines) const {
    for (const auto& [line, ran] : fragment_text)
      if (line == index) return ran;
    return lines[index].text;
  }
  std::vector<std::string> problems;  // lines the model could not follow, steps no block explains
};

// One line per block: end (mm), how far it ran, its times. For test failure messages.
std::string describe(const SessionRecord& s, const MachineSettings& m);

// Replays the answered lines of one session (its `events` into `lines`) to find the
// blocks grbl planned, and walks the step log along them. A soft reset drops what grbl
// had planned; where it fell in the step log is read from grbl's status reports (`device`,
// in the order grbl sent them): the last one before the reset's banner says how far the
// machine had got, the first one after it where the machine stood at the reset, and
// the reset falls in the standstill that follows. O(lines + steps).
SessionRecord build_session(const StepLog& log, const std::vector<HostLine>& lines, const std::vector<SessionEvent>& events,
                            const MachineSettings& s, const std::vector<DeviceLine>& device = {});

struct FirmwareRecord {
  MachineSettings settings;
  std::vector<SessionRecord> sessions;
  std::vector<HostLine> lines;
  std::vector<DeviceLine> device;
};

// The transcript replayed against the walked blocks.
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
  double pen_down_mm = 0;  // pen-down path the firmware drew, from the step log
  // Steps the machine took after the pen output changed within their block: a feed hold
  // at a travel's end lets grbl run the next pen-down command while the last segments
  // still run (a touch of the pen a few steps long where the stroke begins anyway).
  size_t steps_pen_changed = 0;
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
