// The job loop of the grbl streamer: what one Streamer::stream() call does.
#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <deque>
#include <thread>

#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/gcode_state.hpp"
#include "drivers/motion/grbl_motion.hpp"
#include "drivers/stream/grbl/codes.hpp"
#include "drivers/stream/grbl/streamer.hpp"
#include "drivers/stream/session.hpp"

namespace stipplot::io::grbl {

namespace {
// A line grbl runs only once its planner is empty (gcode.c): a dwell, a spindle (pen)
// command, a program pause or end. Its "ok" proves every move before it ran.
bool is_sync_line(const std::string& text) {
  for (const GcodeWord& w : gcode_words(text)) {
    if (w.letter == 'G' && is_dwell(w)) return true;
    if (w.letter == 'M') {
      const long m = std::lround(w.value);
      if (m == 0 || m == 1 || m == 2 || m == 3 || m == 4 || m == 5 || m == 30) return true;
    }
  }
  return false;
}

// A line that only dwells (G4 P..): grbl skipping it changes no mark the lines behind it draw.
bool only_dwell(const std::string& text) {
  bool dwell = false;
  for (const GcodeWord& w : gcode_words(text)) {
    if (w.letter == 'G' && is_dwell(w)) dwell = true;
    else if (w.letter != 'P' && w.letter != 'N') return false;
  }
  return dwell;
}

// Seconds a line dwells, as grbl counts them (its 50 ms steps), 0 for any other line.
double dwell_seconds(const std::string& text) {
  const GcodeEffect e = GcodeState().apply(text);  // a dwell is not modal: any state reads it
  return e.dwell ? motion::grbl_dwell_seconds(e.dwell_p) : 0;
}

// A line that moves an axis (X, Y or Z word, not a dwell).
bool moves_axes(const std::string& text) {
  bool axis = false;
  for (const GcodeWord& w : gcode_words(text)) {
    if (w.letter == 'G' && is_dwell(w)) return false;
    axis |= w.letter == 'X' || w.letter == 'Y' || w.letter == 'Z';
  }
  return axis;
}

// "20", "0.6": the watchdog's time as a person reads it.
std::string seconds_text(Millis m) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", static_cast<double>(m.count()) / 1000);
  return b;
}
}  // namespace

// One stream() call. The loop sends while the window has room, polls status, and hands
// each line grbl sends to the handler of its kind; controls (pause, resume, abort) are
// applied between lines.
class Streamer::JobRun {
 public:
  JobRun(Streamer& s, const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
         const ProgressFn& progress, StreamControls* controls)
      : s_(s), o_(s.o_), session_(job, start, preamble, journal, progress), controls_(controls),
        window_(o_.mode, static_cast<size_t>(o_.rx_buffer)) {
    refuse_long_lines();
    for (size_t i = 0; i < preamble.size(); ++i)
      if (moves_axes(preamble[i])) last_preamble_move_ = static_cast<long>(i);
  }

  StreamResult run() {
    try {
      for (;;) {
        const auto now = clock::now();
        if (apply_controls() == Control::Aborted) return abort();
        send_while_it_fits();
        if (finished(now)) break;
        poll_if_due(now);
        read_and_dispatch();
        check_watchdog();
      }
    } catch (const TransportError&) {
      session_.sync_journal();
      throw;
    }
    session_.complete();
    StreamResult res = session_.finish();
    session_.all_lines_done();
    report();
    return res;
  }

 private:
  enum class Control { Go, Aborted };
  using clock = std::chrono::steady_clock;

  // Before anything is sent: a line that cannot fit grbl's receive buffer would never
  // be sent (character counting) or overflow it.
  void refuse_long_lines() const {
    for (size_t i = 0; i < session_.items(); ++i) {
      const size_t bytes = session_.text(i).size() + 1;
      if (bytes <= static_cast<size_t>(o_.rx_buffer)) continue;
      const long line = session_.job_line(i);
      throw UserError((line >= 0 ? "line " + std::to_string(line + 1) : std::string("a resume line")) + " is " +
                      std::to_string(bytes) + " bytes with its newline, more than grbl's receive buffer of " +
                      std::to_string(o_.rx_buffer) + " bytes (profile [serial] rx_buffer_bytes, --rx-buffer): "
                      "it could never be sent whole; nothing was sent");
    }
  }

