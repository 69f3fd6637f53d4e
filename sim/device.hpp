#pragma once
// What the simulated plotters share: a serving thread on a link, a model of the wire
// (byte time at the baud rate, 10 bits a byte, and a round-trip latency), a clock
// that runs `speedup` times faster than real time (everything, wire included, is in
// device time so the proportions stay those of the real machine), fault injection,
// and the record of what the pen drew.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "drivers/job/segments.hpp"
#include "sim/link.hpp"

namespace stipplot::sim {

using io::Segment;

struct LinkModel {
  double baud = 0;          // 0: bytes take no time on the wire
  double latency_ms = 0;    // round trip (USB-serial adapters: a few ms)
};

// Fault injection. Lines are counted from 1 over the protocol's lines (G-code lines,
// not '$' commands, for grbl; instructions for HPGL); replies over replies.
struct Faults {
  long drop_reply = -1;      // grbl: the reply to line K is never sent; HPGL: the K-th query reply
  long corrupt_reply = -1;   // ... is garbled
  long stall_line = -1;      // line K holds the machine for stall_ms (device time)
  double stall_ms = 0;
  long disconnect_after_bytes = -1;  // the link goes down after N received bytes
  long error_line = -1;      // line K is rejected (grbl error:N, HPGL error 1)
  int error_code = 20;
  long alarm_line = -1;      // line K raises an alarm (grbl ALARM:1, HPGL not-ready)
  double not_ready_ms = 0;   // HPGL: the operator makes it ready again after this long (0: never)
  long reset_line = -1;      // the controller resets when line K arrives (grbl: its reset input; HPGL: IN)
  // The board loses power after N received bytes: it stops where it is, its buffers and
  // position are gone, the link goes down; it boots afresh (grbl: the banner) when a
  // client opens the port again (the operator re-zeroed the machine at the origin).
  long power_loss_after_bytes = -1;
  double power_loss_after_s = -1;  // ... or this many device seconds after the first byte came
};

// How a simulator runs, whatever it simulates: its clock, its wire, its faults.
struct SimRun {
  double speedup = 1;  // device time runs this many times faster than real time
  LinkModel link;
  Faults faults;
};

struct SimStats {
  double busy_start = -1, busy_end = -1;  // device seconds: first motion start, last motion end
  double starved_s = 0;   // machine idle with nothing to do between those (waiting for data)
  size_t blocks = 0, lines = 0, errors = 0, alarms = 0;
  size_t rx_overflow = 0;  // bytes that arrived with the receive buffer full (lost)
  size_t bytes_in = 0;
  double plot_time() const { return busy_start < 0 ? 0 : busy_end - busy_start; }
  double starved_share() const { return plot_time() > 0 ? starved_s / plot_time() : 0; }
};

class SimDevice {
 public:
  explicit SimDevice(const SimRun& run);
  virtual ~SimDevice();
  SimDevice(const SimDevice&) = delete;
  SimDevice& operator=(const SimDevice&) = delete;

  // Serves on this link from a thread (replacing a link that went down).
  void attach(std::unique_ptr<SimLink> link);
  // In-process convenience: a pipe, the simulator at one end; returns the other end.
  std::unique_ptr<io::Transport> connect_loopback();
  // A pty; returns its path.
  std::string open_pty();
  void stop();
  // False after an injected disconnect, until attach() is called again.
  bool connected() const { return connected_.load(); }
  // Waits (real time) until the machine has nothing left to do or `seconds` passed.
  bool wait_idle(double seconds);
  std::vector<Segment> record() const;
  SimStats stats() const;
  std::string link_name() const;
  double device_time() const;

 protected:
  // All hooks run on the serving thread with the device clock at `t` (seconds).
  virtual void on_connect(double t) = 0;
  // A client has opened the port (a pty seen opened): an Arduino's DTR reset, if modelled.
  virtual void on_client_open(double) {}
  virtual void on_byte(char c, double t) = 0;
  virtual void advance(double t) = 0;      // run the machine up to t
  virtual double next_event() const = 0;   // device time of the next internal event
  virtual void on_disconnect(double t) = 0;
  virtual void on_power_loss(double) {}  // before the link goes down with it
  virtual bool idle() const = 0;
  void send(const std::string& s, double t);
  // Starvation bookkeeping: the machine starts / stops doing something.
  void mark_busy(double t);
  void mark_idle(double t);
  void mark_paused();  // a hold or pause: idle time then is not starvation

  mutable std::mutex m_;  // guards rec_ and stats_ against readers on other threads
  io::PenTrace rec_;  // pen-down moves and touches, by the rules io::job_segments uses
  SimStats stats_;
  Faults faults_;
  LinkModel linkm_;

 private:
  void serve();
  void disconnect(double t);
  double speedup_;
  std::chrono::steady_clock::time_point t0_;
  std::unique_ptr<SimLink> link_;  // the serve thread's alone once it runs: only it swaps links
  std::unique_ptr<SimLink> next_link_;  // a link attached while the old one may still be in use
  std::thread thread_;
  std::atomic<bool> stop_{false}, connected_{false};
  std::mutex link_m_;
  std::condition_variable link_cv_;
  bool new_link_ = false;
  struct Timed {
    char c;
    double t;
  };
  std::deque<Timed> wire_in_;
  std::deque<std::pair<double, std::string>> wire_out_;
  double last_in_ = 0, last_out_ = 0;
  double first_in_ = -1;  // device time of the first byte received
  double idle_since_ = -1;
  bool ever_busy_ = false;
  bool client_present_ = false;
  std::atomic<bool> idle_flag_{true};
};

}  // namespace stipplot::sim
