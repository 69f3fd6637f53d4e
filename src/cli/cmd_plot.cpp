// stipplot plot: stream a job to a plotter (serial, USB, or the in-process simulator),
// with progress, pause/abort on Ctrl-C, check mode, and resume from the journal.
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <algorithm>
#include <cctype>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/plot_job.hpp"
#include "drivers/device/machine.hpp"
#include "drivers/device/motion_setup.hpp"
#include "drivers/device/pen_rule.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "drivers/job/segments.hpp"
#include "drivers/job/timed_job.hpp"
#include "drivers/stream/grbl/machine_settings.hpp"
#include "drivers/job/ebb_reader.hpp"
#include "drivers/stream/ebb/streamer.hpp"
#include "drivers/stream/grbl/streamer.hpp"
#include "drivers/stream/hpgl/streamer.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/ebb/nickname.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/transport/devices.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "geometry/page.hpp"
#include "sim/grbl_sim.hpp"
#include "sim/hpgl_sim.hpp"
#include "sim/record.hpp"
#include "util/output_paths.hpp"
#include "util/progress.hpp"

namespace stipplot::cli {

namespace {

std::atomic<int> g_interrupts{0};
extern "C" void on_plot_sigint(int) { g_interrupts.fetch_add(1); }

// SIGTERM and SIGHUP stop the plot as an abort does (feed hold, the device's buffers
// dropped, the journal exact), so that --resume continues without a line lost or
// redrawn. The handler only stores to lock-free atomics.
std::atomic<std::atomic<bool>*> g_abort_target{nullptr};
std::atomic<int> g_stop_signal{0};
extern "C" void on_plot_stop_signal(int sig) {
  g_stop_signal.store(sig);
  if (std::atomic<bool>* a = g_abort_target.load()) a->store(true);
}

struct PlotArgs {
  std::string input, profile, port, resume, job_out;
  PlanArgs plan;      // an SVG's planning
  LayoutArgs layout;  // an SVG's layout on the profile's sheet
  PenHeightArgs heights;  // an SVG's pen heights on an EBB
  bool page_given = false, flow_given = false, handshake_given = false, rx_buffer_given = false;
  bool sim = false, check = false, json = false, quiet = false, skip_errors = false, unlock = false, newline = false;
  bool control = false;  // driven by another program through stdin (stipplot serve)
  std::string stream = "counting", handshake = "escb", flow = "none", pen_change = "ask";
  int baud = 0, rx_buffer = 128;
  double sim_speedup = 20, sim_baud = 115200, sim_latency_ms = 2;
  std::string sim_out, page = "A4";

