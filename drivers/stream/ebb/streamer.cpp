#include "drivers/stream/ebb/streamer.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <thread>

#include "drivers/job/ebb_reader.hpp"
#include "drivers/stream/device_error.hpp"
#include "drivers/stream/ebb/reset.hpp"
#include "drivers/stream/session.hpp"

namespace stipplot::io::ebb {

using clock = std::chrono::steady_clock;

namespace {
// Queries whose legacy reply is one line with no OK after it.
bool no_ok(const std::string& name) { return name == "QG" || name == "V"; }

Millis millis(double s) { return Millis(static_cast<long>(s * 1000)); }
}  // namespace

Firmware parse_firmware(const std::string& reply) {
  Firmware f;
  f.text = reply;
  const size_t v = reply.find("Version ");
  if (reply.find("EBB") == std::string::npos || v == std::string::npos ||
      std::sscanf(reply.c_str() + v + 8, "%d.%d.%d", &f.major, &f.minor, &f.patch) < 2)
    throw UserError("the device does not answer V as an EiBotBoard does (it said '" + reply.substr(0, 60) +
                    "'): choose the profile of the machine on this port");
  // 2.5 brought QS's step counts and SC,11/12 as axicli uses them; 4.x is not known yet.
  if (f.major < 2 || (f.major == 2 && f.minor < 5) || f.major > 3)
    throw UserError("EBB firmware " + std::to_string(f.major) + "." + std::to_string(f.minor) + "." +
                    std::to_string(f.patch) + " is not supported (2.5 to 3.x are): update the board's firmware");
  return f;
}

Options options_for(const DeviceProfile& p) {
  Options o;
  o.fifo = p.ebb.fifo_commands;
  o.steps_per_mm = p.ebb.steps_per_mm;
  o.watchdog = Millis(static_cast<long>(p.serial.watchdog_s * 1000));
  return o;
}

Streamer::Streamer(Transport& t, Options o) : t_(t), o_(std::move(o)) {
  if (o_.in_flight < 1) throw UserError("EBB: at least one command must be in flight");
}

bool Streamer::read_line(std::string& out, Millis timeout) {
  const auto end = clock::now() + timeout;
  for (;;) {
    // A line ends at '\r' or '\n' (legacy replies end in "\r\n" or "\n\r"); empty ones are skipped.
    size_t eol;
    while ((eol = incoming_.find_first_of("\r\n")) == 0) incoming_.erase(0, 1);
    if (eol != std::string::npos) {
      out = incoming_.substr(0, eol);
      incoming_.erase(0, eol + 1);
      return true;
    }
    const auto left = std::chrono::duration_cast<Millis>(end - clock::now());
    if (left.count() <= 0) return false;
    char buf[256];
    const size_t n = t_.read(buf, sizeof buf, std::min(left, Millis(50)));
    incoming_.append(buf, n);
    if (heard_.size() < 200) heard_.append(buf, std::min(n, 200 - heard_.size()));
  }
}

namespace {
// "!6 Err: ..." (legacy) or "SC!6 Err: ..." (standardized: the command's name first).
bool is_error(const std::string& line) {
  const size_t bang = line.find('!');
  return bang != std::string::npos && bang <= 2 && line.find(" Err", bang) != std::string::npos;
}
}  // namespace

std::string Streamer::reply(const std::string& cmd, Millis timeout, long job_line) {
  const std::string name = ebb_command_name(cmd);
  const auto end = clock::now() + timeout;
  std::string data, line;
  int nudges = 0;
  for (;;) {
    const auto left = std::chrono::duration_cast<Millis>(end - clock::now());
    if (left.count() <= 0)
      throw TransportError(TransportError::Kind::Timeout,
                           "the EBB on " + t_.describe() + " did not answer `" + cmd + "` within " +
                               std::to_string(timeout.count() / 1000) + " s");
    if (!read_line(line, std::min(left, Millis(300)))) {
      // ebb_sim (the firmware on a PC) stops its clock once the board is idle, sometimes
      // with an answer half sent or an error's line end held back; any input brings the rest. A QG does (three at most: the
      // firmware's input buffer is 256 bytes); its own late answer is harmless, being a
      // line before an OK (below) or a true QG answer from a moment before.
      if (nudges++ < 3) t_.write("QG\r");
      continue;
    }
    if (is_error(line)) {
      const int code = std::atoi(line.c_str() + line.find('!') + 1);
      // With commands in flight the firmware may print a command's error after the next
      // one's OK: the line named or the one before it.
      throw DeviceError("the EBB refused `" + cmd + "`" +
                            (job_line >= 0 ? " (job line " + std::to_string(job_line + 1) + " or the one before it)"
                                           : std::string()) +
                            ": " + line,
                        job_line, code, false);
    }
    if (o_.standardized) {  // "NAME" or "NAME,data"
      if (line.compare(0, name.size(), name) != 0) continue;  // not ours (a late reply)
      return line.size() > name.size() + 1 ? line.substr(name.size() + 1) : "";
    }
    // The last data line before the OK: an earlier one is a late answer to a QG.
    if (line == "OK") return data;
    data = line;
    if (no_ok(name)) return data;
  }
}

std::string Streamer::command(const std::string& cmd) {
  t_.write(cmd + "\r");
  return reply(cmd, o_.reply_timeout);
}

void Streamer::connect() {
  // Replies a dead host left on the line are not ours.
  for (int i = 0; i < 10; ++i) {
    char buf[256];
    if (t_.read(buf, sizeof buf, Millis(30)) == 0) break;
  }
  incoming_.clear();
  heard_.clear();
  std::string v;
  // V first: a command a dropped link cut short is completed by it into an error, never a move.
  for (int attempt = 0; attempt < 3 && v.empty(); ++attempt) {
    t_.write("V\r");
    std::string line;
    const auto end = clock::now() + o_.reply_timeout;
    while (clock::now() < end) {
      if (!read_line(line, Millis(300))) {
        // Half an EBB's answer stuck in ebb_sim (see reply()): another V brings it.
        if (incoming_.find("EBB") != std::string::npos) t_.write("V\r");
        continue;
      }
      if (line.find("EBB") != std::string::npos) {
        v = line;
        break;
      }
      // The tail of an answer the drain above cut short ("Version 3.0.2": the link came
      // back while the board was answering a dead host's V): ours is still to come.
      if (line.find("Version") != std::string::npos) t_.write("V\r");
    }
  }
  if (v.empty())
    throw UserError("the device on " + t_.describe() + " does not answer V as an EiBotBoard does" +
                    (heard_.empty() ? std::string(" (it said nothing)") : " (it said '" + heard_.substr(0, 60) + "')") +
                    ": choose the profile of the machine on this port");
  fw_ = parse_firmware(v);
  incoming_.clear();
  note("EBB firmware " + v);
  if (fw_.major >= 3) {
    if (o_.standardized) {
      // Its own answer is an empty line (the mode changes between the name and the end).
      t_.write("CU,10,1\r");
      std::this_thread::sleep_for(Millis(50));
    } else {
      command("CU,10,0");
    }
    if (o_.setup) command("CU,4," + std::to_string(o_.fifo));  // waits for the FIFO to empty first
  } else if (o_.standardized) {
    throw UserError("EBB firmware " + v + " has no standardized replies (CU,10 is 3.x)");
  }
}

std::array<int64_t, 2> Streamer::position() {
  const std::string r = command("QS");
  long long a = 0, b = 0;
  if (std::sscanf(r.c_str(), "%lld,%lld", &a, &b) != 2) throw UserError("the EBB answered QS with '" + r + "'");
  return {a, b};
}

bool Streamer::pen_up() { return std::atoi(command("QP").c_str()) != 0; }

std::string Streamer::nickname() {
  try {
    return command("QT");
  } catch (const DeviceError&) {  // a firmware without QT (before 2.5.5) has no nickname
    return "";
  }
}

bool Streamer::idle() {
  const std::string r = command("QG");
  return (std::strtol(r.c_str(), nullptr, 16) & 0x0F) == 0;  // FIFO, executing, motor 1, motor 2
}

void Streamer::wait_idle(double max_seconds) {
  const auto end = clock::now() + millis(max_seconds) + o_.watchdog;
  while (!idle()) {
    if (clock::now() > end)
      throw TransportError(TransportError::Kind::Timeout, "the EBB on " + t_.describe() + " did not finish its moves");
    std::this_thread::sleep_for(Millis(20));
  }
}

ResumePlan Streamer::resume(const Job& job, const JournalState& journal, const DeviceProfile& profile) {
  const auto& L = job.lines;
  const double spm = profile.ebb.steps_per_mm;
  wait_idle(60);  // what a dead host queued runs to its end first
  const std::array<int64_t, 2> at = position();
  const bool up = pen_up();
  // The servo settings are the job's own (a board may have been set up since).
  ResumePlan rp;
  for (const JobLine& l : L) {
    if (ebb_motion_command(ebb_command_name(l.text))) break;
    if (ebb_command_name(l.text) == "SC") rp.preamble.push_back(l.text);
  }
  if (journal.last_acked < 0) return rp;  // nothing ran: from the start (EM zeroes the board)
  const size_t first = static_cast<size_t>(journal.last_acked);
  const size_t last = std::min(L.size() - 1, first + o_.in_flight + 1);
  long where = -1;     // position and pen match
  long pos_only = -1;  // position matches, the pen was lifted by the host (a pause or an abort)
  for (size_t i = first; i <= last; ++i) {
    if (ebb_motor_steps(L[i].x, L[i].y, spm) != at) continue;
    if (L[i].pen_down != up) {
      where = static_cast<long>(i);
      break;
    }
    if (pos_only < 0) pos_only = static_cast<long>(i);
  }
  if (where < 0 && pos_only >= 0 && up) {
    where = pos_only;
    for (size_t i = static_cast<size_t>(where) + 1; i-- > 0;)
      if (ebb_command_name(L[i].text) == "SP" && L[i].pen_down) {
        rp.preamble.push_back(L[i].text);  // the job's own pen-down, with its delay
        break;
      }
  }
  size_t first_sm = 0;
  while (first_sm < L.size() && !ebb_motion_command(ebb_command_name(L[first_sm].text))) ++first_sm;
  const bool home = at[0] == 0 && at[1] == 0;
  if (where >= 0 && home && static_cast<size_t>(where) < first_sm) {
    rp.next = 0;  // still in the set-up, maybe reset there: all of it again (EM zeroes the board where it stands)
    rp.preamble.clear();
    rp.why = "the board stands at home before the job's first move";
    return rp;
  }
  if (where < 0 && home) {
    // Reset (a power cycle or reboot zeroes the counters and loses the FIFO): what it ran
    // is the journal's to say. Only the operator can say where the carriage is.
    ResumePlan reset = plan_reset_resume(job, journal, profile, fw_.major >= 3 ? o_.fifo : 1);
    reset.note = "the board was reset (it stands at 0,0, where none of the journal's last lines leave it): the carriage is "
                 "taken to be at home, where the plot began; if it is not, stop and move it there by hand, then resume "
                 "again; resuming at line " + std::to_string(reset.next + 1) + ", " + reset.why;
    return reset;
  }
  if (where < 0) {
    char b[200];
    std::snprintf(b, sizeof b, "the EBB stands at motor steps %lld,%lld (pen %s), not where the job's lines %ld-%zu leave it",
                  static_cast<long long>(at[0]), static_cast<long long>(at[1]), up ? "up" : "down", journal.last_acked + 1,
                  last + 1);
    throw UserError(std::string(b) +
                    ": it was moved since (a reset board stands at 0,0); nothing was sent: move it home by hand, "
                    "switch it off and on, and resume again");
  }
  rp.next = static_cast<size_t>(where) + 1;
  if (rp.next != first + 1)
    rp.note = "the board ran " + std::to_string(rp.next - first - 1) + " line(s) past the journal's last: resuming at line " +
              std::to_string(rp.next + 1);
  rp.why = "the board kept its position (QS) and pen (QP)";
  return rp;
}

// One stream() call: commands in order, at most in_flight unanswered; each OK is a line
// done (queued on a powered board).
class Streamer::JobRun {
 public:
  JobRun(Streamer& s, const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
         const ProgressFn& progress, StreamControls* controls)
      : s_(s), session_(job, start, preamble, journal, progress), controls_(controls), spm_(s.o_.steps_per_mm) {
    for (const std::string& p : preamble)
      if (ebb_motion_command(ebb_command_name(p))) {
        const EbbCommand c = parse_ebb_command(p, 0);
        preamble_moves_ |= c.s1 != 0 || c.s2 != 0;
      }
    for (const JobLine& l : job.lines) {
      if (pen_up_.empty() && l.text.rfind("SP,1", 0) == 0) pen_up_ = l.text;
      if (pen_down_.empty() && l.text.rfind("SP,0", 0) == 0) pen_down_ = l.text;
    }
  }

