#pragma once
// A simulated HPGL pen plotter (HP 7475A-like): a finite input buffer that sends
// XOFF/XON as it fills and drains (when handshake is xonxoff), device-control
// queries answered at once (ESC.B free buffer bytes, ESC.O extended status, ESC.E,
// ESC.L buffer size), instructions IN SP PU PD PA PR VS OE OS OI executed at the pace
// of the motion model, freeing their buffer bytes when done.
#include <deque>
#include <string>

#include "drivers/device/profile.hpp"
#include "drivers/motion/hpgl_motion.hpp"
#include "drivers/motion/motion_params.hpp"
#include "sim/device.hpp"

namespace stipplot::sim {

struct HpglSimConfig : SimRun {
  MotionParams motion;        // mm/s, mm/s^2; VS overrides the pen-down speed
  double units_per_mm = 40;   // HP plotter units: 0.025 mm
  int buffer_bytes = 1024;
  bool xonxoff = false;       // send XOFF when fewer than xoff_free bytes are free, XON above xon_free
  int xoff_free = 128, xon_free = 512;
};

// The simulator of the device a profile describes: its motion, plotter units, buffer
// and handshake (the link, speed-up and faults are left to the caller).
HpglSimConfig hpgl_sim_config(const DeviceProfile& p);

class HpglSim final : public SimDevice {
 public:
  explicit HpglSim(const HpglSimConfig& cfg);
  ~HpglSim() override;
  size_t overflow_bytes() const { return stats().rx_overflow; }

 protected:
  void on_connect(double t) override;
  void on_byte(char c, double t) override;
  void advance(double t) override;
  double next_event() const override;
  void on_disconnect(double t) override;
  void on_power_loss(double t) override;
  bool idle() const override;

 private:
  void start_next(double t);
  size_t complete_instruction() const;
  double execute(const std::string& mn, const std::vector<double>& nums, double t);
  void query_reply(const std::string& r, double t);
  void device_control(char cmd, double t);
  void check_flow(double t);
  int free_bytes() const { return cfg_.buffer_bytes - static_cast<int>(buf_.size()); }

  HpglSimConfig cfg_;
  motion::HpglMotion plotter_;  // the job timer's model of the same plotter
  std::string buf_;            // bytes received, not yet executed
  size_t exec_bytes_ = 0;      // length of the instruction being executed (still in buf_)
  double busy_until_ = -1;     // end of the instruction being executed
  bool executing_ = false;
  // Pending effects of the executing instruction, applied when it ends.
  std::vector<std::pair<double, double>> pending_moves_;
  int esc_state_ = 0;          // 0 none, 1 got ESC, 2 got ESC '.', 3 in parameters
  char esc_cmd_ = 0;
  bool xoff_sent_ = false, not_ready_ = false;
  double ready_at_ = -1;       // device time the not-ready fault ends (-1: not scheduled)
  int error_ = 0;
  bool absolute_ = true, pen_down_ = false, pending_pen_ = false;
  double x_ = 0, y_ = 0;
  double vs_mm_s_;
  long instr_seen_ = 0, replies_ = 0;
  double now_ = 0;
};

}  // namespace stipplot::sim