  void validate() const {
    if (input.empty() && resume.empty()) throw UserError("give a job to plot, or --resume JOB");
    if (sim && !port.empty()) throw UserError("--sim and --port exclude each other");
    heights.check();
    if (!resume.empty() && heights.any_given())
      throw UserError("--pos-up/--pos-down apply to an SVG drawing; a resumed job keeps its own servo settings");
    if (!resume.empty() && heights.moves_opt && heights.moves_opt->count() > 0)
      throw UserError("--ebb-moves applies to an SVG drawing; a resumed job keeps its own moves");
    // A USB bulk endpoint has no line settings: refuse them rather than drop them.
    if (port.rfind("usb:", 0) == 0 && (baud > 0 || flow_given))
      throw UserError("--port " + port + " is a USB bulk endpoint (libusb): it has no baud rate or flow control; " +
                      "--baud and --flow apply to serial ports (a USB-serial adapter shows up as /dev/ttyUSB*)");
    require_positive("--sim-speedup", sim_speedup);
    require_nonnegative("--sim-baud", sim_baud);
    require_nonnegative("--sim-latency-ms", sim_latency_ms);
    if (pen_change != "ask" && pen_change != "continue" && pen_change != "stop")
      throw UserError("--pen-change must be ask, continue or stop, not '" + pen_change + "'");
    const auto sim_file = [&](const char* ext) { return sim_out.empty() ? sim_out : sim_out + ext; };
    check_output_paths({{"input", input}, {"--resume", resume}},
                       {{"--job", job_out}, {"--sim-out", sim_file(".png")}, {"--sim-out", sim_file(".svg")}});
  }
  void log(const std::string& s) const {
    if (!quiet) std::fprintf(stderr, "stipplot: %s\n", s.c_str());
  }
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

// One key from the terminal, without waiting for Enter (canonical mode and echo off for
// the read, restored after); EOF or an error reads as 0.
char read_key() {
  termios saved{};
  const bool raw = ::tcgetattr(STDIN_FILENO, &saved) == 0;
  if (raw) {
    termios t = saved;
    t.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    ::tcsetattr(STDIN_FILENO, TCSANOW, &t);
  }
  char c = 0;
  if (::read(STDIN_FILENO, &c, 1) != 1) c = 0;
  if (raw) ::tcsetattr(STDIN_FILENO, TCSANOW, &saved);
  return c;
}

// The job to plot, read and parsed, the device it goes to, and, on --resume, where the
// journal says it stopped.
struct PlotJob {
  PreparedJob prepared;
  bool resuming = false;
  io::JournalState resume_state;
  std::string hash;  // of the job text, kept in the journal
  DeviceProfile device;
  io::GcodePenRule pen_rule;
  io::Job job;
  bool grbl() const { return prepared.dialect == io::Dialect::GCode; }
  bool ebb() const { return prepared.dialect == io::Dialect::Ebb; }
  size_t start() const { return resuming ? static_cast<size_t>(resume_state.last_acked + 1) : 0; }
};

// What the G-code timer needs of the wire: grbl waits for characters on a slow one.
io::GcodeLink gcode_link_of(const DeviceProfile& dev) {
  io::GcodeLink link;
  link.baud = dev.serial.port.baud;
  link.rx_buffer = dev.serial.rx_buffer_bytes;
  return link;
}

// The command line's serial and protocol settings over the profile's.
void apply_overrides(const PlotArgs& A, DeviceProfile& dev, bool grbl) {
  if (A.baud > 0) dev.serial.port.baud = A.baud;
  if (A.flow_given) dev.serial.port.flow = io::parse_flow_control(A.flow);
  if (A.rx_buffer_given && grbl) dev.serial.rx_buffer_bytes = A.rx_buffer;
  if (A.handshake_given) dev.hpgl.handshake = parse_hpgl_handshake(A.handshake);
  dev.serial.newline = dev.serial.newline || A.newline;
}

// A new job is prepared (an SVG planned and written); a resumed one must be the file
// its journal was written for. A resumed job goes back to the journal's port.
PlotJob load_job(PlotArgs& A) {
  PlotJob pj;
  pj.resuming = !A.resume.empty();
  if (pj.resuming) {
    pj.resume_state = io::Journal::load(io::Journal::path_for(A.resume));
    // The profile the job was started with, unless another is named (then it must agree).
    pj.prepared = {A.resume, dialect_of(A.resume), A.profile.empty() ? pj.resume_state.header.profile : A.profile, {}};
    if (pj.resume_state.torn) A.log("the journal's last record was cut short (a crash mid-write): resuming from the one before");
    if (pj.resume_state.complete) throw UserError("job " + A.resume + " was already plotted to the end (journal says done)");
    if (A.port.empty() && !A.sim) A.port = pj.resume_state.header.port;
  } else {
    pj.prepared = prepare_job({A.input, A.profile, A.job_out, A.plan, A.layout, A.heights});
    if (!pj.prepared.layout_note.empty()) A.log("laid out on the sheet: " + pj.prepared.layout_note);
  }
  const std::string& path = pj.prepared.path;
  const std::string text = read_file(path);
  pj.hash = hex(io::fnv1a64(text));
  pj.device = plot_profile(pj.prepared.profile.empty() ? A.profile : pj.prepared.profile, pj.prepared.dialect);
  if (pj.ebb() != (pj.device.protocol == Protocol::ebb))
    throw UserError("job " + path + (pj.ebb() ? " holds EiBotBoard commands" : " is not an EiBotBoard job") +
                    " and profile " + pj.device.name + " is " +
                    (pj.ebb() ? "not an EBB machine" : "an EBB machine") + ": choose a profile for this job");
  pj.pen_rule = gcode_pen_rule(pj.device);
  pj.job = pj.ebb()    ? io::parse_ebb_job(text, pj.device.ebb.steps_per_mm)
           : pj.grbl() ? io::parse_gcode_job(text, pj.pen_rule)
                       : io::parse_hpgl_job(text);
  if (pj.job.lines.empty()) throw UserError("job " + path + " has no lines to plot");
  // A job file for a named machine must stay inside its travel (an SVG's plan was checked
  // when it was written).
  if (!pj.prepared.profile.empty()) check_job_fits(pj.job, pj.device, path);
  if (pj.resuming)
    io::Journal::check_belongs(pj.resume_state, path, pj.hash, io::to_string(pj.prepared.dialect), pj.job.lines.size(),
                               pj.prepared.profile);
  apply_overrides(A, pj.device, pj.grbl());
  // The timed plan: the ETA counts down the machine's own time (pauses take none).
  if (pj.grbl()) {
    io::apply_timing(pj.job, io::time_gcode_job(pj.job, grbl_settings_for(pj.device), gcode_link_of(pj.device)));
  } else if (pj.ebb()) {
    io::apply_timing(pj.job, io::time_ebb_job(pj.job));
  } else {
    io::apply_timing(pj.job, io::time_hpgl_job(pj.job, hpgl_motion_for(pj.device)));
  }
  return pj;
}

// Where the bytes go: a port (the one plausible device without --port), or the
// simulator of the device on a pty, opened as a serial port like a real one.
struct PlotLink {
  std::unique_ptr<sim::SimDevice> sim;
  std::unique_ptr<io::Transport> port;
  std::string port_name;
  std::string journal_port;  // as given: ebb:NAME finds the board again on --resume
};

PlotLink open_link(const PlotArgs& A, const PlotJob& pj) {
  PlotLink link;
  const DeviceProfile& dev = pj.device;
  if (!A.sim) {
    link.journal_port = A.port.empty() ? io::choose_port(io::list_devices()) : A.port;
    link.port_name = io::ebb::resolve_port(link.journal_port, dev.serial.port);
    link.port = io::open_port(link.port_name, dev.serial.port);
    return link;
  }
  if (pj.ebb())
    throw UserError("--sim has no EiBotBoard simulator in process: plot on the board's port (or on the EBB firmware "
                    "simulator over a pty, tests/ebb/README.md)");
  const sim::SimRun run{A.sim_speedup, {A.sim_baud, A.sim_latency_ms}, {}};
  if (pj.grbl()) {
    sim::GrblSimConfig c = sim::grbl_sim_config(dev);
    static_cast<sim::SimRun&>(c) = run;
    link.sim = std::make_unique<sim::GrblSim>(c);
  } else {
    sim::HpglSimConfig c = sim::hpgl_sim_config(dev);
    static_cast<sim::SimRun&>(c) = run;
    link.sim = std::make_unique<sim::HpglSim>(c);
  }
  link.port_name = link.sim->open_pty();
  auto ps = std::make_unique<io::PosixSerial>(link.port_name, dev.serial.port);
  // In-band XOFF must arrive in time: write no faster than the simulated wire.
  if (dev.hpgl.handshake == HpglHandshake::xonxoff && A.sim_baud > 0) ps->pace(A.sim_baud / 10 * A.sim_speedup);
  link.port = std::move(ps);
  return link;
}

// --control: another program steers the plot with lines on standard input ("pause",
// "resume", "abort"), and answers pen changes ("continue" or "abort") that are announced
// as {"pen_change": LINE} on stderr. Standard input is read on its own thread, which
// only sets the streamer's atomic controls or hands over the answer.
class PlotControl {
 public:
  void start(io::StreamControls& controls) {
    std::thread([this, &controls] {
      std::string line;
      char c;
      while (::read(STDIN_FILENO, &c, 1) == 1) {
        if (c != '\n') {
          line += c;
          continue;
        }
        if (line == "pause") controls.pause = true;
        else if (line == "resume") controls.resume = true;
        else if (line == "abort") controls.abort = true;
        if (line == "continue" || line == "abort") answer(line == "continue");
        line.clear();
      }
      answer(false);  // the controller went away: a waiting pen change is not confirmed
    }).detach();      // blocked in read() until the process ends
  }
  // Announces a pen change and waits for the controller's answer.
  bool ask_pen_change(const std::string& job_line) {
    std::unique_lock<std::mutex> lock(m_);
    answered_ = false;
    std::fprintf(stderr, "%s\n", nlohmann::json({{"pen_change", job_line}}).dump().c_str());
    cv_.wait(lock, [this] { return answered_; });
    return answer_;
  }

