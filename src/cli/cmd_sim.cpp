// stipplot sim grbl|hpgl: a simulated plotter on a pseudo-terminal, until killed.
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <thread>

#include "cli/commands.hpp"
#include "geometry/page.hpp"
#include "sim/grbl_sim.hpp"
#include "sim/hpgl_sim.hpp"
#include "sim/record.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"
#include "util/output_paths.hpp"

namespace stipplot::cli {

namespace {
std::atomic<bool> g_sim_stop{false};
extern "C" void on_sim_signal(int) { g_sim_stop = true; }

struct SimArgs {
  std::string kind;
  double speedup = 1, baud = 0, latency_ms = 0;
  int rx_buffer = 128, buffer = 1024;
  bool xonxoff = false, soft_limits = false, homing = false, reset_on_open = false;
  double travel_x = 300, travel_y = 300;
  std::string record_png, record_svg, record_out, page = "A4";
  sim::Faults faults;
  bool once = false;
};

// The simulator the options describe (grbl's or the HPGL plotter's own defaults for the rest).
std::unique_ptr<sim::SimDevice> make_simulator(const SimArgs& a) {
  const sim::SimRun run{a.speedup, {a.baud, a.latency_ms}, a.faults};
  if (a.kind == "grbl") {
    sim::GrblSimConfig c;
    static_cast<sim::SimRun&>(c) = run;
    c.rx_buffer = a.rx_buffer;
    c.soft_limits = a.soft_limits;
    c.homing = a.homing;
    c.reset_on_open = a.reset_on_open;
    c.travel = {a.travel_x, a.travel_y, 50};
    return std::make_unique<sim::GrblSim>(c);
  }
  sim::HpglSimConfig c;
  static_cast<sim::SimRun&>(c) = run;
  c.buffer_bytes = a.buffer;
  c.xonxoff = a.xonxoff;
  return std::make_unique<sim::HpglSim>(c);
}

// One pen-down segment a line, "x0 y0 x1 y1 pen" in device units (mm, plotter units):
// what a script compares with the job.
void write_record_text(const std::vector<io::Segment>& rec, const std::string& path) {
  std::string text;
  char b[160];
  for (const io::Segment& s : rec) {
    std::snprintf(b, sizeof b, "%.9g %.9g %.9g %.9g %d\n", s.x0, s.y0, s.x1, s.y1, s.pen);
    text += b;
  }
  write_file_atomic(path, text);
}

// Serves until Ctrl-C or SIGTERM (with --once, until the first client's job is drawn),
// then writes what was drawn.
void run_sim(const SimArgs& a) {
  require_positive("--speedup", a.speedup);
  require_nonnegative("--baud", a.baud);
  require_nonnegative("--latency-ms", a.latency_ms);
  check_output_paths({}, {{"--record-png", a.record_png}, {"--record-svg", a.record_svg}, {"--record-out", a.record_out}});
  PageSpec ps = parse_page(a.page);
  Page page;
  page.width_mm = ps.width_mm;
  page.height_mm = ps.height_mm;
  std::unique_ptr<sim::SimDevice> dev = make_simulator(a);
  // HPGL draws in plotter units, y up from the lower left.
  const bool hpgl = a.kind != "grbl";
  const double upm = hpgl ? sim::HpglSimConfig{}.units_per_mm : 1, flip = hpgl ? ps.height_mm : 0;
  std::signal(SIGINT, on_sim_signal);
  std::signal(SIGTERM, on_sim_signal);
  std::printf("%s\n", dev->open_pty().c_str());
  std::fflush(stdout);
  while (!g_sim_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (!dev->connected()) {  // an injected disconnect: the device comes back on a new pty
      std::printf("%s\n", dev->open_pty().c_str());
      std::fflush(stdout);
    }
    if (a.once && !dev->record().empty() && dev->wait_idle(0)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      if (dev->wait_idle(0)) break;
    }
  }
  dev->stop();
  auto rec = dev->record();
  if (!a.record_png.empty()) sim::write_record_png(rec, page, upm, a.record_png, flip);
  if (!a.record_svg.empty()) sim::write_record_svg(rec, page, upm, a.record_svg, flip);
  if (!a.record_out.empty()) write_record_text(rec, a.record_out);
  sim::SimStats s = dev->stats();
  std::fprintf(stderr, "simulator: %zu lines, %zu segments drawn, plot time %.1f s (device), starved %.2f%%\n", s.lines,
               rec.size(), s.plot_time(), 100 * s.starved_share());
}

}  // namespace

void register_sim(CLI::App& app) {
  auto a = std::make_shared<SimArgs>();
  CLI::App* cmd = app.add_subcommand("sim", "Run a simulated grbl or HPGL plotter on a pseudo-terminal");
  cmd->footer(
      "Prints the pty path, then serves until Ctrl-C; plot to it with --port PATH. On exit it writes what\n"
      "it drew (--record-png/--record-svg). Faults count lines from 1 (G-code lines or HPGL instructions).\n"
      "Example: stipplot sim grbl --speedup 10 --record-png drawn.png   (then: stipplot plot job.gcode --port /dev/pts/N)");
  cmd->add_option("kind", a->kind, "grbl | hpgl")->required()->check(CLI::IsMember({"grbl", "hpgl"}));
  cmd->add_option("--speedup", a->speedup, "Run this many times faster than real time")->capture_default_str();
  cmd->add_option("--baud", a->baud, "Model the wire at this baud rate (10 bits a byte); 0 = instant")->capture_default_str();
  cmd->add_option("--latency-ms", a->latency_ms, "Round-trip latency of the link (USB-serial: a few ms)")->capture_default_str();
  cmd->add_option("--rx-buffer", a->rx_buffer, "grbl receive buffer bytes")->capture_default_str();
  cmd->add_option("--buffer", a->buffer, "HPGL input buffer bytes")->capture_default_str();
  cmd->add_flag("--xonxoff", a->xonxoff, "HPGL: send XOFF/XON as the buffer fills and drains");
  cmd->add_flag("--soft-limits", a->soft_limits, "grbl: enable soft limits ($20=1, with homing $22=1): machine space -$130..0");
  cmd->add_flag("--homing", a->homing, "grbl: homing enabled ($22=1): locked in ALARM at power-on until $H or $X");
  cmd->add_flag("--reset-on-open", a->reset_on_open, "grbl: reboot when a client opens the port, as an Arduino does (DTR)");
  cmd->add_option("--travel-x", a->travel_x, "grbl: X travel in mm ($130)")->capture_default_str();
  cmd->add_option("--travel-y", a->travel_y, "grbl: Y travel in mm ($131)")->capture_default_str();
  cmd->add_option("--record-png", a->record_png, "On exit, render what was drawn to this PNG");
  cmd->add_option("--record-svg", a->record_svg, "On exit, write what was drawn as SVG");
  cmd->add_option("--record-out", a->record_out, "On exit, write what was drawn as text: x0 y0 x1 y1 pen, a segment a line");
  cmd->add_option("--page", a->page, "Page for the record rendering")->capture_default_str();
  auto* g = "Fault injection";
  cmd->add_option("--drop-reply", a->faults.drop_reply, "Never answer line K (HPGL: the K-th query)")->group(g);
  cmd->add_option("--corrupt-reply", a->faults.corrupt_reply, "Garble the reply to line K")->group(g);
  cmd->add_option("--stall-line", a->faults.stall_line, "Stall at line K ...")->group(g);
  cmd->add_option("--stall-ms", a->faults.stall_ms, "... for this many ms (device time)")->group(g);
  cmd->add_option("--disconnect-after", a->faults.disconnect_after_bytes, "Hang up after N received bytes (then a new pty)")->group(g);
  cmd->add_option("--power-loss-after", a->faults.power_loss_after_bytes,
                  "Lose power after N received bytes: stop, forget buffers and position, hang up; boot afresh when the "
                  "port is opened again (a new pty)")->group(g);
  cmd->add_option("--power-loss-after-s", a->faults.power_loss_after_s,
                  "... or this many device seconds after the first byte")->group(g);
  cmd->add_option("--error-line", a->faults.error_line, "Reject line K (grbl error:20, HPGL error 1)")->group(g);
  cmd->add_option("--alarm-line", a->faults.alarm_line, "Alarm at line K (grbl ALARM:1, HPGL not ready)")->group(g);
  cmd->add_option("--reset-line", a->faults.reset_line, "The controller resets when line K arrives (grbl: its reset input)")->group(g);
  cmd->add_flag("--once", a->once, "Exit when the first client has finished and the machine is idle (for scripts)")->group(g);
  cmd->callback([a] { run_sim(*a); });
}

}  // namespace stipplot::cli
