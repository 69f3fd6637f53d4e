#include "drivers/stream/hpgl/streamer.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <climits>
#include <cstdint>
#include <thread>

#include "drivers/stream/device_error.hpp"
#include "drivers/stream/session.hpp"

namespace stipplot::io::hpgl {

using clock = std::chrono::steady_clock;

namespace {
// "20", "0.6": the watchdog's time as a person reads it.
std::string seconds_text(Millis m) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", static_cast<double>(m.count()) / 1000);
  return b;
}
}  // namespace

Options options_for(const DeviceProfile& p) {
  Options o;
  o.handshake = p.hpgl.handshake;
  o.newline = p.serial.newline;
  o.watchdog = Millis(static_cast<long>(p.serial.watchdog_s * 1000));
  return o;
}

std::string error_meaning(int code) {
  switch (code) {
    case 0: return "no error";
    case 1: return "instruction not recognized";
    case 2: return "wrong number of parameters";
    case 3: return "out-of-range parameters";
    case 5: return "unknown character set";
    case 6: return "position overflow";
    case 7: return "buffer overflow (data was lost)";
    default: return "HP-GL error " + std::to_string(code);
  }
}

Streamer::Streamer(Transport& t, Options o) : t_(t), o_(std::move(o)) {
  if (o_.reserve < 0 || o_.buffer_bytes < 0) throw UserError("HPGL buffer size and reserve must be >= 0");
  if (o_.retries < 0) throw UserError("HPGL retries must be >= 0");
}

void Streamer::pump(Millis timeout) {
  char buf[512];
  size_t n = t_.read(buf, sizeof buf, timeout);
  for (size_t i = 0; i < n; ++i) {
    if (buf[i] == 0x13) {
      if (!xoff_) xoff_since_ = clock::now();
      xoff_ = true;
    } else if (buf[i] == 0x11) {
      xoff_ = false;
    } else {
      incoming_.push_back(buf[i]);
      if (heard_.size() < 256) heard_.push_back(buf[i]);
    }
  }
}

bool Streamer::read_reply(std::string& out, Millis timeout) {
  auto end = clock::now() + timeout;
  for (;;) {
    auto eol = incoming_.find_first_of("\r\n");
    while (eol == 0) {
      incoming_.erase(0, 1);
      eol = incoming_.find_first_of("\r\n");
    }
    if (eol != std::string::npos) {
      out = incoming_.substr(0, eol);
      incoming_.erase(0, eol + 1);
      return true;
    }
    auto left = std::chrono::duration_cast<Millis>(end - clock::now());
    if (left.count() <= 0) return false;
    pump(std::min(left, Millis(50)));
  }
}

int Streamer::query(char c) {
  for (int attempt = 0; attempt <= o_.retries; ++attempt) {
    incoming_.clear();
    t_.write(std::string("\x1b.") + c);
    std::string r;
    if (!read_reply(r, o_.reply_timeout)) {
      note(std::string("no answer to ESC.") + c + ", asking again");
      continue;
    }
    char* end = nullptr;
    long v = std::strtol(r.c_str(), &end, 10);
    // One number: a reply with a comma is a late answer to an output instruction (OA).
    if (end != r.c_str() && *end == '\0' && v >= 0) return static_cast<int>(v);
    note(std::string("garbled answer to ESC.") + c + ": '" + r + "', asking again");
    std::this_thread::sleep_for(Millis(20));
    pump(Millis(20));
  }
  // A G-code controller on the port talks, but not HPGL: say so, not only "no answer".
  std::string hint;
  if (heard_.find("Grbl") != std::string::npos || heard_.find("ok") != std::string::npos ||
      heard_.find("error:") != std::string::npos)
    hint = "; what it did say sounds like grbl (G-code), not an HPGL plotter: choose a grbl profile for this port";
  throw TransportError(TransportError::Kind::Timeout, std::string("the plotter on ") + t_.describe() +
                                                          " does not answer ESC." + c + " (tried " +
                                                          std::to_string(o_.retries + 1) + " times)" + hint);
}