 private:
  void answer(bool go_on) {
    std::lock_guard<std::mutex> lock(m_);
    answered_ = true;
    answer_ = go_on;
    cv_.notify_all();
  }
  std::mutex m_;
  std::condition_variable cv_;
  bool answered_ = false, answer_ = false;
};
PlotControl g_control;  // lives as long as its reader thread: the whole process

// The progress bar and JSON progress lines; Ctrl-C pauses (feed hold, pen lifted) at
// the streamer's next step, and the next report asks whether to resume or abort.
class PlotProgress {
 public:
  PlotProgress(const PlotArgs& A, size_t lines) : A_(A), bar_("plot", lines, !A.quiet && !A.json) {
    std::signal(SIGINT, on_plot_sigint);
    g_abort_target.store(&controls.abort);
    if (g_stop_signal.load()) controls.abort = true;
    for (int sig : {SIGTERM, SIGHUP}) std::signal(sig, on_plot_stop_signal);
    if (A.control) g_control.start(controls);
  }
  ~PlotProgress() {
    for (int sig : {SIGTERM, SIGHUP}) std::signal(sig, SIG_DFL);
    g_abort_target.store(nullptr);
  }
  PlotProgress(const PlotProgress&) = delete;
  PlotProgress& operator=(const PlotProgress&) = delete;
  io::StreamControls controls;