  StreamResult run() {
    try {
      if (!send_all()) {
        session_.sync_journal();
        return session_.finish();
      }
      settle();
    } catch (const UserError&) {  // device errors and a lost link too: the journal is made durable
      session_.sync_journal();
      throw;
    }
    session_.complete();
    return session_.finish();
  }

 private:
  const JobLine* line_of(size_t item) const {
    const long l = session_.job_line(item);
    return l < 0 ? nullptr : &session_.job().lines[static_cast<size_t>(l)];
  }

  // The firmware time of what is queued or in flight: the longest an OK may take.
  double queued_seconds() const {
    double s = 0;
    const size_t from = answered_ > static_cast<size_t>(s_.o_.fifo) + 1 ? answered_ - s_.o_.fifo - 1 : 0;
    for (size_t i = from; i < sent_; ++i)
      if (const JobLine* l = line_of(i)) s += l->est_s;
    return s;
  }

  void answer_front() {
    const size_t item = in_flight_.front();
    const double allowed = queued_seconds();
    if (item == kQb) {
      const std::string r = s_.reply("QB", s_.o_.watchdog + millis(allowed));
      in_flight_.pop_front();
      button_ |= std::atoi(r.c_str()) != 0;
      return;
    }
    if (item == kQs) {
      const std::string r = s_.reply("QS", s_.o_.watchdog + millis(allowed));
      in_flight_.pop_front();
      const size_t before = qs_after_.front();
      qs_after_.pop_front();
      long long a = 0, b = 0;
      if (std::sscanf(r.c_str(), "%lld,%lld", &a, &b) == 2) prove({a, b}, before);
      return;
    }
    s_.reply(session_.text(item), s_.o_.watchdog + millis(allowed), session_.job_line(item));
    in_flight_.pop_front();
    answered_ = item + 1;
    if (ebb_motion_command(ebb_command_name(session_.text(item)))) moved_ = true;
    if (session_.job_line(item) >= 0) session_.acknowledge(session_.job_line(item));
    session_.report(sent_);
  }