void Streamer::connect() {
  // Answers to a dead host's last queries may still wait on the port: not ours.
  for (int i = 0; i < 20; ++i) {
    const size_t before = incoming_.size();
    pump(Millis(30));
    if (incoming_.size() == before) break;
  }
  incoming_.clear();
  if (o_.handshake != HpglHandshake::buffer_query && !o_.status_queries) {
    buffer_ = o_.buffer_bytes;
    return;
  }
  buffer_ = o_.buffer_bytes > 0 ? o_.buffer_bytes : query('L');
  if (buffer_ <= o_.reserve) throw UserError("the plotter reports a buffer of " + std::to_string(buffer_) + " bytes: too small");
  // Wait for earlier work to finish (after a reconnect), so free space means empty; a
  // buffer that stops draining holds what a dead host left unfinished: clear it (the
  // journal has only what was drawn).
  int last_free = query('B');
  auto since = clock::now();
  while (last_free < buffer_) {
    std::this_thread::sleep_for(Millis(50));
    const int free = query('B');
    if (free != last_free) {
      last_free = free;
      since = clock::now();
    } else if (clock::now() - since > o_.watchdog) {
      note("the plotter's buffer held " + std::to_string(buffer_ - free) +
           " bytes it did not draw (an unfinished instruction from an earlier session?): cleared with ESC.K");
      t_.write("\x1b.K");
      std::this_thread::sleep_for(Millis(100));
      last_free = query('B');
      if (last_free < buffer_) throw UserError("the plotter's buffer does not empty, even after ESC.K");
    }
  }
}

DevicePen Streamer::device_pen() {
  DevicePen p;
  // OA is answered once the plotter reaches it: not while it is not ready (its late
  // answer would be taken for another's), nor without status queries.
  if (!o_.status_queries || (query('O') & 16)) return p;
  incoming_.clear();
  t_.write(o_.newline ? "OA;\n" : "OA;");
  std::string r;
  double x = 0, y = 0;
  int down = 0;
  if (read_reply(r, o_.reply_timeout) && std::sscanf(r.c_str(), "%lf,%lf,%d", &x, &y, &down) == 3) {
    p.known = true;
    p.down = down != 0;
    p.x = x;
    p.y = y;
  }
  return p;
}

// One stream() call. HPGL has no per-line answer: a line counts as done once the
// plotter's buffer has taken it past (ESC.B) or, without buffer queries, once written.
class Streamer::JobRun {
 public:
  JobRun(Streamer& s, const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
         const ProgressFn& progress, StreamControls* controls)
      : s_(s), o_(s.o_), session_(job, start, preamble, journal, progress), controls_(controls) {
    // The whole byte stream, and where each item ends in it. Host-only lines (comments,
    // pauses) take no bytes: HP-GL/1 plotters answer CO with error 1.
    for (size_t i = 0; i < session_.items(); ++i) {
      const JobLine* jl = line_of(i);
      if (!(jl && jl->host_only)) {
        data_ += session_.text(i);
        if (o_.newline) data_ += '\n';
      }
      ends_.push_back(data_.size());
      if (jl && jl->pause) pauses_.push_back(i);
    }
    refuse_long_instructions();
  }

  StreamResult run() {
    try {
      const bool aborted = o_.handshake == HpglHandshake::buffer_query ? !stream_polled() : !stream_paced();
      if (aborted) {
        session_.sync_journal();
        return session_.finish();
      }
      check_status(true);
    } catch (const TransportError&) {
      session_.sync_journal();
      throw;
    } catch (const DeviceError&) {
      session_.sync_journal();
      throw;
    }
    session_.complete();
    return session_.finish();
  }

 private:
  using clock = std::chrono::steady_clock;

  bool abort_requested() { return controls_ && controls_->abort.exchange(false); }

  // Before anything is sent: an instruction longer than the room the buffer ever has
  // would sit in it unfinished, and the plotter would wait for its end for ever.
  void refuse_long_instructions() const {
    if (s_.buffer_ <= 0) return;  // no buffer size known (no queries): the handshake paces it
    const size_t room = static_cast<size_t>(s_.buffer_ - (o_.handshake == HpglHandshake::buffer_query ? o_.reserve : 0));
    for (size_t i = 0; i < ends_.size(); ++i) {
      const size_t bytes = ends_[i] - (i ? ends_[i - 1] : 0);
      if (bytes <= room) continue;
      const long line = session_.job_line(i);
      throw UserError((line >= 0 ? "instruction " + std::to_string(line + 1) : std::string("a resume instruction")) +
                      " is " + std::to_string(bytes) + " bytes, more than the " + std::to_string(room) +
                      " the plotter's buffer can take at once: split it (the writer's max_points_per_command); nothing was sent");
    }
  }

