#pragma once
// A simulated grbl 1.1 pen plotter: the start-up banner, a 128-byte receive buffer,
// grbl's own planner and stepper timing (drivers/motion/grbl_motion.hpp: per-axis limits,
// junction deviation, a 15-block look-ahead, the $1 stepper idle lock), ok / error:N,
// status reports with buffer state, feed hold / resume / soft reset, M0 pauses, G4 dwells
// in grbl's 50 ms steps, $$ settings that change the motion, soft limits in grbl's
// negative machine space (ALARM:2), a homing lock at power-on, $C check mode, and a
// record of every pen-down move. The pen is down while the spindle runs with S > 0
// (servo or laser) or while Z is below the pen rule's height.
//
// An Arduino resets when its port is opened (DTR): with `reset_on_open` every client
// that opens the port reboots the board (planner and buffers lost, position zeroed; the
// record assumes the operator re-zeroed the machine at the origin).
#include <array>
#include <map>
#include <optional>
#include <string>

#include "drivers/device/profile.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/motion/grbl_motion.hpp"
#include "sim/device.hpp"

namespace stipplot::sim {

struct GrblSimConfig : SimRun {
  motion::GrblSettings machine;           // $100-$122, $11, $1, the planner's size
  std::array<double, 3> travel{300, 300, 50};  // $130-$132
  bool soft_limits = false;               // $20 (grbl needs $22 homing for it)
  bool homing = false;                    // $22: locked in ALARM at power-on until $H or $X
  bool laser_mode = false;                // $32
  int status_mask = 3;                    // $10: 2 adds Bf: (buffer state) to status reports
  io::GcodePenRule pen;                   // which spindle/Z states mean "pen down"
  int rx_buffer = 128;
  bool reset_on_open = false;             // DTR auto-reset of an Arduino
  double boot_s = 0.5;                    // bootloader time before the banner (device seconds)
};

// The simulator of the device a profile describes: the settings its [grbl] section and
// [motion] expect, its pen rule, travel and RX buffer (the link, speed-up and faults
// are left to the caller).
GrblSimConfig grbl_sim_config(const DeviceProfile& p);

class GrblSim final : public SimDevice {
 public:
  explicit GrblSim(const GrblSimConfig& cfg);
  ~GrblSim() override;
  static constexpr const char* banner = "Grbl 1.1h ['$' for help]";
  // Times the board was rebooted by a port open (reset_on_open).
  size_t boots() const;

 protected:
  void on_connect(double t) override;
  void on_client_open(double t) override;
  void on_byte(char c, double t) override;
  void advance(double t) override;
  double next_event() const override;
  void on_disconnect(double t) override;
  void on_power_loss(double t) override;
  bool idle() const override;

 private:
  // What a line asks for, on a copy of the modal state.
  struct LineEffect {
    int motion = 0;
    bool absolute = true, inches = false;
    double feed = 0, s_val = 0;
    int spindle = 0;  // 0 off, 3, 4
    bool dwell = false, m0 = false, m2 = false, have_p = false;
    double p = 0;
    bool ax[3] = {false, false, false};
    double val[3] = {0, 0, 0};
    motion::Vec3 target{};  // where the axes go (mm, machine)
    bool axes() const { return ax[0] || ax[1] || ax[2]; }
  };
  enum class Result { Done, Blocked };
  void process(double t);  // parse lines from RX while grbl's main loop may
  Result execute_line(const std::string& line, double t);
  Result execute_system(const std::string& line, double t);
  int interpret(const std::string& line, LineEffect& e) const;
  Result accept(const LineEffect& e, long no, double t);
  bool outside_soft_limits(const motion::Vec3& target) const;
  void reply(long no, const std::string& r, double t);  // with the reply faults of line `no`
  void run_motion(double t);                            // the machine up to t, recording
  void halt(double t);
  void reset(double t);
  long line_under_way() const;
  void boot(double t);
  void alarm(int code, double t);
  void status(double t);
  std::string settings_text() const;
  void apply_settings();  // $$ values -> the motion model (when idle)
  bool pen_down_state() const;
  // Blocks held by a feed hold still count: grbl's sync waits for an empty planner.
  bool machine_busy() const { return motion_.busy() || motion_.planned() > 0 || dwell_until_ > 0; }
  void set_pen(bool down);
  motion::Vec3 traced_position() const;  // the caller holds m_

  GrblSimConfig cfg_;
  std::map<int, double> settings_;
  motion::GrblMotion motion_;
  std::string rx_;                    // receive buffer (bytes not yet taken by the parser)
  std::optional<std::string> line_;   // line taken from RX, waiting for the planner / a sync
  // Modal state as the parser sees it; its position is the end of the last planned move.
  motion::Vec3 parser_pos_{};
  double feed_ = 0, spindle_s_ = 0;
  int spindle_ = 0;
  bool absolute_ = true, inches_ = false;
  int motion_mode_ = 0;
  // Machine state.
  bool hold_ = false, check_ = false, alarm_ = false, pause_m0_ = false, need_reset_ = false;
  bool spindle_stopped_in_hold_ = false;
  double dwell_until_ = 0;
  long dwell_no_ = -1;
  double stall_until_ = 0;
  double booting_until_ = -1;  // bootloader: bytes are ignored, the banner comes at the end
  double now_ = 0;
  long lines_seen_ = 0, replies_ = 0;
  size_t boots_ = 0;
  long interrupted_ = -2;  // the line an alarm cut short, answered at the reset (-2: none)
};

}  // namespace stipplot::sim