  // Something happened: a line answered, or a status report that differs from the last.
  void progressed() { last_progress_ = clock::now(); }

  // Lines outstanding and nothing happening for the watchdog's time beyond what the
  // oldest of them takes by the timed plan (a long dwell): the device is stuck.
  void check_watchdog() {
    if (paused_ || window_.empty()) {
      progressed();
      return;
    }
    const long line = session_.job_line(window_.oldest().item);
    const double own_s = line >= 0 ? session_.job().lines[static_cast<size_t>(line)].est_s : 0;
    const auto allowed = o_.watchdog + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(own_s));
    if (clock::now() - last_progress_ <= allowed) return;
    rollback_to_executed();
    session_.sync_journal();
    throw TransportError(TransportError::Kind::Timeout,
                         "grbl on " + s_.t_.describe() + " took nothing for " +
                             seconds_text(o_.watchdog) + " s (no line answered, no motion, state " +
                             (s_.last_status_.state.empty() ? std::string("unknown") : s_.last_status_.state) +
                             ") with " + std::to_string(window_.size()) + " line(s) unanswered: the plot stopped");
  }

  void report() { session_.report(next_, s_.last_status_.state, s_.last_status_.x, s_.last_status_.y, executed_estimate()); }

  // Everything sent and answered, and grbl has been seen idle since (or is checking).
  bool finished(clock::time_point now) {
    if (next_ < session_.items() || !window_.empty()) return false;
    if (!finishing_) {
      finishing_ = true;
      next_poll_ = now;  // ask at once whether grbl is done
    }
    return idle_after_everything_ || s_.last_status_.state == "Check";
  }

  Control apply_controls() {
    if (!controls_) return Control::Go;
    if (controls_->abort.exchange(false)) return Control::Aborted;
    if (controls_->pause.exchange(false) && !paused_) {
      s_.t_.write("!");
      paused_ = true;
      if (o_.lift_on_pause) {
        std::this_thread::sleep_for(Millis(100));
        s_.t_.write("\x9e");  // spindle stop override: lifts a servo pen while held
      }
      s_.note("paused (feed hold)");
    }
    if (controls_->resume.exchange(false) && paused_) {
      s_.t_.write("~");
      paused_ = false;
      s_.note("resumed");
    }
    return Control::Go;
  }

  void send_while_it_fits() {
    while (!paused_ && next_ < session_.items()) {
      const std::string& text = session_.text(next_);
      const size_t bytes = text.size() + 1;
      if (!window_.fits(bytes)) break;
      s_.t_.write(text + "\n");
      window_.sent(next_, bytes);
      ++next_;
    }
  }

  void poll_if_due(clock::time_point now) {
    if (now < next_poll_) return;
    s_.t_.write("?");
    // grbl answers the '?'s in order: each report says what it held once the lines sent
    // before its '?' had arrived, and nothing of the ones sent after (still on the wire).
    if (asked_after_.size() < 1024) asked_after_.push_back(next_);  // lost reports only age the rest: safe
    next_poll_ = now + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1.0 / o_.poll_hz));
  }

  // Waits for one line from grbl until the next poll is due, and hands it to the
  // handler of its kind.
  void read_and_dispatch() {
    std::string line;
    auto wait = std::clamp(std::chrono::duration_cast<Millis>(next_poll_ - clock::now()), Millis(1), Millis(50));
    if (!s_.reader_.read_line(line, wait)) {
      if (clock::now() - last_rx_ > o_.silence_timeout)
        throw TransportError(TransportError::Kind::Timeout,
                             "grbl on " + s_.t_.describe() + " stopped answering (nothing for " +
                                 std::to_string(o_.silence_timeout.count() / 1000) + " s, not even status reports)");
      return;
    }
    last_rx_ = clock::now();
    const Reply r = classify_reply(line);
    if (r.answers_a_line()) progressed();
    switch (r.kind) {
      case ReplyKind::Ok: on_ok(); break;
      case ReplyKind::Error: on_error(line, r.code); break;
      case ReplyKind::Alarm: on_alarm(r.code); break;
      case ReplyKind::Status: on_status(line); break;
      case ReplyKind::Banner: on_restart(); break;
      case ReplyKind::Message: s_.note("grbl: " + line); break;
      case ReplyKind::Other: s_.note("unrecognised reply from grbl: '" + line + "' (ignored)"); break;
    }
  }

  // The line answered was done; a job line (not the preamble) counts and is journalled.
  // A sync line's answer proves the moves before it ran, except after a reset: grbl ends
  // the wait for its planner on the abort and still answers ok (protocol.c,
  // protocol_buffer_synchronize returns on sys.abort; gc_execute_line reports STATUS_OK).
  void acknowledge(const LineWindow::Line& l, bool proves_moves = true) {
    const long line = session_.job_line(l.item);
    // A sync line answered after the preamble's travel: the machine is on the job's path.
    if (proves_moves && static_cast<long>(l.item) > last_preamble_move_ && is_sync_line(session_.text(l.item)))
      last_preamble_move_ = -1;
    if (line < 0) return;
    session_.acknowledge(line);
    if (proves_moves && is_sync_line(session_.job().lines[static_cast<size_t>(line)].text)) {
      // grbl answers a sync line once it has run, after every block before it: all
      // acknowledged moves are executed.
      last_sync_acked_ = line;
      before_sync_ = std::move(acked_motion_);
      acked_motion_.clear();
      prove_sync(static_cast<size_t>(line));
      return;
    }
    if (session_.job().lines[static_cast<size_t>(line)].motion) {
      acked_motion_.push_back(line);
      ++motion_acked_;
      // Older moves than the snapshot's planner could hold are known executed.
      while (motion_acked_ - acked_motion_.size() + static_cast<size_t>(o_.planner_blocks) < snapshot_.motion_acked)
        acked_motion_.pop_front();
    }
  }

  void on_ok() {
    if (window_.empty()) {
      s_.note("unexpected 'ok' from grbl (ignored)");
      return;
    }
    acknowledge(window_.answered());
    report();
  }

  void on_error(const std::string& line, int code) {
    if (window_.empty()) {
      s_.note("grbl reported " + line + " with no line outstanding: " + error_meaning(code));
      return;
    }
    const LineWindow::Line l = window_.answered();
    const long idx = session_.job_line(l.item);
    const std::string where = idx >= 0 ? "line " + std::to_string(idx + 1) : "resume preamble";
    const std::string msg =
        "grbl error:" + std::to_string(code) + " at " + where + " `" + session_.text(l.item) + "`: " + error_meaning(code);
    StreamResult& res = session_.result();
    res.errors.push_back({idx, code});
    if (o_.skip_errors || idx < 0) {
      ++res.errors_skipped;
      s_.note(msg + " (skipped)");
      if (idx >= 0) acknowledge(l);
      return;
    }
    // grbl drops the rejected line but runs the lines behind it in its receive buffer
    // (protocol.c reports the error and reads on): the machine would draw on without
    // it. Stop it at once and resume from the rejected line, which was not executed; a
    // rejected dwell only changed the timing of what ran after it, which stays done.
    const long first_undone = only_dwell(session_.text(l.item)) ? LONG_MAX : idx - 1;
    try {
      stop_machine();
      session_.rollback_to(std::min(rollback_to_executed(true), first_undone));
      session_.device_cleared();
    } catch (const TransportError&) {
      session_.rollback_to(std::min(executed_estimate(), first_undone));
    }
    throw DeviceError(msg + (first_undone == LONG_MAX
                                 ? " (the job stopped; grbl skipped that dwell and drew on: --resume goes on from where it stopped)"
                                 : " (the job stopped; that line was not executed: --resume sends it again, or fix it if it is wrong)"),
                      idx, code, false);
  }

  // Feed hold, wait until the machine stands, then a soft reset: grbl's buffers are
  // dropped without the position loss (ALARM:3) a reset in motion causes.
  void stop_machine() {
    s_.t_.write("!");
    status_after_hold(Millis(5000));
    reset_counting_answers();
  }

  // Ctrl-X, counting the answers that arrive before grbl's banner: for lines it had taken
  // before the reset (not proof that moves before them ran: see acknowledge).
  void reset_counting_answers() {
    s_.t_.write("\x18");
    const auto end = clock::now() + o_.banner_timeout;
    std::string line;
    while (clock::now() < end) {
      if (!s_.reader_.read_line(line, Millis(50))) continue;
      const Reply r = classify_reply(line);
      if (r.kind == ReplyKind::Banner) return;
      if (r.answers_a_line() && !window_.empty()) {
        const LineWindow::Line l = window_.answered();
        if (r.kind == ReplyKind::Ok) acknowledge(l, false);
      }
    }
    throw TransportError(TransportError::Kind::Timeout, "grbl did not restart after a soft reset (Ctrl-X) within " +
                                                            std::to_string(o_.banner_timeout.count()) + " ms");
  }

  [[noreturn]] void on_alarm(int code) {
    const long idx = window_.empty() ? session_.result().last_acked : session_.job_line(window_.oldest().item);
    // Leave the port sane: reset flushes grbl's buffers and restarts its parser.
    bool reset_ok = true;
    try {
      reset_counting_answers();
    } catch (const TransportError&) {
      reset_ok = false;
    }
    rollback_to_executed(reset_ok);
    if (reset_ok) session_.device_cleared();
    throw DeviceError("grbl ALARM:" + std::to_string(code) + " near line " + std::to_string(idx + 1) + ": " +
                          alarm_meaning(code) + " The machine is locked: check it, unlock ($X) or re-home, then resume.",
                      idx, code, true);
  }

  [[noreturn]] void on_restart() {
    const long done = rollback_to_executed(true);
    session_.device_cleared();
    throw DeviceError("grbl restarted during the job (reset or power loss); its buffer was lost. Resume continues after line " +
                          std::to_string(done + 1),
                      done, 0, true);
  }

  void on_status(const std::string& line) {
    Status st;
    if (!parse_status(line, st)) return;
    // The items sent before this report's '?' (0 for a report nobody here asked for).
    size_t sent_when_asked = 0;
    if (!asked_after_.empty()) {
      sent_when_asked = asked_after_.front();
      asked_after_.pop_front();
    }
    const Status& was = s_.last_status_;
    if (st.state != was.state || st.x != was.x || st.y != was.y || st.z != was.z || st.blocks_free != was.blocks_free ||
        st.bytes_free != was.bytes_free)
      progressed();
    take_snapshot(st);
    prove_position(st);
    report();
    if (st.state.rfind("Alarm", 0) == 0) {
      rollback_to_executed(true);
      throw DeviceError("grbl entered ALARM state during the job (see the machine); resume after unlocking", -1, 0, true);
    }
    if (st.state.rfind("Hold", 0) == 0 && !paused_ && !window_.empty()) release_program_pause();
    const bool empty = st.state == "Idle" && (st.blocks_free < 0 || st.blocks_free == o_.planner_blocks) &&
                       (st.bytes_free < 0 || st.bytes_free == o_.rx_buffer);
    if (empty && sent_when_asked >= session_.items()) idle_after_everything_ = true;
    count_lost_replies(empty, sent_when_asked);
  }

  // A hold that is not ours, with a pause of the job (M0) as the oldest line unanswered:
  // grbl has done everything before it (M0 waits for the planner to empty) and waits for
  // cycle start. Ask, then release it with '~' or stop there.
  void release_program_pause() {
    const size_t item = window_.oldest().item;
    const long line = session_.job_line(item);
    if (line < 0 || m0_released_ == static_cast<long>(item)) return;
    const JobLine& jl = session_.job().lines[static_cast<size_t>(line)];
    if (!jl.pause) return;
    PauseAnswer answer = PauseAnswer::go;
    if (o_.on_pause) {
      session_.pause_begins();
      answer = o_.on_pause({line, jl.note});
      session_.pause_ends();
      progressed();  // the operator's time is not the device's
    }
    if (answer != PauseAnswer::go) stop_at_pause(line, jl, answer);
    m0_released_ = static_cast<long>(item);
    s_.t_.write("~");
  }

  // The lines after the pause wait in grbl's buffer: a reset drops them. With stop_after
  // the pause itself counts as done (the operator changes the pen before resuming).
  [[noreturn]] void stop_at_pause(long line, const JobLine& jl, PauseAnswer answer) {
    if (answer == PauseAnswer::stop_after) acknowledge(window_.answered());
    try {
      s_.soft_reset();
      session_.device_cleared();
    } catch (const TransportError&) {
    }
    session_.sync_journal();
    throw UserError("stopped at the pause on line " + std::to_string(line + 1) + " (" + jl.note + ")" +
                    (answer == PauseAnswer::stop_after ? ", counted as done: do it before resuming" : ""));
  }

  // Lost replies: grbl idle with its buffers empty, several reports running, yet lines
  // unanswered that were sent before those reports were asked for (their answers would
  // have come first). Lines sent after a '?' may still be on the wire, where grbl cannot
  // see them: counting those answered would let the host overfill grbl's buffer.
  void count_lost_replies(bool empty, size_t sent_when_asked) {
    const bool covers = !window_.empty() && window_.oldest().item < sent_when_asked;
    if (!empty || !covers) {
      idle_polls_ = 0;
      return;
    }
    if (idle_polls_++ == 0) idle_first_ = clock::now();
    if (idle_polls_ < 3 || clock::now() - idle_first_ <= o_.lost_reply_after) return;
    // grbl reports Idle, its buffers empty, while it dwells: a dwell among these lines (the
    // window's items run on from its oldest) is given its time as well.
    double dwell = 0;
    for (size_t i = window_.oldest().item; i < sent_when_asked; ++i) dwell = std::max(dwell, dwell_seconds(session_.text(i)));
    if (clock::now() - idle_first_ <= o_.lost_reply_after + std::chrono::duration<double>(dwell)) return;
    size_t lost = 0;
    while (!window_.empty() && window_.oldest().item < sent_when_asked) {
      acknowledge(window_.answered());
      ++lost;
    }
    StreamResult& res = session_.result();
    res.warnings.push_back("grbl went idle without acknowledging " + std::to_string(lost) +
                           " line(s): a reply was lost; counting them as done");
    s_.note(res.warnings.back());
    idle_polls_ = 0;
  }

  // A status report and what had been acknowledged when it came. grbl prints answers
  // and reports in the order things happen, so the blocks in its planner then are the
  // newest moves acknowledged before the report; moves acknowledged after it may or may
  // not have run since.
  void take_snapshot(const Status& st) {
    s_.last_status_ = st;
    snapshot_ = {motion_acked_, session_.result().last_acked, st.blocks_free};
  }

  // The last job line grbl has surely executed (as of the latest status report):
  // acknowledged lines may still wait in its planner, and a reset (ours, an alarm's, a
  // power loss) discards them. Erring early only draws a move twice; erring late would
  // lose it.
  long executed_estimate() const {
    int in_planner = snapshot_.blocks_free >= 0 ? o_.planner_blocks - snapshot_.blocks_free : o_.planner_blocks;
    const size_t first_kept = motion_acked_ - acked_motion_.size();  // acked_motion_[0]'s number
    // kept moves acked before the report (none when a sync line since has cleared them)
    const size_t known = snapshot_.motion_acked > first_kept ? snapshot_.motion_acked - first_kept : 0;
    in_planner = std::clamp(in_planner, 0, static_cast<int>(known));
    if (in_planner == 0) return std::max(snapshot_.last_acked, last_sync_acked_);
    return std::max(acked_motion_[known - static_cast<size_t>(in_planner)] - 1, last_sync_acked_);
  }

  // Where grbl stopped, once its buffers are gone (after a reset grbl keeps its step
  // position): among the moves acknowledged but not known executed, the first whose
  // line holds that point is the one under way (done up to the one before it), or, if
  // the point is its end, the last done. Earlier rather than later on crossings: a move
  // drawn twice, never one lost. -2 when no move holds it (a power cycle zeroes grbl).
  long executed_at_position(double x, double y) const {
    constexpr double tol = 0.02;  // mm: a couple of steps
    const auto& L = session_.job().lines;
    // Every move not proved run by a sync line: grbl drops a block from its planner once
    // the stepper has taken it, so the planner fill alone can call a move done that a
    // hold and a reset cut short.
    // 0: not on the move; 1: on it, short of its end; 2: at its end (within MPos's
    // rounding: a hold can stop a move one step short, and that move is then drawn again).
    auto on = [&](size_t line) {
      const double x0 = line ? L[line - 1].x : 0, y0 = line ? L[line - 1].y : 0, x1 = L[line].x, y1 = L[line].y;
      const double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
      const double u = len2 > 0 ? std::clamp(((x - x0) * dx + (y - y0) * dy) / len2, 0.0, 1.0) : 0.0;
      if (std::hypot(x0 + u * dx - x, y0 + u * dy - y) > tol) return 0;
      return std::hypot(x1 - x, y1 - y) <= 0.003 ? 2 : 1;
    };
    for (long line : acked_motion_)
      if (const int at = on(static_cast<size_t>(line))) return at == 2 ? line : line - 1;
    // Short of the end of a move the last sync line's answer called done: a reset ended
    // that sync's wait for the planner, and grbl answered ok all the same (seen on the
    // real firmware: an outside reset in mid-stroke, the stroke's M5 answered before ALARM:3).
    for (long line : before_sync_)
      if (on(static_cast<size_t>(line)) == 1) return line - 1;
    return -2;
  }

  // A status report's position on the path of the acknowledged lines proves everything
  // before it was drawn; the journal keeps it, so a resume after a power loss (position
  // gone) starts there rather than before every move grbl had queued. The search starts
  // where the machine surely is by now (the last proof, the last sync line answered, or
  // the session's first line once its preamble's travel is proved run) and takes the
  // first line whose path holds the position: at a crossing the earlier, so a proof never
  // claims more than was drawn. O(lines acknowledged since that start).
  void prove_position(const Status& st) {
    if (last_preamble_move_ >= 0 || st.state == "Check" || st.state.rfind("Alarm", 0) == 0) return;
    constexpr double tol = 0.02;  // mm: a couple of steps, as executed_at_position
    const auto& L = session_.job().lines;
    const long last = session_.result().last_acked;
    for (long k = std::max({proof_.line, last_sync_acked_, static_cast<long>(session_.start())}); k <= last; ++k) {
      const size_t i = static_cast<size_t>(k);
      if (k < 0 || !L[i].motion) continue;
      const double x0 = i ? L[i - 1].x : 0, y0 = i ? L[i - 1].y : 0, dx = L[i].x - x0, dy = L[i].y - y0;
      const double len2 = dx * dx + dy * dy;
      const double u = len2 > 0 ? std::clamp(((st.x - x0) * dx + (st.y - y0) * dy) / len2, 0.0, 1.0) : 0.0;
      if (std::hypot(x0 + u * dx - st.x, y0 + u * dy - st.y) > tol) continue;
      const ProvenPoint p{k, st.x, st.y, st.z};
      if (p == proof_) return;
      proof_ = p;
      session_.proven(p);
      return;
    }
  }

  // A sync line's answer proves it ran, and everything before it: the next line starts
  // where it leaves the pen. Not for a line that lowers the pen (its answer comes before
  // the pen rests on the paper: a dot is made by the dwell after it) nor one that also
  // moves (grbl syncs before the line's own motion). O(1).
  void prove_sync(size_t line) {
    const auto& L = session_.job().lines;
    const bool lowers = L[line].pen_down && !(line > 0 && L[line - 1].pen_down);
    if (lowers || L[line].motion || line + 1 >= L.size()) return;
    const ProvenPoint p{static_cast<long>(line) + 1, L[line].x, L[line].y, s_.last_status_.z};
    if (p.line <= proof_.line) return;
    proof_ = p;
    session_.proven(p);
  }

  // After grbl lost its buffers: the journal and the result go back to what was
  // executed, from where the machine stopped when grbl can say, else from the planner
  // fill of the last status report.
  long rollback_to_executed(bool ask_position = false) {
    long done = executed_estimate();
    if (ask_position) {
      try {
        const Status st = s_.query_status(Millis(2000));
        const long at = executed_at_position(st.x, st.y);
        if (at != -2) done = at;  // where the machine stands is what ran
      } catch (const TransportError&) {
      }
    }
    session_.rollback_to(done);
    return done;
  }

  StreamResult abort() {
    stop_machine();
    const long done = rollback_to_executed(true);
    session_.device_cleared();
    StreamResult res = session_.finish();
    s_.note("job aborted; the machine was reset. Resume continues after line " + std::to_string(done + 1));
    return res;
  }

  // A status report taken once the hold has stopped the machine (Hold:0, or Idle when
  // there was nothing to hold), with every answer before it counted, so the snapshot is
  // what grbl holds now.
  void status_after_hold(Millis timeout) {
    const auto end = clock::now() + timeout;
    bool asked = false;
    std::string line;
    while (clock::now() < end) {
      if (!s_.reader_.read_line(line, Millis(20))) {
        if (!asked) s_.t_.write("?");  // what was on its way has arrived: ask
        asked = true;
        continue;
      }
      const Reply r = classify_reply(line);
      if (r.answers_a_line() && !window_.empty()) {
        const LineWindow::Line l = window_.answered();
        if (r.kind == ReplyKind::Ok) acknowledge(l);
      } else if (Status st; r.kind == ReplyKind::Status && parse_status(line, st)) {
        take_snapshot(st);
        if (asked && st.state != "Run" && st.state != "Hold:1" && st.state != "Jog") return;
        asked = false;  // still stopping: ask again once the line is quiet
      }
    }
  }

  struct Snapshot {
    size_t motion_acked = 0;  // moves acknowledged when the report came
    long last_acked = -1;     // the last line acknowledged then
    int blocks_free = -1;     // what the report said (-1: it did not say)
  };

  Streamer& s_;
  const Options& o_;
  StreamSession session_;
  StreamControls* controls_;
  LineWindow window_;
  size_t next_ = 0;                 // next item to send
  std::deque<long> acked_motion_;   // acknowledged motion lines not yet known executed
  std::deque<long> before_sync_;    // the moves the last sync line's answer called executed
  size_t motion_acked_ = 0;         // moves acknowledged in all (acked_motion_ keeps the last)
  long last_sync_acked_ = -1;       // the last sync line answered: everything up to it ran
  long last_preamble_move_ = -1;    // the preamble's last travel, until a sync line proves it run
  ProvenPoint proof_;               // the last proof journalled (a status report, a sync line)
  Snapshot snapshot_{0, session_.result().last_acked, -1};
  clock::time_point last_rx_ = clock::now(), next_poll_ = last_rx_, idle_first_ = last_rx_, last_progress_ = last_rx_;
  int idle_polls_ = 0;                // idle, empty reports running that cover an unanswered line
  std::deque<size_t> asked_after_;    // for each '?' unanswered: the items sent before it
  bool idle_after_everything_ = false;  // idle and empty, asked once every line was sent
  bool paused_ = false, finishing_ = false;
  long m0_released_ = -2;           // the M0 item whose pause was released
};

StreamResult Streamer::stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                              const ProgressFn& progress, StreamControls* controls) {
  return JobRun(*this, job, start, preamble, journal, progress, controls).run();
}

}  // namespace stipplot::io::grbl
