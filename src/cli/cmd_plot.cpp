// stipplot plot: stream a job to a plotter (serial, USB, or the in-process simulator),
// with progress, pause/abort on Ctrl-C, check mode, and resume from the journal.
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <algorithm>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/plot_job.hpp"
#include "drivers/device/pen_rule.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/segments.hpp"
#include "drivers/stream/grbl/streamer.hpp"
#include "drivers/stream/hpgl/streamer.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/transport/devices.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "geometry/page.hpp"
#include "sim/grbl_sim.hpp"
#include "sim/hpgl_sim.hpp"
#include "sim/record.hpp"
#include "util/progress.hpp"

namespace stipplot::cli {

namespace {

std::atomic<int> g_interrupts{0};
extern "C" void on_plot_sigint(int) { g_interrupts.fetch_add(1); }

struct PlotArgs {
  std::string input, profile, port, resume, job_out;
  bool page_given = false, flow_given = false, handshake_given = false, rx_buffer_given = false;
  bool sim = false, check = false, json = false, quiet = false, skip_errors = false, unlock = false, newline = false;
  std::string stream = "counting", handshake = "escb", flow = "none";
  int baud = 0, rx_buffer = 128;
  double sim_speedup = 20, sim_baud = 115200, sim_latency_ms = 2;
  std::string sim_out, page = "A4";
};

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("cannot read " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string hex(uint64_t v) {
  char b[24];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

bool stdin_tty() { return ::isatty(STDIN_FILENO) == 1; }

}  // namespace

void register_plot(CLI::App& app) {
  auto a = std::make_shared<PlotArgs>();
  CLI::App* cmd = app.add_subcommand("plot", "Plot a job on a plotter or the simulated plotter");
  cmd->footer(
      "IN is a .gcode/.nc (grbl) or .hpgl/.plt job. Without --port or --sim the one plausible device\n"
      "(`stipplot devices`) is used. Ctrl-C pauses (feed hold, pen lifted) and asks whether to resume or\n"
      "abort. The journal IN.journal records every line the device acknowledged; after a disconnect,\n"
      "power loss or abort, `stipplot plot --resume IN` lifts the pen, travels to where it stopped and\n"
      "continues. --sim plots on the in-process simulator (over a pty) and writes IN.sim.png/.svg.\n"
      "Examples: stipplot plot job.gcode --sim\n"
      "          stipplot plot job.gcode --port /dev/ttyUSB0 --check\n"
      "          stipplot plot --resume job.gcode --port /dev/ttyUSB0");
  cmd->add_option("input", a->input, "Job file (.gcode, .hpgl)");
  cmd->add_option("--profile", a->profile, "Device profile (name or PATH): serial settings, handshake, pen, motion");
  cmd->add_option("--job", a->job_out, "Where to write the job planned from an SVG (default: IN with .gcode/.hpgl)");
  cmd->add_option("--port", a->port, "Serial port (/dev/ttyUSB0, COM3), usb:VID:PID, or file:PATH");
  cmd->add_flag("--sim", a->sim, "Plot on the in-process simulated plotter");
  cmd->add_option("--resume", a->resume, "Continue job JOB from its journal (JOB.journal)");
  cmd->add_flag("--check", a->check, "grbl: validate every line in check mode ($C) before the pen moves");
  cmd->add_option("--stream", a->stream, "grbl streaming: counting (character counting) | wait (send-and-wait)")
      ->capture_default_str();
  auto* rx = cmd->add_option("--rx-buffer", a->rx_buffer, "grbl receive buffer bytes (default: profile, 128)");
  auto* hs = cmd->add_option("--handshake", a->handshake, "HPGL: escb (poll ESC.B) | xonxoff | hardware (default: profile, escb)");
  cmd->add_flag("--newline", a->newline, "HPGL: end each instruction with a newline");
  cmd->add_option("--baud", a->baud, "Serial baud rate (default: 115200 grbl, 9600 HPGL)");
  auto* fl = cmd->add_option("--flow", a->flow, "Serial flow control: none | xonxoff | rtscts (default: profile, none)");
  cmd->add_flag("--skip-errors", a->skip_errors, "grbl error:N: warn and continue instead of stopping");
  cmd->add_flag("--unlock", a->unlock, "grbl: send $X if it starts in ALARM");
  cmd->add_flag("--json", a->json, "One-line JSON summary on stdout; JSON progress lines on stderr");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress bar or notes");
  auto* g = "Simulator";
  cmd->add_option("--sim-speedup", a->sim_speedup, "Simulated plotter runs this many times faster")->capture_default_str()->group(g);
  cmd->add_option("--sim-baud", a->sim_baud, "Simulated wire baud rate")->capture_default_str()->group(g);
  cmd->add_option("--sim-latency-ms", a->sim_latency_ms, "Simulated round-trip latency")->capture_default_str()->group(g);
  cmd->add_option("--sim-out", a->sim_out, "Write what the simulator drew to PREFIX.png and PREFIX.svg")->group(g);
  auto* pg = cmd->add_option("--page", a->page, "Page for the simulator's rendering (default: fitted to what was drawn)")->group(g);
  cmd->callback([a, rx, hs, fl, pg] {
    auto t0 = std::chrono::steady_clock::now();
    PlotArgs& A = *a;
    A.rx_buffer_given = rx->count() > 0;
    A.handshake_given = hs->count() > 0;
    A.flow_given = fl->count() > 0;
    A.page_given = pg->count() > 0;
    if (A.input.empty() && A.resume.empty()) throw UserError("give a job to plot, or --resume JOB");
    if (A.sim && !A.port.empty()) throw UserError("--sim and --port exclude each other");
    require_positive("--sim-speedup", A.sim_speedup);
    require_nonnegative("--sim-baud", A.sim_baud);
    require_nonnegative("--sim-latency-ms", A.sim_latency_ms);
    // The job and its journal.
    PreparedJob pj;
    io::JournalState resume_state;
    bool resuming = !A.resume.empty();
    if (resuming) {
      pj = {A.resume, dialect_of(A.resume), A.profile};
      resume_state = io::Journal::load(io::Journal::path_for(A.resume));
      if (resume_state.complete) throw UserError("job " + A.resume + " was already plotted to the end (journal says done)");
      if (A.port.empty() && !A.sim) A.port = resume_state.header.port;
    } else {
      pj = prepare_job({A.input, A.profile, A.job_out});
    }
    std::string text = read_file(pj.path);
    std::string hash = hex(io::fnv1a64(text));
    if (resuming && resume_state.header.job_hash != hash)
      throw UserError("job " + pj.path + " changed since it was started (its journal belongs to another version)");
    DeviceProfile dev = plot_profile(pj.profile.empty() ? A.profile : pj.profile, pj.dialect);
    const io::GcodePenRule pen_rule = gcode_pen_rule(dev);
    io::Job job = pj.dialect == io::Dialect::Hpgl ? io::parse_hpgl_job(text) : io::parse_gcode_job(text, pen_rule);
    if (job.lines.empty()) throw UserError("job " + pj.path + " has no lines to plot");
    bool grbl = pj.dialect == io::Dialect::GCode;
    auto log = [&A](const std::string& s) {
      if (!A.quiet) std::fprintf(stderr, "stipplot: %s\n", s.c_str());
    };
    // The device.
    if (A.baud > 0) dev.serial.port.baud = A.baud;
    if (A.flow_given) dev.serial.port.flow = io::parse_flow_control(A.flow);
    if (A.rx_buffer_given && grbl) dev.serial.rx_buffer_bytes = A.rx_buffer;
    if (A.handshake_given) dev.hpgl.handshake = parse_hpgl_handshake(A.handshake);
    dev.serial.newline = dev.serial.newline || A.newline;
    const io::SerialSettings& ser = dev.serial.port;
    const bool xonxoff = dev.hpgl.handshake == HpglHandshake::xonxoff;
    std::unique_ptr<sim::SimDevice> simdev;
    std::unique_ptr<io::Transport> port;
    std::string port_name;
    if (A.sim) {
      if (grbl) {
        sim::GrblSimConfig c = sim::grbl_sim_config(dev);
        c.speedup = A.sim_speedup;
        c.link = {A.sim_baud, A.sim_latency_ms};
        simdev = std::make_unique<sim::GrblSim>(c);
      } else {
        sim::HpglSimConfig c = sim::hpgl_sim_config(dev);
        c.speedup = A.sim_speedup;
        c.link = {A.sim_baud, A.sim_latency_ms};
        simdev = std::make_unique<sim::HpglSim>(c);
      }
      port_name = simdev->open_pty();
      auto ps = std::make_unique<io::PosixSerial>(port_name, ser);
      if (xonxoff && A.sim_baud > 0) ps->pace(A.sim_baud / 10 * A.sim_speedup);
      port = std::move(ps);
    } else {
      port_name = A.port.empty() ? io::choose_port(io::list_devices()) : A.port;
      port = io::open_port(port_name, ser);
    }
    log("plotting " + pj.path + " (" + std::to_string(job.lines.size()) + " lines) on " + port->describe());
    // Progress, and Ctrl-C: pause, then ask.
    Progress bar("plot", job.lines.size(), !A.quiet && !A.json);
    io::StreamControls controls;
    int handled = 0;
    bool asked_pause = false;
    auto last_json = std::chrono::steady_clock::now() - std::chrono::seconds(10);
    std::signal(SIGINT, on_plot_sigint);
    io::ProgressFn progress = [&](const io::StreamProgress& p) {
      bar.set_eta_hint(p.eta_s);
      bar.set_suffix(std::to_string(p.lines_acked) + "/" + std::to_string(p.lines_total) + " lines " + p.state);
      bar.update(p.lines_acked);
      if (A.json && !A.quiet && std::chrono::steady_clock::now() - last_json > std::chrono::seconds(1)) {
        last_json = std::chrono::steady_clock::now();
        nlohmann::json j = {{"progress", p.lines_total ? double(p.lines_acked) / double(p.lines_total) : 1.0},
                            {"lines_acked", p.lines_acked}, {"lines_sent", p.lines_sent}, {"lines", p.lines_total},
                            {"elapsed_s", p.elapsed_s}, {"eta_s", p.eta_s}, {"state", p.state}};
        std::fprintf(stderr, "%s\n", j.dump().c_str());
      }
      int seen = g_interrupts.load();
      if (seen > handled && !asked_pause) {
        handled = seen;
        asked_pause = true;
        controls.pause = true;  // applied at the streamer's next step; ask on the next report
        return;
      }
      if (asked_pause) {
        asked_pause = false;
        bool resume = false;
        if (stdin_tty()) {
          std::fprintf(stderr, "\nPaused, pen lifted. [r]esume or [a]bort? ");
          std::string answer;
          std::getline(std::cin, answer);
          resume = !answer.empty() && (answer[0] == 'r' || answer[0] == 'R');
        }
        (resume ? controls.resume : controls.abort) = true;
      }
    };
    // Journal.
    std::unique_ptr<io::Journal> journal;
    std::string jpath = io::Journal::path_for(pj.path);
    if (resuming) {
      journal = std::make_unique<io::Journal>(jpath, io::JournalHeader{}, true);
    } else {
      io::JournalHeader h{pj.path, hash, io::to_string(pj.dialect), pj.profile, A.sim ? "" : port_name, job.lines.size()};
      journal = std::make_unique<io::Journal>(jpath, h);
    }
    nlohmann::json s;
    s["command"] = "plot";
    s["job"] = pj.path;
    s["journal"] = jpath;
    s["port"] = A.sim ? "sim" : port_name;
    s["lines"] = job.lines.size();
    io::StreamResult res;
    size_t start = resuming ? static_cast<size_t>(resume_state.last_acked + 1) : 0;
    try {
      if (grbl) {
        io::grbl::Options o = io::grbl::options_for(dev);
        o.mode = io::grbl::parse_mode(A.stream);
        o.skip_errors = A.skip_errors;
        o.unlock = A.unlock;
        o.log = log;
        o.on_pause_m0 = [&](const std::string& line) {
          if (A.sim || !stdin_tty()) return true;
          std::fprintf(stderr, "\nPause in the job (%s): change the pen, then press Enter (or type a to abort) ", line.c_str());
          std::string answer;
          std::getline(std::cin, answer);
          return answer.empty() || (answer[0] != 'a' && answer[0] != 'A');
        };
        io::grbl::Streamer st(*port, o);
        st.connect();
        for (const auto& w : st.check_settings(st.read_settings(), io::grbl::expectations_for(job))) log("warning: " + w);
        if (A.check) {
          auto errs = st.check_job(job);
          s["check_errors"] = errs.size();
          if (!errs.empty()) {
            std::string msg = "check mode found " + std::to_string(errs.size()) + " bad line(s); first: line " +
                              std::to_string(errs[0].first + 1) + " `" + job.lines[static_cast<size_t>(errs[0].first)].text +
                              "`: error:" + std::to_string(errs[0].second);
            throw UserError(msg);
          }
          log("check mode: all " + std::to_string(job.lines.size()) + " lines accepted");
        }
        io::ResumePlan rp{start, {}};
        if (resuming) rp = io::plan_resume(job, start, st.device_pen(pen_rule));
        res = st.stream(job, rp.next, rp.preamble, journal.get(), progress, &controls);
      } else {
        io::hpgl::Options o = io::hpgl::options_for(dev);
        o.log = log;
        io::hpgl::Streamer st(*port, o);
        st.connect();
        io::ResumePlan rp{start, {}};
        if (resuming) rp = io::plan_resume(job, start);
        res = st.stream(job, rp.next, rp.preamble, journal.get(), progress, &controls);
      }
    } catch (const UserError& e) {
      bar.finish();
      std::string hint = journal && journal->last_acked() >= 0
                             ? " — the journal has line " + std::to_string(journal->last_acked() + 1) +
                                   "; continue with: stipplot plot --resume " + pj.path + (A.sim ? " --sim" : "")
                             : "";
      throw UserError(std::string(e.what()) + hint);
    }
    bar.finish();
    journal.reset();
    s["completed"] = res.completed;
    s["lines_acked"] = res.lines_acked;
    s["errors_skipped"] = res.errors_skipped;
    s["warnings"] = res.warnings;
    if (simdev) {
      simdev->wait_idle(600);
      auto rec = simdev->record();
      sim::SimStats st = simdev->stats();
      auto planned = io::job_segments(job);
      s["sim_segments"] = rec.size();
      s["sim_plot_s"] = st.plot_time();
      s["sim_starved_pct"] = 100 * st.starved_share();
      if (!resuming) s["sim_exact"] = rec.size() == planned.size() && std::is_permutation(rec.begin(), rec.end(), planned.begin());
      std::string prefix = A.sim_out.empty() ? pj.path + ".sim" : A.sim_out;
      double upm = grbl ? 1 : dev.machine.units_per_mm;
      Drawing drawn;
      if (A.page_given) {
        PageSpec ps = parse_page(A.page);
        Page page;
        page.width_mm = ps.width_mm;
        page.height_mm = ps.height_mm;
        drawn = sim::record_to_drawing(rec, page, upm, 0.3, dev.machine.y_up() ? ps.height_mm : 0);
      } else {
        drawn = sim::record_to_fitted_drawing(rec, upm, dev.machine.y_up());  // shown as it lies on the paper
      }
      sim::write_drawing_png_svg(drawn, prefix + ".png", prefix + ".svg");
      s["sim_png"] = prefix + ".png";
      s["sim_svg"] = prefix + ".svg";
    }
    s["seconds"] = seconds_since(t0);
    if (A.json) {
      std::printf("%s\n", s.dump().c_str());
    } else if (!A.quiet) {
      std::printf("%s %s: %zu lines acknowledged in %.1f s%s\n", res.completed ? "plotted" : "stopped", pj.path.c_str(),
                  res.lines_acked, res.seconds,
                  simdev ? (", simulator drew " + std::to_string(s["sim_segments"].get<size_t>()) + " segments -> " +
                            s["sim_png"].get<std::string>())
                               .c_str()
                         : "");
    }
    if (!res.completed) throw UserError("plot stopped at line " + std::to_string(res.last_acked + 1) +
                                        "; continue with: stipplot plot --resume " + pj.path);
  });
}

}  // namespace stipplot::cli