  void operator()(const io::StreamProgress& p) {
    bar_.set_eta_hint(p.eta_s);
    bar_.set_suffix(std::to_string(p.lines_acked) + "/" + std::to_string(p.lines_total) + " lines " + p.state);
    bar_.update(p.lines_acked);
    // A controlling program draws the progress as it goes: five lines a second.
    const auto every = A_.control ? std::chrono::milliseconds(200) : std::chrono::milliseconds(1000);
    if (A_.json && !A_.quiet && std::chrono::steady_clock::now() - last_json_ > every) {
      last_json_ = std::chrono::steady_clock::now();
      nlohmann::json j = {{"progress", p.lines_total ? double(p.lines_acked) / double(p.lines_total) : 1.0},
                          {"lines_acked", p.lines_acked}, {"lines_sent", p.lines_sent}, {"lines", p.lines_total},
                          {"elapsed_s", p.elapsed_s}, {"eta_s", p.eta_s}, {"state", p.state}};
      std::fprintf(stderr, "%s\n", j.dump().c_str());
    }
    int seen = g_interrupts.load();
    if (seen > handled_ && !asked_pause_) {
      handled_ = seen;
      asked_pause_ = true;
      controls.pause = true;  // applied at the streamer's next step; ask on the next report
      return;
    }
    if (asked_pause_) {
      asked_pause_ = false;
      (ask_resume() ? controls.resume : controls.abort) = true;
    }
  }
  void finish(bool completed) { bar_.finish(completed); }