  // A QS answered after items [0, before) were queued: the carriage stood on the path of
  // a job line from the first one the board may not have run by then (ebb/reset.hpp:
  // the FIFO holds the last ones) up to the last acknowledged, the earliest such line
  // taken. While that window reaches back into a preamble that moves (a reset's travel
  // home), nothing is proved: the carriage may be on that travel. O(fifo + window).
  void prove(const Steps& at, size_t before) {
    const long last = before ? session_.job_line(before - 1) : -1;
    if (last < 0) return;  // nothing of the job queued yet
    const size_t start = session_.start();
    const size_t lo = first_unsure(session_.job(), last, s_.o_.fifo);
    if (lo < start && preamble_moves_) return;
    const size_t from = std::max({lo, start, proof_.line > 0 ? static_cast<size_t>(proof_.line) : size_t{0}});
    const long line = first_on_path(session_.job(), from, static_cast<size_t>(last), at, spm_);
    if (line < 0) return;
    const double x = static_cast<double>(at[0] + at[1]) / (2 * spm_), y = static_cast<double>(at[0] - at[1]) / (2 * spm_);
    const ProvenPoint p{line, x, y, 0};
    if (p == proof_) return;
    proof_ = p;
    session_.proven(p);
  }

  // Waits for the board to run what it queued (the job's end, a pause, a hold), proving
  // where the carriage is as it goes and once it stands: the FIFO is no longer kept full,
  // so a proof says more than the FIFO's bound does (at a pause, exactly where it stopped).
  void settle() {
    const auto end = clock::now() + millis(queued_seconds()) + s_.o_.watchdog;
    while (!s_.idle()) {
      if (clock::now() > end)
        throw TransportError(TransportError::Kind::Timeout, "the EBB on " + s_.t_.describe() + " did not finish its moves");
      if (proving()) {
        next_proof_ = clock::now() + s_.o_.proof_interval;
        prove(s_.position(), sent_);
      }
      std::this_thread::sleep_for(Millis(20));
    }
    if (moved_ && spm_ > 0 && s_.o_.proof_interval.count() > 0) prove(s_.position(), sent_);
  }

