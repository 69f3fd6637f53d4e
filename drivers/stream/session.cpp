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

void StreamSession::report(size_t items_sent, const std::string& state, double x, double y) {
  if (!progress_fn_) return;
  StreamProgress& pg = progress_;
  pg.elapsed_s = elapsed_s();
  pg.lines_sent = start_ + (items_sent > preamble_.size() ? items_sent - preamble_.size() : 0);
  // ETA: the job's time model, corrected by how fast the device has really gone (the
  // operator's pauses are not its time).
  const double device_s = pg.elapsed_s - res_.paused_s;
  const double ratio = est_done_ > 0.5 && device_s > 1 ? device_s / est_done_ : 1.0;
  pg.eta_s = std::max(0.0, job_.est_total_s - est_done_) * ratio;
  pg.state = state;
  pg.x = x;
  pg.y = y;
  progress_fn_(pg);
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
