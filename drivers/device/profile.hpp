#pragma once
// Device profiles: what a writer, a driver or a simulator needs to know about one
// plotter, read from a TOML file (drivers/profiles/*.toml) into typed sections, one per
// [section] of the file. The sections go where they are used as they are: [serial] to the
// transport, [motion] to the time model and the simulators, [hpgl] and the handshake to
// the HPGL writer and streamer. Every key is required unless noted, and unknown keys are
// refused, so a typo never silently falls back to a default; errors name the file and
// the key.
#include <filesystem>
#include <string>
#include <vector>

#include "drivers/motion/ebb_motion.hpp"
#include "drivers/motion/motion_params.hpp"
#include "drivers/transport/transport.hpp"

namespace stipplot {

enum class Protocol { grbl, hpgl, ebb };
// Corner of the page at machine zero; coordinates grow away from it along each axis,
// times the axis sign (grbl machines homed to "negative space" use -1).
enum class Origin { top_left, bottom_left };
enum class PenMethod { servo, z_axis, laser, hpgl, ebb };
// How the host avoids overrunning an HPGL plotter's buffer: not at all, in-band
// XON/XOFF from the plotter, RTS/CTS in the serial driver, or asking for the free space
// (ESC.B) before sending.
enum class HpglHandshake { none, xonxoff, hardware, buffer_query };

// [machine] Travel limits in machine coordinates (mm): x in [0, travel_x], y in
// [0, travel_y] when both signs are +1; with a sign of -1 the range is [-travel, 0].
struct MachineGeometry {
  double travel_x_mm = 0, travel_y_mm = 0;
  Origin origin = Origin::top_left;
  int x_sign = 1, y_sign = 1;
  // Where machine zero sits, measured from the page's origin corner into the page (mm).
  double origin_offset_x_mm = 0, origin_offset_y_mm = 0;
  double resolution_mm = 0.01;  // coordinates are rounded to this
  double units_per_mm = 1;      // HPGL: 40 plotter units per mm
  // The paper the machine takes, as it lies on it (width along the page's x): the key
  // `sheet` ("A4 landscape", "A3 portrait", "300x200mm"), optional; without it, the travel
  // plus the origin offset. Drawings are laid out on it unless --page says otherwise.
  double sheet_width_mm = 0, sheet_height_mm = 0;
  // Machine +Y points up the page (grbl's positive space from a bottom-left zero, HPGL).
  bool y_up() const { return (origin == Origin::bottom_left) == (y_sign > 0); }
};

// [pen]
struct PenSetup {
  PenMethod method = PenMethod::servo;
  int count = 1;          // pens the machine holds (carousel), 1 = change by hand
  std::vector<int> map;   // pen i+1's home slot map[i]; empty = pen n in slot n (carousel.hpp)
  double servo_down_s = 0;    // servo: M3 S<down> lowers the pen
  double servo_up_s = 0;      //        M3 S<up> lifts it; 0 means M5
  double z_up_mm = 0, z_down_mm = 0, z_feed_mm_s = 0;  // z_axis
  double laser_power_s = 0;   // laser: M4 S<power> while "down", M5 otherwise
  double dot_dwell_s = 0;     // extra time the pen rests on a single-point stroke
  // ebb: the pen-lift servo as axicli sets it, in percent of the servo's range (0 = the
  // pulse width [ebb] servo_min, 100 = servo_max) and of its full-range sweep rate.
  double pos_up_pct = 60, pos_down_pct = 30;
  double rate_raise_pct = 75, rate_lower_pct = 50;
  double delay_up_ms = 0, delay_down_ms = 0;  // waited after the servo's own travel time
  // ebb: the lift motor. "ebb-servo" is a standard RC servo on pin RB1 (the firmware's
  // default, 8 PWM channels of 3 ms); "ebb-brushless" the narrow-band brushless servo of the
  // NextDraw (and AxiDraw's penlift 3), driven as their software does: on RB2 with one
  // channel (SC,8,1), so the rates count per 3 ms ([ebb] servo_pwm_period 0.03).
  bool ebb_brushless = false;
};

// [ebb] (protocol ebb): an EiBotBoard machine. Two motors mixed (motor 1 = x + y, motor 2
// = x - y, AxiDraw's belt layout) at `steps_per_mm` motor steps per mm of each sum (80 at
// 16x microstepping: 2032 steps/inch, axidraw_conf's native_res_factor 1016 x 2); the
// servo's pulse range in 1/12 µs units and its timing constants (axidraw_conf.py);
// moves as the firmware's accelerating LM commands (`moves = "lm"`, the default: one a
// speed ramp, firmware 2.7+) or constant-rate SM commands of at most `time_slice_ms`
// (`moves = "sm"`, any firmware); the motion FIFO lengthened to `fifo_commands` (CU,4;
// v3.x only).
struct EbbSetup {
  double steps_per_mm = 80;
  int servo_min = 9855, servo_max = 27831;
  double servo_sweep_ms = 200, servo_move_min_ms = 45, servo_move_slope_ms = 2.69;
  double servo_pwm_period = 0.24;  // axicli's rate scale: range * period / sweep per % of rate
  int time_slice_ms = 25;
  motion::EbbMoveKind moves = motion::EbbMoveKind::lm;
  int fifo_commands = 32;
  double max_step_rate_hz = 25000;  // the 25 kHz motion interrupt: one step per tick
};

// The EBB pen's servo positions, rates and the time each move takes, as axicli computes
// them from the percentages (pen_handling.py): position = min + (max - min) * pct / 100,
// rate = (max - min) * pwm_period / sweep_ms * rate_pct, and a move's time the 4th-power
// blend of (slope * dist + min) and (sweep * dist / rate_pct), plus the delay.
struct EbbPen {
  int up = 0, down = 0;          // SC,4 / SC,5
  int rate_up = 0, rate_down = 0;  // SC,11 / SC,12
  int raise_ms = 0, lower_ms = 0;  // SP,1,<raise_ms> / SP,0,<lower_ms>
  int pin = 0;                   // SP's port-B pin; 0: the firmware's default (RB1)
  int channels = 0;              // SC,8,<channels>; 0: the firmware's default (8)
};
EbbPen ebb_pen(const PenSetup& pen, const EbbSetup& e);
// The commands that set the servo up (SC,4, 5, 11, 12, and SC,8 for one channel) and that
// lower or raise the pen (SP,0/1,<ms>[,<pin>]).
std::vector<std::string> ebb_servo_setup(const EbbPen& pen);
std::string ebb_pen_command(const EbbPen& pen, bool down);

// [hpgl] (protocol hpgl only), and [serial] handshake.
struct HpglSettings {
  bool velocity = false;        // VS allowed
  double max_velocity_cm_s = 0; // VS upper limit of the device
  int max_points_per_command = 0;
  HpglHandshake handshake = HpglHandshake::none;
};

// [grbl] (protocol grbl, optional): the machine's own settings the plan depends on, as
// `$$` reports them, checked when plotting. $110/$111 are [motion] speed_up_mm_s,
// $120/$121 accel_mm_s2, $11 junction_deviation_mm, $130/$131 the travel. Without the
// section: steps from the resolution, Z like X, and grbl's default $1 of 25 ms.
struct GrblSetup {
  bool given = false;           // the profile has a [grbl] section
  double steps_per_mm_x = 100, steps_per_mm_y = 100, steps_per_mm_z = 100;  // $100-$102
  double max_rate_z_mm_s = 0;   // $112 / 60 (0: as X)
  double accel_z_mm_s2 = 0;     // $122 (0: as X)
  double idle_lock_ms = 25;     // $1: the stepper idle lock after every stop (255: none)
};

// [serial]
struct SerialSetup {
  io::SerialSettings port;    // baud and flow control, as the transport takes them
  int rx_buffer_bytes = 128;  // grbl's serial RX buffer; HPGL: the plotter's buffer
  bool newline = true;        // end every command with '\n'
  // Seconds the device may take nothing (no line answered, no buffer space freed, no
  // motion) beyond what the job's own timing allows before the plot stops (optional key).
  double watchdog_s = 20;
};

struct DeviceProfile {
  std::string name;         // profile name (the file's stem for shipped ones)
  std::string description;  // one line
  std::filesystem::path source;
  Protocol protocol = Protocol::grbl;
  MachineGeometry machine;
  MotionParams motion;
  PenSetup pen;
  HpglSettings hpgl;
  GrblSetup grbl;
  EbbSetup ebb;
  SerialSetup serial;
};

// An EBB profile's pen heights changed (percent, 0 to 100, as pos_up_pct/pos_down_pct), with
// the pen-lift and drop times that follow from them ([motion] pen_lift_s, pen_drop_s).
void set_ebb_pen_heights(DeviceProfile& p, double up_pct, double down_pct);

// Parses and validates a profile file; throws UserError naming the file and key.
// O(file size).
DeviceProfile load_profile_file(const std::filesystem::path& path);
// Parses profile text (for tests); `origin` names it in errors.
DeviceProfile parse_profile(const std::string& toml_text, const std::string& origin);

// Directories searched for shipped profiles, in order: $STIPPLOT_PROFILES, a profiles/
// folder next to the executable, ../share/stipplot/profiles, the source tree's.
std::vector<std::filesystem::path> profile_dirs();
// Shipped profiles by name (each *.toml in the first directory holding it), sorted by name.
// O(total size of the profile files).
std::vector<DeviceProfile> list_profiles();
// NAME (a shipped profile) or PATH (anything with a '/' or ending in .toml).
DeviceProfile find_profile(const std::string& name_or_path);

inline constexpr const char* kDefaultProfile = "grbl-servo";

std::string to_string(Protocol p);
std::string to_string(PenMethod m);
// The [pen] method as the profile names it (ebb-servo or ebb-brushless for an EBB).
std::string pen_method_name(const PenSetup& pen);

// The handshake as `plot --handshake` names it: escb (buffer_query), xonxoff, hardware.
HpglHandshake parse_hpgl_handshake(const std::string& s);

}  // namespace stipplot