  void drain() {
    while (!in_flight_.empty()) answer_front();
  }

  // The job's pause (a pen change): everything before it drawn, then ask.
  void pause_at(size_t item) {
    drain();
    settle();
    const JobLine& jl = *line_of(item);
    PauseAnswer a = PauseAnswer::go;
    if (s_.o_.on_pause) {
      session_.pause_begins();
      a = s_.o_.on_pause({session_.job_line(item), jl.note});
      session_.pause_ends();
    }
    const std::string where = "stopped at the pause on line " + std::to_string(session_.job_line(item) + 1) + " (" + jl.note + ")";
    if (a == PauseAnswer::stop) throw UserError(where);
    session_.acknowledge(session_.job_line(item));
    if (a == PauseAnswer::stop_after) throw UserError(where + ", counted as done: do it before resuming");
  }

  // The operator's pause (Ctrl-C): the queue runs out, the pen goes up; then resume or abort.
  bool hold() {
    drain();
    settle();
    const bool was_down = !s_.pen_up();
    if (was_down && !pen_up_.empty()) s_.command(pen_up_);
    while (!controls_->resume.load() && !controls_->abort.load()) {
      session_.report(sent_, "Hold");
      std::this_thread::sleep_for(Millis(50));
    }
    controls_->pause = false;
    if (controls_->abort.exchange(false)) return false;
    controls_->resume = false;
    if (was_down && !pen_down_.empty()) s_.command(pen_down_);
    return true;
  }