  // Data in the plotter and nothing freed for the watchdog's time beyond the timed
  // plan's time of the instruction it is drawing: it is stuck.
  void check_watchdog(int free) {
    const auto now = clock::now();
    if (free != last_free_ || (controls_ && controls_->pause.load())) {
      last_free_ = free;
      last_change_ = now;
      return;
    }
    if (free >= s_.buffer_) {
      last_change_ = now;
      return;
    }
    const JobLine* jl = acked_upto_ < ends_.size() ? line_of(acked_upto_) : nullptr;
    const double own_s = jl ? jl->est_s : 0;
    const auto allowed = o_.watchdog + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(own_s));
    if (now - last_change_ <= allowed) return;
    session_.sync_journal();
    throw TransportError(TransportError::Kind::Timeout,
                         "the plotter on " + s_.t_.describe() + " took nothing for " +
                             seconds_text(o_.watchdog) + " s with " +
                             std::to_string(s_.buffer_ - free) + " bytes in its buffer: the plot stopped");
  }

  const JobLine* line_of(size_t item) const {
    const long line = session_.job_line(item);
    return line < 0 ? nullptr : &session_.job().lines[static_cast<size_t>(line)];
  }

  // The next pause not yet passed (SIZE_MAX: none), and the bytes before it.
  size_t pause_item() const { return next_pause_ < pauses_.size() ? pauses_[next_pause_] : SIZE_MAX; }
  size_t send_limit() const { return pause_item() == SIZE_MAX ? data_.size() : ends_[pause_item()]; }
  bool at_pause() const { return pause_item() != SIZE_MAX && sent_ == send_limit(); }

  // Everything before the pause is drawn: ask; the pause counts as done once the
  // operator says go (or with stop_after), so a resume after `stop` asks again.
  void pause_here() {
    const size_t item = pause_item();
    const long line = session_.job_line(item);
    const JobLine& jl = session_.job().lines[static_cast<size_t>(line)];
    acknowledge_through(sent_);
    PauseAnswer answer = PauseAnswer::go;
    if (o_.on_pause) {
      session_.pause_begins();
      answer = o_.on_pause({line, jl.note});
      session_.pause_ends();
    }
    if (answer == PauseAnswer::stop) {
      session_.sync_journal();
      throw UserError("stopped at the pause on line " + std::to_string(line + 1) + " (" + jl.note + ")");
    }
    ++next_pause_;
    acknowledge_through(sent_);
    if (answer == PauseAnswer::stop_after) {
      session_.sync_journal();
      throw UserError("stopped at the pause on line " + std::to_string(line + 1) + " (" + jl.note +
                      "), counted as done: do it before resuming");
    }
  }

  // Items whose bytes all lie within the first `executed` bytes are done, up to the
  // next pause.
  void acknowledge_through(size_t executed) {
    while (acked_upto_ < ends_.size() && acked_upto_ < pause_item() && ends_[acked_upto_] <= executed) {
      const long line = session_.job_line(acked_upto_);
      if (line >= 0) session_.acknowledge(line);
      ++acked_upto_;
    }
    const size_t items_sent = static_cast<size_t>(std::upper_bound(ends_.begin(), ends_.end(), sent_) - ends_.begin());
    session_.report(items_sent);
  }

  // ESC.B: send at most the free space (less a reserve); what the buffer no longer holds
  // has been drawn. False if aborted.
  bool stream_polled() {
    for (;;) {
      if (abort_requested()) {
        // Abort graphics: the plotter drops its buffer but finishes the instruction under
        // way; the resume sees from where the pen is whether it did.
        s_.t_.write("\x1b.K");
        return false;
      }
      // The free space, then the status: a plotter flags an error as it takes the
      // instruction, so a clean status proves every instruction done before it ran.
      const int free = s_.query('B');
      const int status = o_.status_queries ? s_.query('O') : 0;
      if (status & 16) {
        wait_ready();
        continue;
      }
      check_watchdog(free);
      const size_t in_buffer = static_cast<size_t>(std::max(0, s_.buffer_ - free));
      if (status & 32) stop_on_error(sent_ > in_buffer ? sent_ - in_buffer : 0);
      acknowledge_through(sent_ > in_buffer ? sent_ - in_buffer : 0);
      clean_upto_ = acked_upto_;
      if (at_pause() && free >= s_.buffer_) {
        if (o_.status_queries) wait_drawn();
        pause_here();
        continue;
      }
      if (sent_ == data_.size() && free >= s_.buffer_) return true;
      const bool paused = controls_ && controls_->pause.load();
      const size_t room = free > o_.reserve ? static_cast<size_t>(free - o_.reserve) : 0;
      const size_t chunk = paused ? 0 : std::min(room, send_limit() - sent_);
      if (chunk > 0) {
        s_.t_.write(std::string_view(data_).substr(sent_, chunk));
        sent_ += chunk;
      } else {
        std::this_thread::sleep_for(o_.poll_interval);
      }
    }
  }

  // Paced, a line counts as done once written; what the plotter has taken from its
  // buffer (ESC.B is answered after every byte before it arrived, and the plotter frees an
  // instruction's bytes as it finishes it) proves the lines before drawn. Journalled as
  // the start of the first line not wholly taken, so that a resume after a power loss
  // (the buffer gone) starts there. At most every proof_interval. O(log items).
  void prove_taken() {
    if (!o_.status_queries || s_.buffer_ <= 0 || clock::now() < next_proof_) return;
    next_proof_ = clock::now() + o_.proof_interval;
    const size_t in_buffer = static_cast<size_t>(std::max(0, s_.buffer_ - s_.query('B')));
    const size_t taken = sent_ > in_buffer ? sent_ - in_buffer : 0;
    const size_t item = static_cast<size_t>(std::upper_bound(ends_.begin(), ends_.end(), taken) - ends_.begin());
    const long line = item < ends_.size() ? session_.job_line(item) : -1;
    if (line <= proof_.line) return;  // in the preamble yet, all taken, or nothing new
    const auto& L = session_.job().lines;
    proof_ = {line, line ? L[static_cast<size_t>(line) - 1].x : 0, line ? L[static_cast<size_t>(line) - 1].y : 0, 0};
    session_.proven(proof_);
  }

  // XON/XOFF or hardware handshake: write in small pieces, watching for XOFF between
  // them; then wait until the plotter has drawn it all. False if aborted.
  bool stream_paced() {
    while (sent_ < data_.size() || at_pause()) {
      if (abort_requested()) return false;
      prove_taken();
      if (at_pause()) {
        if (o_.status_queries) wait_drawn();
        pause_here();
        continue;
      }
      s_.pump(Millis(0));
      if (o_.handshake == HpglHandshake::xonxoff && s_.xoff_) {
        if (clock::now() - s_.xoff_since_ > o_.not_ready_timeout)
          throw TransportError(TransportError::Kind::Timeout,
                               "the plotter held XOFF for " + std::to_string(o_.not_ready_timeout.count() / 1000) + " s");
        s_.pump(Millis(20));
        continue;
      }
      const size_t chunk = std::min<size_t>(64, send_limit() - sent_);
      s_.t_.write(std::string_view(data_).substr(sent_, chunk), Millis(60000));
      sent_ += chunk;
      acknowledge_through(sent_);  // without per-line acknowledgement, a line counts as done once written
    }
    if (o_.status_queries) wait_drawn();
    return true;
  }

  // Until the plotter has drawn everything, or reports an error (then OE in
  // check_status names it), or stops consuming data (an incomplete instruction left
  // after lost bytes would hold its buffer forever).
  void wait_drawn() {
    int last_free = -1;
    auto since = clock::now();
    for (;;) {
      if (s_.query('O') & (8 | 32)) return;
      const int free = s_.query('B');
      if (free != last_free) {
        last_free = free;
        since = clock::now();
      } else if (clock::now() - since > o_.not_ready_timeout) {
        throw DeviceError("the plotter stopped taking data with " + std::to_string(s_.buffer_ - free) +
                              " bytes in its buffer (bytes lost to a late XOFF?)",
                          session_.result().last_acked, 0, false);
      }
      std::this_thread::sleep_for(Millis(50));
    }
  }

  // The plotter flagged an error in an instruction begun since the last clean status:
  // it skips that instruction and draws on, so drop what it holds (ESC.K keeps only the
  // instruction under way), let that finish, and go back to the last item done before
  // the clean status. The suspect instructions after it (one or two at a sane polling
  // rate) are sent again on resume: one of them was never drawn.
  [[noreturn]] void stop_on_error(size_t executed) {
    acknowledge_through(executed);
    s_.t_.write("\x1b.K");
    wait_empty();
    long back = -1;  // the last job line of the items before the first suspect
    for (size_t i = clean_upto_; i-- > 0;)
      if ((back = session_.job_line(i)) >= 0) break;
    if (back < 0) back = static_cast<long>(session_.start()) - 1;
    session_.rollback_to(std::min(back, session_.result().last_acked));
    session_.device_cleared();
    s_.t_.write(o_.newline ? "OE;\n" : "OE;");
    std::string r;
    const int code = s_.read_reply(r, Millis(5000)) ? std::atoi(r.c_str()) : -1;
    const long from = session_.result().last_acked + 1;
    const std::string what = code >= 0 ? std::to_string(code) + " (" + error_meaning(code) + ")" : "(OE unanswered)";
    throw DeviceError("the plotter reports HP-GL error " + what + " in an instruction from line " +
                          std::to_string(from + 1) + " on; the job stopped, its buffer cleared: --resume sends them again",
                      from, code, false);
  }

  // Waits until the plotter's buffer is empty, as long as it keeps taking bytes.
  void wait_empty() {
    int last = -1;
    auto since = clock::now();
    for (;;) {
      const int free = s_.query('B');
      if (free >= s_.buffer_) return;
      if (free != last) last = free, since = clock::now();
      if (clock::now() - since > o_.watchdog) return;
      std::this_thread::sleep_for(o_.poll_interval);
    }
  }

  // Not ready (paper lever up, view mode): the plotter holds its buffer. Wait for the
  // operator up to not_ready_timeout; then drop the buffer (ESC.K), so that what the
  // journal says was drawn is all that will be, and stop.
  void wait_ready() {
    const auto since = clock::now();
    while (s_.query('O') & 16) {
      if (clock::now() - since > o_.not_ready_timeout) {
        const int free = s_.query('B');
        const size_t in_buffer = static_cast<size_t>(std::max(0, s_.buffer_ - free));
        acknowledge_through(sent_ > in_buffer ? sent_ - in_buffer : 0);
        s_.t_.write("\x1b.K");
        session_.device_cleared();
        throw DeviceError("the plotter is not ready (paper lever raised or view mode?) and stayed so for " +
                              std::to_string(o_.not_ready_timeout.count() / 1000) +
                              " s; its buffer was cleared: resume when it is ready",
                          session_.result().last_acked, 16, true);
      }
      std::this_thread::sleep_for(Millis(100));
    }
    last_change_ = clock::now();  // the operator's time is not a stuck plotter
  }

  // ESC.O: waits out "not ready" (paper lever, view mode) up to not_ready_timeout; on an
  // error bit, or at the end, asks OE and stops on an error.
  void check_status(bool final) {
    if (!o_.status_queries) return;
    const long last = session_.result().last_acked;
    int st = s_.query('O');
    if (st & 16) {
      auto since = clock::now();
      while (st & 16) {
        if (clock::now() - since > o_.not_ready_timeout)
          throw DeviceError("the plotter is not ready (paper lever raised or view mode?) and stayed so for " +
                                std::to_string(o_.not_ready_timeout.count() / 1000) + " s; resume when it is ready",
                            last, 16, true);
        std::this_thread::sleep_for(Millis(100));
        st = s_.query('O');
      }
    }
    if (!(st & 32) && !final) return;
    // OE goes through the plotter's buffer: if that is stuck (lost bytes left an
    // unfinished instruction), OE would never be answered.
    if ((st & 32) && !(st & 8) && s_.query('B') < s_.buffer_ && final)
      throw DeviceError("the plotter reports an error and its buffer holds an unfinished instruction "
                        "(bytes lost to a late XOFF or no handshake?); the job is incomplete",
                        last, 7, false);
    s_.t_.write(o_.newline ? "OE;\n" : "OE;");
    std::string r;
    if (!s_.read_reply(r, Millis(30000)))
      throw TransportError(TransportError::Kind::Timeout, "the plotter on " + s_.t_.describe() + " does not answer OE");
    const int code = std::atoi(r.c_str());
    if (code != 0)
      throw DeviceError("the plotter reports HP-GL error " + std::to_string(code) + " (" + error_meaning(code) +
                            ") after line " + std::to_string(last + 1),
                        last, code, false);
  }

  Streamer& s_;
  const Options& o_;
  StreamSession session_;
  StreamControls* controls_;
  std::string data_;
  std::vector<size_t> ends_;  // end offset of each item in data_
  std::vector<size_t> pauses_;  // items that are pauses, in order
  size_t sent_ = 0, acked_upto_ = 0, next_pause_ = 0;
  size_t clean_upto_ = 0;  // items done before the last status without an error flag
  int last_free_ = -1;
  clock::time_point last_change_ = clock::now();
  clock::time_point next_proof_ = clock::now();
  ProvenPoint proof_;  // paced: the last proof journalled
};

StreamResult Streamer::stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                              const ProgressFn& progress, StreamControls* controls) {
  return JobRun(*this, job, start, preamble, journal, progress, controls).run();
}

}  // namespace stipplot::io::hpgl
