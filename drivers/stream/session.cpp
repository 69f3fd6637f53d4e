#include "drivers/stream/session.hpp"

#include <algorithm>

namespace stipplot::io {

StreamSession::StreamSession(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                             const ProgressFn& progress)
    : job_(job), start_(start), preamble_(preamble), journal_(journal), progress_fn_(progress),
      t0_(std::chrono::steady_clock::now()) {
  res_.last_acked = journal ? journal->last_acked() : static_cast<long>(start) - 1;
  progress_.lines_total = job.lines.size();
  progress_.lines_acked = start;
  for (size_t i = start; i < job.lines.size(); ++i) est_session_ += job.lines[i].est_s;
}

const std::string& StreamSession::text(size_t item) const {
  return item < preamble_.size() ? preamble_[item] : job_.lines[start_ + item - preamble_.size()].text;
}

long StreamSession::job_line(size_t item) const {
  return item < preamble_.size() ? -1 : static_cast<long>(start_ + item - preamble_.size());
}

void StreamSession::acknowledge(long line) {
  res_.last_acked = line;
  ++res_.lines_acked;
  progress_.lines_acked = static_cast<size_t>(line) + 1;
  est_done_ += job_.lines[static_cast<size_t>(line)].est_s;
  if (journal_) journal_->ack(static_cast<size_t>(line));
}

void StreamSession::proven(const ProvenPoint& p) {
  if (journal_) journal_->proven(p);
}

void StreamSession::report(size_t items_sent, const std::string& state, double x, double y, long executed) {
  if (!progress_fn_) return;
  StreamProgress& pg = progress_;
  pg.elapsed_s = elapsed_s();
  pg.lines_sent = start_ + (items_sent > preamble_.size() ? items_sent - preamble_.size() : 0);
  if (first_send_s_ < 0 && pg.lines_sent > start_) first_send_s_ = pg.elapsed_s - res_.paused_s;
  pg.eta_s = eta_s(executed == kAckedAreExecuted ? res_.last_acked : executed);
  pg.state = state;
  pg.x = x;
  pg.y = y;
  progress_fn_(pg);
}

// The job's time model for what is left, at the rate the device really goes (device
// seconds per model second since the first line went out, over the model time of what
// it has executed; the operator's pauses are not its time). O(1).
double StreamSession::eta_s(long executed) {
  const double device_s = elapsed_s() - res_.paused_s;
  const double base = start_ > 0 ? job_.lines[start_ - 1].done_s : 0;
  double done = 0;
  if (executed >= static_cast<long>(start_) && executed < static_cast<long>(job_.lines.size()))
    done = std::clamp(job_.lines[static_cast<size_t>(executed)].done_s - base, 0.0, est_session_);
  // Half a second of work is enough to measure against; before that, the model as it is.
  if (first_send_s_ >= 0 && done > 0.5) rate_ = (device_s - first_send_s_) / done;
  return std::max(0.0, est_session_ - done) * rate_;
}

void StreamSession::rollback_to(long line) {
  if (journal_) journal_->rollback_to(line);
  res_.last_acked = line;
}

void StreamSession::device_cleared() {
  if (journal_) journal_->device_cleared();
}

void StreamSession::sync_journal() {
  if (journal_) journal_->sync();
}

void StreamSession::complete() {
  if (journal_) journal_->done();
  res_.completed = true;
}

void StreamSession::pause_begins() {
  pause_t0_ = std::chrono::steady_clock::now();
  ++res_.pauses;
}

void StreamSession::pause_ends() {
  res_.paused_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - pause_t0_).count();
}

double StreamSession::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

StreamResult StreamSession::finish() {
  res_.seconds = elapsed_s();
  return res_;
}

}  // namespace stipplot::io
