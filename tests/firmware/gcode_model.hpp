#pragma once
// grbl 1.1's view of a G-code stream, written from grbl's source (gcode.c, planner.c)
// and independent of stipplot's own parser, so the firmware tests do not check the
// driver against itself: which lines move the machine (and by how many steps: grbl
// plans a block only for a move of at least one step), which change the pen, which make
// grbl empty its planner first; and the marks a pen leaves (segments drawn with the pen
// down, dots where it went down and up without moving).
#include <cstddef>
#include <string>
#include <vector>

namespace firmware {

struct Steps {
  long x = 0, y = 0, z = 0;
  friend bool operator==(const Steps&, const Steps&) = default;
};

// The machine settings the tests depend on, from a settings file ($N=V lines).
struct MachineSettings {
  double steps_per_mm[3] = {250, 250, 250};  // $100-$102 (grbl's defaults until set)
  double max_rate_mm_min[3] = {500, 500, 500};  // $110-$112
  double accel_mm_s2[3] = {10, 10, 10};       // $120-$122
  int status_mask = 1;                        // $10: 2 adds Bf: (planner blocks, RX bytes free)
  double spindle_max = 1000;                  // $30: the S that gives full PWM duty
  double idle_lock_ms = 25;                   // $1: grbl's stepper idle delay when motion stops
  bool soft_limits = false, homing = false;   // $20, $22
  static MachineSettings parse(const std::string& text);
  static MachineSettings load(const std::string& path);
};

// How the pen is moved. Servo (and laser): down while the spindle runs with S above
// `servo_up_s`. Z axis: down while Z is below `z_down_below_mm`.
struct PenRule {
  enum class Kind { Servo, ZAxis } kind = Kind::Servo;
  double servo_up_s = 0;
  double z_down_below_mm = 1.5;
  static PenRule servo(double up_s = 0) { return {Kind::Servo, up_s, 0}; }
  static PenRule z_axis(double down_below_mm) { return {Kind::ZAxis, 0, down_below_mm}; }
  // The shipped profiles: grbl-servo and grbl-laser (servo), grbl-z (Z 3 up / 0 down).
  static PenRule for_profile(const std::string& name);
};

// What one line does.
struct LineEffect {
  bool motion = false;  // a G0/G1 move (a planner block when from != to)
  bool rapid = false;
  Steps from, to;
  bool spindle_change = false;  // M3/M4/M5, or S changed while the spindle runs
  int pen_before = -1;          // servo pen state set before the move (grbl's order of execution): -1 unchanged, 0 up, 1 down
  int pen_after = -1;           // ... after it (M2/M30 stop the spindle last)
  bool sync = false;            // grbl empties its planner before running it (G4, M0-M2, spindle changes)
  double dwell_s = 0;
  bool pause = false;        // M0/M1
  bool program_end = false;  // M2/M30
  bool check_mode_toggle = false;  // $C
  bool system = false;             // a '$' line
};

// One line at a time, as grbl's parser takes them (after an "ok"; a line grbl answered
// with error:N changed nothing and must not be fed). Throws std::runtime_error for
// G-code it does not follow (arcs, G92, G10, G28, G53, ...) naming the line.
class GcodeInterpreter {
 public:
  explicit GcodeInterpreter(const MachineSettings& s, PenRule rule);
  LineEffect feed(const std::string& line);
  // grbl's soft reset / power-on: modal state to defaults, machine at `pos`.
  void reset(Steps pos);
  Steps position() const { return pos_; }
  bool pen_down() const;
  bool check_mode() const { return check_mode_; }
  const PenRule& rule() const { return rule_; }

 private:
  MachineSettings set_;
  PenRule rule_;
  Steps pos_;
  double target_mm_[3] = {0, 0, 0};  // grbl keeps the programmed position in mm (gc_state.position)
  bool rapid_ = true, absolute_ = true, inches_ = false, check_mode_ = false;
  int spindle_ = 0;  // 0 off, 3 CW, 4 CCW
  double s_ = 0;
};

// A mark on the paper, in machine steps. Segments are undirected; a Partial is a
// segment cut short (power cut or reset while it was being drawn).
struct Mark {
  enum class Kind { Segment, Dot, Partial } kind = Kind::Segment;
  Steps a, b;
};

// Collects the marks of executed moves and pen changes.
class MarkCollector {
 public:
  MarkCollector(PenRule rule, double z_steps_per_mm) : rule_(rule), z_steps_per_mm_(z_steps_per_mm) {}
  void pen(bool down, Steps at);  // a servo pen change grbl executed at `at` (ignored for a Z pen)
  // A move grbl executed from `from` to `to` (`to` = where it stopped if !complete).
  // For a Z pen the pen state follows Z.
  void move(Steps from, Steps to, bool complete);
  void finish();  // a pen still down and unmoved made a dot
  const std::vector<Mark>& marks() const { return marks_; }
  bool down() const { return down_; }

 private:
  bool z_down(long z_steps) const;
  void set_down(bool down, Steps at);
  PenRule rule_;
  double z_steps_per_mm_;
  bool down_ = false, moved_ = false;
  Steps at_;
  std::vector<Mark> marks_;
};

// The marks a job draws when every line runs once, from the machine at 0,0,0 pen up.
// O(length of the job).
std::vector<Mark> expected_marks(const std::string& gcode, const MachineSettings& s, const PenRule& rule);

// grbl's line filter (protocol.c): whitespace, control characters and comments dropped,
// letters capitalised. "G1 X1 (go) ; now" -> "G1X1".
std::string grbl_line_filter(const std::string& raw);

// Splits G-code text into lines (grbl ends a line at '\n' or '\r'; empty lines dropped).
std::vector<std::string> gcode_lines(const std::string& text);

}  // namespace firmware
