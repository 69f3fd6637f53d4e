#pragma once
// The bookkeeping of one streaming session, the same whatever the protocol: what is
// sent (the resume preamble, then job lines from `start`), which job lines the device
// has done (counted and journalled), progress with an ETA, and the result.
#include <chrono>
#include <string>
#include <vector>

#include "drivers/job/job.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/stream.hpp"

namespace stipplot::io {

class StreamSession {
 public:
  StreamSession(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                const ProgressFn& progress);

  // Items are what is sent, in order: the preamble, then the job's lines from start.
  size_t items() const { return preamble_.size() + (job_.lines.size() > start_ ? job_.lines.size() - start_ : 0); }
  const std::string& text(size_t item) const;
  long job_line(size_t item) const;  // -1 for a preamble line
  const Job& job() const { return job_; }
  size_t start() const { return start_; }  // the first job line sent after the preamble

  // The device has done job line `line`.
  void acknowledge(long line);
  // The device proved it drew up to this point (journalled).
  void proven(const ProvenPoint& p);
  // Calls the progress callback: `items_sent` items are out, the device last said this,
  // and has executed the job's lines up to `executed` (by default: all acknowledged ones,
  // as for a plotter whose acknowledgement is its buffer emptying).
  static constexpr long kAckedAreExecuted = -2;
  void report(size_t items_sent, const std::string& state = {}, double x = 0, double y = 0,
              long executed = kAckedAreExecuted);
  // Back to `line` as the last one done (the device discarded lines it had acknowledged).
  void rollback_to(long line);
  // The device's buffers were dropped (reset, ESC.K): what is acknowledged is all it ran.
  void device_cleared();
  // Makes the journal durable before an error leaves the session.
  void sync_journal();
  // The job ran to the end: the journal says so.
  void complete();
  void all_lines_done() { progress_.lines_acked = job_.lines.size(); }

  // The operator's time at a pause: not the device's, so the ETA leaves it out.
  void pause_begins();
  void pause_ends();

  double elapsed_s() const;
  // Seconds left after the lines up to `executed`, by the time model at the device's
  // measured rate.
  double eta_s(long executed);
  StreamResult& result() { return res_; }
  const StreamResult& result() const { return res_; }
  // The result as it stands, timed.
  StreamResult finish();

 private:
  const Job& job_;
  size_t start_;
  const std::vector<std::string>& preamble_;
  Journal* journal_;
  const ProgressFn& progress_fn_;
  std::chrono::steady_clock::time_point t0_;
  StreamResult res_;
  StreamProgress progress_;
  double est_done_ = 0;  // the time model's seconds for the lines done
  double est_session_ = 0;  // ... for the lines this session sends (from start_)
  double first_send_s_ = -1;  // device seconds when the first job line went out
  double rate_ = 1;           // device seconds per model second, as measured
  std::chrono::steady_clock::time_point pause_t0_{};
};

}  // namespace stipplot::io