 private:
  static bool ask_resume() {
    if (!stdin_tty()) return false;
    std::fprintf(stderr, "\nPaused, pen lifted. [r]esume or [a]bort? ");
    for (;;) {
      const char k = read_key();
      if (k == 'r' || k == 'R' || k == 'a' || k == 'A' || k == 0) {
        std::fprintf(stderr, "%s\n", k == 'r' || k == 'R' ? "resume" : "abort");
        return k == 'r' || k == 'R';
      }
    }
  }
  const PlotArgs& A_;
  Progress bar_;
  int handled_ = 0;
  bool asked_pause_ = false;
  std::chrono::steady_clock::time_point last_json_ = std::chrono::steady_clock::now() - std::chrono::seconds(10);
};

// A new journal for a new job; a resumed one continues its own.
std::unique_ptr<io::Journal> open_journal(const PlotArgs& A, const PlotJob& pj, const std::string& port_name) {
  const std::string jpath = io::Journal::path_for(pj.prepared.path);
  if (pj.resuming) return std::make_unique<io::Journal>(jpath, io::JournalHeader{}, true);
  io::JournalHeader h{pj.prepared.path, pj.hash, io::to_string(pj.prepared.dialect), pj.prepared.profile,
                      A.sim ? "" : port_name, pj.job.lines.size()};
  return std::make_unique<io::Journal>(jpath, h);
}

// The job's pauses from `start` on (pen changes, reloads).
std::vector<size_t> pauses_from(const io::Job& job, size_t start) {
  std::vector<size_t> out;
  for (size_t i = start; i < job.lines.size(); ++i)
    if (job.lines[i].pause) out.push_back(i);
  return out;
}

// Before anything moves: which pen is wanted now, and that every later pause will be
// answered. Nobody at a terminal to ask would let the wrong pen draw every later layer.
void announce_pens(const PlotArgs& A, const PlotJob& pj) {
  const std::string pen = pj.job.pen_at(pj.start());
  if (!pen.empty()) A.log(std::string(pj.resuming ? "resuming with " : "starting with ") + pen + ": is it in the holder?");
  const std::vector<size_t> pauses = pauses_from(pj.job, pj.start());
  if (pauses.empty()) return;
  A.log("the job pauses " + std::to_string(pauses.size()) + " time(s) for the operator; first at line " +
        std::to_string(pauses[0] + 1) + ": " + pj.job.lines[pauses[0]].note);
  if (A.pen_change == "ask" && !A.sim && !A.control && !stdin_tty())
    throw UserError("the job pauses " + std::to_string(pauses.size()) + " time(s) for a pen change (first: " +
                    pj.job.lines[pauses[0]].note +
                    ") and stdin is not a terminal to ask: pass --pen-change continue (go on at every pause) or "
                    "--pen-change stop (stop at the next one; change the pen, then --resume)");
}

// A pause of the job: --pen-change says what to do; "ask" asks at the terminal (the
// simulator has no operator: it goes on).
io::PauseAnswer answer_pause(const PlotArgs& A, const io::PauseRequest& p) {
  A.log("pause at line " + std::to_string(p.line + 1) + ": " + p.note);
  if (A.pen_change == "continue") return io::PauseAnswer::go;
  // A controlling program (the studio) has an operator even on the simulator.
  if (A.control) return g_control.ask_pen_change(p.note) ? io::PauseAnswer::go : io::PauseAnswer::stop;
  if (A.pen_change == "ask" && A.sim) return io::PauseAnswer::go;
  if (A.pen_change == "stop" || !stdin_tty()) return io::PauseAnswer::stop_after;
  std::fprintf(stderr, "\n%s. Press Enter when done (or type a to abort) ", p.note.c_str());
  std::string answer;
  if (!std::getline(std::cin, answer)) return io::PauseAnswer::stop;
  return answer.empty() || (answer[0] != 'a' && answer[0] != 'A') ? io::PauseAnswer::go : io::PauseAnswer::stop;
}

// Where to go on, from the journal and the device as it is now (as the fault tests resume);
// the summary says from which line, how much pen-down path it may draw again, and why.
io::ResumePlan resume_plan(const PlotArgs& A, const PlotJob& pj, const io::DevicePen& device, const io::ResumeWindow& w,
                           nlohmann::json& summary) {
  io::ResumePlan rp = io::resume_from_journal(pj.job, pj.resume_state, device, w);
  if (!rp.note.empty()) A.log(rp.note);
  const double mm = rp.redraw / (pj.grbl() ? 1.0 : pj.device.machine.units_per_mm);
  summary["resume"] = {{"from_line", rp.next + 1}, {"redraw_mm", std::round(mm * 100) / 100}, {"why", rp.why}};
  return rp;
}

// grbl: connect, compare its settings with the job, check mode if asked, resume where
// the device's pen is, stream.
// A write-only sink (file:PATH, a USB printer node): the job goes as it is, line by
// line, with nothing asked of the device (no status query, no reset, no handshake), and
// nothing to journal, since nothing answers.
void write_to_sink(const PlotArgs& A, const PlotJob& pj, io::Transport& sink, std::chrono::steady_clock::time_point t0) {
  if (pj.resuming) throw UserError(sink.describe() + " never answers: there is nothing to resume; write the whole job again");
  const std::string eol = pj.ebb() ? "\r" : pj.grbl() || pj.device.serial.newline ? "\n" : "";
  size_t lines = 0, bytes = 0;
  for (const auto& l : pj.job.lines) {
    if (l.host_only) continue;  // HPGL pause comments: for the host, never the device
    sink.write(l.text + eol);
    ++lines, bytes += l.text.size() + eol.size();
  }
  sink.flush();
  sink.close();
  nlohmann::json s = {{"command", "plot"}, {"job", pj.prepared.path}, {"port", sink.describe()}, {"lines", lines},
                      {"bytes", bytes}, {"completed", true}, {"answers", false}, {"seconds", seconds_since(t0)}};
  if (A.json) std::printf("%s\n", s.dump().c_str());
  else if (!A.quiet)
    std::printf("wrote %zu lines (%zu bytes) of %s to %s as they are: a sink never answers, so nothing was checked, "
                "timed or journalled\n", lines, bytes, pj.prepared.path.c_str(), sink.describe().c_str());
}

// grbl's motion settings differ from the profile's: the plot is the same, its time is
// not; the job is timed again from grbl's own numbers (the ETA counts those down).
void time_from_machine(const PlotArgs& A, PlotJob& pj, const std::map<int, double>& reported, nlohmann::json& summary) {
  const auto cmp = io::grbl::compare_motion_settings(reported, grbl_settings_for(pj.device));
  if (!cmp.changes_time()) return;
  const double profile_s = pj.job.est_total_s;
  io::apply_timing(pj.job, io::time_gcode_job(pj.job, cmp.machine, gcode_link_of(pj.device)));
  std::string what;
  for (const auto& c : cmp.time_changes) what += (what.empty() ? "" : ", ") + c;
  A.log("warning: grbl's settings differ from profile " + pj.device.name + "'s: " + what + "; timed with grbl's: about " +
        format_duration(pj.job.est_total_s) + " (the profile's numbers: " + format_duration(profile_s) + ")");
  summary["settings_differ"] = cmp.time_changes;
  summary["estimate_s_profile"] = profile_s;
  summary["estimate_s"] = pj.job.est_total_s;
}

io::StreamResult run_grbl(const PlotArgs& A, PlotJob& pj, io::Transport& port, io::Journal& journal,
                          PlotProgress& progress, nlohmann::json& summary) {
  const io::Job& job = pj.job;
  io::grbl::Options o = io::grbl::options_for(pj.device);
  o.mode = io::grbl::parse_mode(A.stream);
  o.skip_errors = A.skip_errors;
  o.unlock = A.unlock;
  o.log = [&A](const std::string& s) { A.log(s); };
  o.on_pause = [&A](const io::PauseRequest& p) { return answer_pause(A, p); };
  io::grbl::Streamer st(port, o);
  st.connect();
  const std::map<int, double> reported = st.read_settings();
  for (const auto& w : st.check_settings(reported, io::grbl::expectations_for(job))) A.log("warning: " + w);
  time_from_machine(A, pj, reported, summary);
  if (A.check) {
    auto errs = st.check_job(job);
    summary["check_errors"] = errs.size();
    if (!errs.empty()) {
      std::string msg = "check mode found " + std::to_string(errs.size()) + " bad line(s); first: line " +
                        std::to_string(errs[0].first + 1) + " `" + job.lines[static_cast<size_t>(errs[0].first)].text +
                        "`: error:" + std::to_string(errs[0].second);
      throw UserError(msg);
    }
    A.log("check mode: all " + std::to_string(job.lines.size()) + " lines accepted");
  }
  io::ResumePlan rp{pj.start(), {}, {}, 0, {}};
  if (pj.resuming) rp = resume_plan(A, pj, st.device_pen(pj.pen_rule), st.resume_window(), summary);
  return st.stream(job, rp.next, rp.preamble, &journal, std::ref(progress), &progress.controls);
}

io::StreamResult run_hpgl(const PlotArgs& A, const PlotJob& pj, io::Transport& port, io::Journal& journal,
                          PlotProgress& progress, nlohmann::json& summary) {
  io::hpgl::Options o = io::hpgl::options_for(pj.device);
  o.log = [&A](const std::string& s) { A.log(s); };
  o.on_pause = [&A](const io::PauseRequest& p) { return answer_pause(A, p); };
  io::hpgl::Streamer st(port, o);
  st.connect();
  io::ResumePlan rp{pj.start(), {}, {}, 0, {}};
  if (pj.resuming) rp = resume_plan(A, pj, st.device_pen(), st.resume_window(), summary);
  return st.stream(pj.job, rp.next, rp.preamble, &journal, std::ref(progress), &progress.controls);
}

// EBB: connect (V), on --resume go on from the board's own position and pen (or, on a
// board that was reset, from the journal's last proof with the carriage at home), stream.
io::StreamResult run_ebb(const PlotArgs& A, const PlotJob& pj, io::Transport& port, io::Journal& journal,
                         PlotProgress& progress, nlohmann::json& summary) {
  io::ebb::Options o = io::ebb::options_for(pj.device);
  o.log = [&A](const std::string& s) { A.log(s); };
  o.on_pause = [&A](const io::PauseRequest& p) { return answer_pause(A, p); };
  io::ebb::Streamer st(port, o);
  st.connect();
  summary["firmware"] = st.firmware().text;
  io::ResumePlan rp{pj.start(), {}, {}, 0, {}};
  if (pj.resuming) {
    rp = st.resume(pj.job, pj.resume_state, pj.device);
    if (!rp.note.empty()) A.log(rp.note);
    summary["resume"] = {{"from_line", rp.next + 1}, {"redraw_mm", std::round(rp.redraw * 100) / 100}, {"why", rp.why}};
    if (!rp.note.empty()) summary["resume"]["note"] = rp.note;
  }
  return st.stream(pj.job, rp.next, rp.preamble, &journal, std::ref(progress), &progress.controls);
}

// What the simulator drew: compared with the job, and rendered as it lies on the paper.
void render_sim_record(const PlotArgs& A, const PlotJob& pj, sim::SimDevice& simdev, nlohmann::json& s) {
  simdev.wait_idle(600);
  auto rec = simdev.record();
  sim::SimStats st = simdev.stats();
  auto planned = io::job_segments(pj.job);
  s["sim_segments"] = rec.size();
  s["sim_plot_s"] = st.plot_time();
  s["sim_starved_pct"] = 100 * st.starved_share();
  if (!pj.resuming) s["sim_exact"] = rec.size() == planned.size() && std::is_permutation(rec.begin(), rec.end(), planned.begin());
  std::string prefix = A.sim_out.empty() ? pj.prepared.path + ".sim" : A.sim_out;
  const MachineGeometry& machine = pj.device.machine;
  double upm = pj.grbl() ? 1 : machine.units_per_mm;
  Drawing drawn;
  if (A.page_given) {
    PageSpec ps = parse_page(A.page);
    Page page;
    page.width_mm = ps.width_mm;
    page.height_mm = ps.height_mm;
    drawn = sim::record_to_drawing(rec, page, upm, 0.3, machine.y_up() ? ps.height_mm : 0);
  } else {
    drawn = sim::record_to_fitted_drawing(rec, upm, machine.y_up());  // shown as it lies on the paper
  }
  sim::write_drawing_png_svg(drawn, prefix + ".png", prefix + ".svg");
  s["sim_png"] = prefix + ".png";
  s["sim_svg"] = prefix + ".svg";
}

void print_result(const PlotArgs& A, const PlotJob& pj, const io::StreamResult& res, bool simulated,
                  const nlohmann::json& s) {
  if (A.json) {
    std::printf("%s\n", s.dump().c_str());
  } else if (!A.quiet) {
    std::string resumed;  // "; resumed at line 812, redraws at most 3.2 mm: from the last point ..."
    if (s.contains("resume")) {
      char b[96];
      std::snprintf(b, sizeof b, "; resumed at line %zu, redraws at most %.1f mm: ", s["resume"]["from_line"].get<size_t>(),
                    s["resume"]["redraw_mm"].get<double>());
      resumed = b + s["resume"]["why"].get<std::string>();
    }
    std::printf("%s %s: %zu lines acknowledged in %.1f s%s%s\n", res.completed ? "plotted" : "stopped",
                pj.prepared.path.c_str(), res.lines_acked, res.seconds,
                simulated ? (", simulator drew " + std::to_string(s["sim_segments"].get<size_t>()) + " segments -> " +
                             s["sim_png"].get<std::string>())
                                .c_str()
                          : "",
                resumed.c_str());
  }
}

void plot(PlotArgs& A) {
  auto t0 = std::chrono::steady_clock::now();
  A.validate();
  PlotJob pj = load_job(A);
  announce_pens(A, pj);
  PlotLink link = open_link(A, pj);
  if (!link.port->answers()) return write_to_sink(A, pj, *link.port, t0);
  A.log("plotting " + pj.prepared.path + " (" + std::to_string(pj.job.lines.size()) + " lines) on " +
        link.port->describe());
  PlotProgress progress(A, pj.job.lines.size());
  std::unique_ptr<io::Journal> journal = open_journal(A, pj, link.journal_port);
  nlohmann::json s;
  s["command"] = "plot";
  s["job"] = pj.prepared.path;
  s["journal"] = journal->path();
  s["port"] = A.sim ? "sim" : link.port_name;
  s["lines"] = pj.job.lines.size();
  io::StreamResult res;
  try {
    res = pj.grbl()  ? run_grbl(A, pj, *link.port, *journal, progress, s)
          : pj.ebb() ? run_ebb(A, pj, *link.port, *journal, progress, s)
                     : run_hpgl(A, pj, *link.port, *journal, progress, s);
  } catch (const UserError& e) {
    progress.finish(false);
    std::string hint = journal->last_acked() >= 0
                           ? " — the journal has line " + std::to_string(journal->last_acked() + 1) +
                                 "; continue with: stipplot plot --resume " + pj.prepared.path + (A.sim ? " --sim" : "")
                           : "";
    throw UserError(std::string(e.what()) + hint);
  }
  progress.finish(res.completed);
  journal.reset();
  s["completed"] = res.completed;
  s["lines_acked"] = res.lines_acked;
  s["errors_skipped"] = res.errors_skipped;
  s["warnings"] = res.warnings;
  s["pauses"] = res.pauses;
  s["paused_s"] = res.paused_s;
  if (link.sim) render_sim_record(A, pj, *link.sim, s);
  s["streamed_s"] = res.seconds;  // from connecting to the device's last move, as progress's elapsed_s
  s["seconds"] = seconds_since(t0);
  print_result(A, pj, res, link.sim != nullptr, s);
  if (!res.completed && g_stop_signal.load())
    throw UserError(std::string("stopped by ") + (g_stop_signal.load() == SIGHUP ? "SIGHUP" : "SIGTERM") +
                    " at line " + std::to_string(res.last_acked + 1) +
                    " (the device stopped and its buffer dropped, the journal saved); continue with: stipplot plot --resume " + pj.prepared.path);
  if (!res.completed)
    throw UserError("plot stopped at line " + std::to_string(res.last_acked + 1) + "; continue with: stipplot plot --resume " +
                    pj.prepared.path);
}

}  // namespace

void register_plot(CLI::App& app) {
  auto a = std::make_shared<PlotArgs>();
  CLI::App* cmd = app.add_subcommand("plot", "Plot a job on a plotter or the simulated plotter");
  cmd->footer(
      "IN is a .gcode/.nc (grbl), .hpgl/.plt or .ebb (EiBotBoard: AxiDraw, profiles axidraw-*) job, or an SVG\n"
      "(laid out and planned as export does). Without --port or --sim the one plausible device\n"
      "(`stipplot devices`) is used. Ctrl-C pauses (feed hold, pen lifted) and asks whether to resume or\n"
      "abort. The journal IN.journal records every line the device acknowledged; after a disconnect,\n"
      "power loss or abort, `stipplot plot --resume IN` lifts the pen, travels to where it stopped and\n"
      "continues. --sim plots on the in-process simulator (over a pty) and writes IN.sim.png/.svg.\n"
      "Examples: stipplot plot job.gcode --sim\n"
      "          stipplot plot job.gcode --port /dev/ttyUSB0 --check\n"
      "          stipplot plot --resume job.gcode --port /dev/ttyUSB0\n"
      "          stipplot plot photo.svg --profile axidraw-v3 --port /dev/ttyACM0   (an AxiDraw's EBB)\n"
      "          stipplot plot photo.svg --profile nextdraw-1117 --port ebb:studio   (the EBB nicknamed studio)");
  cmd->add_option("input", a->input, "Job file (.gcode, .hpgl, .ebb) or SVG");
  cmd->add_option("--profile", a->profile, "Device profile (name or PATH): serial settings, handshake, pen, motion");
  cmd->add_option("--job", a->job_out, "Where to write the job planned from an SVG (default: IN with .gcode/.hpgl/.ebb)");
  cmd->add_option("--port", a->port, "Serial port (/dev/ttyUSB0, COM3), usb:VID:PID, file:PATH, or ebb:NAME (the EBB of that nickname)");
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
  cmd->add_option("--pen-change", a->pen_change,
                  "At the job's pauses (pen changes, reloads): ask (at the terminal) | continue | stop (then --resume)")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "One-line JSON summary on stdout; JSON progress lines on stderr");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress bar or notes");
  cmd->add_flag("--control", a->control,
                "Steered by a program: stdin lines pause|resume|abort, and continue|abort to a {\"pen_change\"} line on stderr");
  auto* g = "Simulator";
  cmd->add_option("--sim-speedup", a->sim_speedup, "Simulated plotter runs this many times faster")->capture_default_str()->group(g);
  cmd->add_option("--sim-baud", a->sim_baud, "Simulated wire baud rate")->capture_default_str()->group(g);
  cmd->add_option("--sim-latency-ms", a->sim_latency_ms, "Simulated round-trip latency")->capture_default_str()->group(g);
  cmd->add_option("--sim-out", a->sim_out, "Write what the simulator drew to PREFIX.png and PREFIX.svg")->group(g);
  auto* pg = cmd->add_option("--page", a->page, "Page for the simulator's rendering (default: fitted to what was drawn)")->group(g);
  // An SVG is laid out on the profile's sheet and planned as `export` does.
  add_layout_options(cmd, a->layout, false);
  cmd->add_option("--margin", a->layout.margin, "SVG: margin kept by --fit and --align (a length)")
      ->capture_default_str()->group("Layout");
  add_pen_height_options(cmd, a->heights);
  add_ebb_moves_option(cmd, a->heights);
  add_plan_options(cmd, a->plan);
  cmd->callback([a, rx, hs, fl, pg] {
    a->rx_buffer_given = rx->count() > 0;
    a->handshake_given = hs->count() > 0;
    a->flow_given = fl->count() > 0;
    a->page_given = pg->count() > 0;
    plot(*a);
  });
}

}  // namespace stipplot::cli
