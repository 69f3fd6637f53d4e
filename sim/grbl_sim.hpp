#pragma once
// A simulated grbl 1.1 pen plotter: the start-up banner, a 128-byte receive buffer,
// a 15-block planner that drains at the pace of a trapezoid motion model with
// junction-deviation corner speeds, ok / error:N, status reports, hold / resume /
// soft reset, $$ settings, soft limits (ALARM:2), $C check mode, and a record of every
// pen-down move. The pen is down while the spindle runs with S > 0 (servo or laser)
// or while Z is below 0.
#include <array>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "drivers/motion/motion_params.hpp"
#include "drivers/device/profile.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "sim/device.hpp"

namespace stipplot::sim {

struct GrblSimConfig : SimRun {
  MotionParams motion;       // speeds, acceleration, junction deviation, planner size
  double z_speed_mm_s = 20, z_accel_mm_s2 = 500;
  double travel_x = 300, travel_y = 300, travel_z = 50;  // soft-limit box: [0,X] x [0,Y] x [-Z,Z]
  bool soft_limits = false;  // $20 (needs $22 homing, as real grbl)
  io::GcodePenRule pen;      // which spindle/Z states mean "pen down"
  int rx_buffer = 128;
};

// The simulator of the device a profile describes: its motion, pen rule, travel and RX
// buffer (the link, speed-up and faults are left to the caller).
GrblSimConfig grbl_sim_config(const DeviceProfile& p);

class GrblSim final : public SimDevice {
 public:
  explicit GrblSim(const GrblSimConfig& cfg);
  ~GrblSim() override;
  static constexpr const char* banner = "Grbl 1.1h ['$' for help]";

 protected:
  void on_connect(double t) override;
  void on_byte(char c, double t) override;
  void advance(double t) override;
  double next_event() const override;
  void on_disconnect(double t) override;
  bool idle() const override;

 private:
  struct Block {
    double x0, y0, z0, x1, y1, z1;
    double len, ux, uy, uz;
    double v_nom, accel;
    double v_junction = 0;  // max entry speed from the corner with the previous block
    bool pen_down;
    // set when it starts:
    double v_entry = 0, v_exit = 0, duration = 0, elapsed = 0;
  };
  // What a line asks for, on a copy of the modal state.
  struct LineEffect {
    int motion = 0;
    bool absolute = true, inches = false;
    double feed = 0, s_val = 0;
    bool spindle_on = false;
    bool dwell = false, m0 = false, m2 = false, spindle_cmd = false, have_p = false;
    double p = 0;
    bool ax[3] = {false, false, false};
    double val[3] = {0, 0, 0};
    double target[3] = {0, 0, 0};  // where the axes go (mm, machine)
    bool axes() const { return ax[0] || ax[1] || ax[2]; }
  };
  void process(double t);                      // parse lines from RX while possible
  enum class Result { Done, Blocked };
  Result execute_line(const std::string& line, double t);
  Result execute_system(const std::string& line, double t);
  int interpret(const std::string& line, LineEffect& e) const;
  Result accept(const LineEffect& e, long no, double t);
  void queue_move(const double target[3], double feed_mm_s, double t);
  bool outside_soft_limits(const double target[3]);
  void reply(long no, const std::string& r, double t);  // with the reply faults of line `no`
  void start_block(double t);
  void finish_block(double t);
  void halt();
  void reset(double t);
  void alarm(int code, double t);
  void status(double t);
  std::string settings_text() const;
  bool pen_down_state() const;
  bool machine_busy() const { return current_.has_value() || !planner_.empty() || dwell_until_ > 0; }
  void set_pen(bool down);
  double position_in_block(const Block& b, double elapsed, double& x, double& y, double& z) const;

  GrblSimConfig cfg_;
  std::map<int, double> settings_;
  std::string rx_;         // receive buffer (bytes not yet taken by the parser)
  std::optional<std::string> line_;  // line taken from RX, waiting for the planner / a sync
  std::deque<Block> planner_;
  std::optional<Block> current_;
  double prev_exit_v_ = 0;
  double last_ux_ = 0, last_uy_ = 0, last_uz_ = 0, last_v_nom_ = 0;
  long dwell_no_ = -1;
  bool have_last_dir_ = false;
  // Modal state and position as the parser sees it (end of the last planned block).
  double px_ = 0, py_ = 0, pz_ = 0;
  double feed_ = 0, spindle_s_ = 0;
  bool spindle_on_ = false, absolute_ = true, inches_ = false;
  int motion_mode_ = 0;
  // Machine state.
  bool hold_ = false, check_ = false, alarm_ = false, pause_m0_ = false, need_reset_ = false;
  bool spindle_stopped_in_hold_ = false;
  double dwell_until_ = 0;
  bool dwell_ok_pending_ = false;
  double stall_until_ = 0;
  double mx_ = 0, my_ = 0, mz_ = 0;  // machine position at the last advance()
  double now_ = 0;
  long lines_seen_ = 0, replies_ = 0;
  bool overflow_line_ = false;
};

}  // namespace stipplot::sim