  bool send_all() {
    const size_t n = session_.items();
    while (sent_ < n || !in_flight_.empty()) {
      if (controls_ && controls_->abort.exchange(false)) {
        // Stop sending; what the board queued runs out (under a second), the pen goes up.
        drain();
        settle();
        if (!pen_up_.empty()) s_.command(pen_up_);
        return false;
      }
      if (controls_ && controls_->pause.load() && !hold()) {
        if (!pen_up_.empty()) s_.command(pen_up_);
        return false;
      }
      if (button_) {
        // The PRG button: stop as an abort does, and say how to go on.
        drain();
        settle();
        if (!pen_up_.empty()) s_.command(pen_up_);
        session_.sync_journal();
        const long done = session_.result().last_acked;
        throw UserError("paused by the board's PRG button after line " + std::to_string(done + 1) +
                        ": the pen is up and the journal kept; `stipplot plot --resume JOB` goes on from there");
      }
      // Until the first move is answered, one command at a time: a set-up the board refuses
      // stops the plot before the pen moves.
      if (sent_ < n && in_flight_.size() < (moved_ ? s_.o_.in_flight : 1)) {
        const JobLine* jl = line_of(sent_);
        if (jl && jl->host_only) {
          if (jl->pause) pause_at(sent_);
          else session_.acknowledge(session_.job_line(sent_));
          answered_ = ++sent_;
          continue;
        }
        if (asking_button()) {  // as a QS: a place in the window
          s_.t_.write("QB\r");
          in_flight_.push_back(kQb);
          next_button_ = clock::now() + s_.o_.button_interval;
          continue;
        }
        if (proving()) {  // takes the free place in the window; the command waits for the next
          s_.t_.write("QS\r");
          in_flight_.push_back(kQs);
          qs_after_.push_back(sent_);
          next_proof_ = clock::now() + s_.o_.proof_interval;
          continue;
        }
        s_.t_.write(session_.text(sent_) + "\r");
        in_flight_.push_back(sent_++);
        continue;
      }
      answer_front();
    }
    return true;
  }

  bool proving() const { return moved_ && spm_ > 0 && s_.o_.proof_interval.count() > 0 && clock::now() >= next_proof_; }

  bool asking_button() const { return moved_ && s_.o_.button_interval.count() > 0 && clock::now() >= next_button_; }

  static constexpr size_t kQs = static_cast<size_t>(-1);  // a QS in flight, not an item
  static constexpr size_t kQb = static_cast<size_t>(-2);  // a QB in flight
  Streamer& s_;
  StreamSession session_;
  StreamControls* controls_;
  std::deque<size_t> in_flight_;
  std::deque<size_t> qs_after_;  // for each QS in flight: the items sent before it
  double spm_ = 0;
  bool preamble_moves_ = false;  // the preamble has SMs or LMs that move
  clock::time_point next_proof_ = clock::now();
  clock::time_point next_button_ = clock::now();
  bool button_ = false;  // a QB said the PRG button was pressed
  ProvenPoint proof_;  // the last journalled
  size_t sent_ = 0, answered_ = 0;
  bool moved_ = false;  // an SM or LM has been answered
  std::string pen_up_, pen_down_;
};

StreamResult Streamer::stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                              const ProgressFn& progress, StreamControls* controls) {
  // LM's kinematics (rate - accel / 2, its accumulators) are 2.7's: refused before anything is sent.
  if (fw_.major == 2 && fw_.minor < 7) {
    bool lm = std::any_of(preamble.begin(), preamble.end(), [](const std::string& p) { return ebb_command_name(p) == "LM"; });
    for (size_t i = start; i < job.lines.size() && !lm; ++i)
      lm = !job.lines[i].host_only && ebb_command_name(job.lines[i].text) == "LM";
    if (lm)
      throw UserError("the job has LM moves, which EBB firmware " + std::to_string(fw_.major) + "." + std::to_string(fw_.minor) +
                      " runs differently (2.7 or later needed): export it again with [ebb] moves = \"sm\" (--ebb-moves sm), or update the firmware");
  }
  return JobRun(*this, job, start, preamble, journal, progress, controls).run();
}

}  // namespace stipplot::io::ebb
