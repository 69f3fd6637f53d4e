#pragma once
// Streams a G-code job to grbl 1.1: waits for the banner, checks $$ settings against
// the device profile, then character counting (keep the bytes of unacknowledged lines
// within the 128-byte receive buffer, so the planner never starves) or send-and-wait;
// real-time '?' status polling, '!' hold / '~' resume, Ctrl-X reset; error:N and
// ALARM:N stop the job with grbl's explanation; a journal records acknowledged lines.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "drivers/device/profile.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/job.hpp"
#include "drivers/stream/device_error.hpp"
#include "drivers/stream/grbl/protocol.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/stream/stream.hpp"
#include "drivers/transport/transport.hpp"

namespace stipplot::io::grbl {

struct Options {
  Mode mode = Mode::CharacterCounting;
  int rx_buffer = 128;
  int planner_blocks = 15;
  double poll_hz = 10;                 // grbl's docs: at most 5-10 Hz; each report is a proof for the journal
  Millis banner_timeout{10000};
  Millis silence_timeout{30000};       // no byte at all for this long: the device is gone
  Millis probe_timeout{1500};          // connect: wait this long for a status report before a reset
  Millis lost_reply_after{1000};       // idle with empty buffers this long: unacknowledged lines are done
  // Lines wait unanswered and nothing changes (no answer, no motion, no buffer freed) for
  // this long beyond the oldest line's own time: the plot stops, the journal kept.
  Millis watchdog{20000};
  bool skip_errors = false;            // error:N: warn and go on instead of stopping
  bool unlock = false;                 // $X if grbl starts in ALARM
  bool lift_on_pause = true;           // spindle-stop override in a hold (servo pens)
  // A pause of the job (M0: a pen change), asked once grbl holds there with everything
  // before it done. Unset: continue at once.
  PauseFn on_pause;
  std::function<void(const std::string&)> log;  // warnings and notes
};

// The profile's RX buffer and planner size.
Options options_for(const DeviceProfile& p);

// What the profile expects of the machine, checked against $$.
struct Expectations {
  double speed_mm_s = 0;    // fastest feed the job uses
  double travel_x = 0, travel_y = 0;  // extent the job needs (largest X, Y)
  double min_x = 0, min_y = 0;        // smallest X, Y the job reaches
  double max_s = 0;         // largest S word in the job
  bool laser = false;
};
Expectations expectations_for(const Job& job);

class Streamer {
 public:
  Streamer(Transport& t, Options o);
  // Banner (or a live status), leaves ALARM only with opt.unlock, waits until Idle.
  void connect();
  std::map<int, double> read_settings();
  // Warnings for settings that differ from what the job needs; throws UserError when
  // the job cannot run: with soft limits ($20=1) grbl 1.1 accepts machine positions in
  // -$130..0 (-$131..0 for Y) only, as its limits.c checks them.
  std::vector<std::string> check_settings(const std::map<int, double>& s, const Expectations& e);
  Status query_status(Millis timeout);
  // The pen as grbl reports it: down if the spindle runs (servo/laser) or Z is below
  // the rule's threshold.
  DevicePen device_pen(const GcodePenRule& rule = {});
  void soft_reset();
  // connect() found grbl freshly started or had to reset it: its buffers were lost, and
  // the lines acknowledged last may not have run.
  bool restarted() const { return restarted_; }
  // How far grbl may be from the journal of a session that did not stop it: its receive
  // buffer ahead (a dead host's last lines ran, reset or not: a reset at connect loses
  // only what was still buffered), and, if its buffers were lost, its planner behind.
  // Blocks grbl has taken out of its planner but not yet run: the stepper's segment buffer
  // (stepper.c, SEGMENT_BUFFER_SIZE 6) may hold the tails of that many short blocks, each
  // discarded from the planner once fully prepared.
  static constexpr size_t kStepperBlocks = 6;
  // A board that came back fresh without the streamer seeing it restart (a power cycle
  // before the port opened: no banner) is told by its parser state (parser_reset): then
  // its planner and stepper count as lost. A board that ran on keeps the job's feed.
  ResumeWindow resume_window() {
    const size_t planner = static_cast<size_t>(o_.planner_blocks);
    const bool fresh = restarted_ || parser_reset();
    return {static_cast<size_t>(o_.rx_buffer), restarted_ ? planner : 0, 1, 0, fresh ? planner + kStepperBlocks : 0};
  }
  // grbl's parser state ($G) is as power-on or a reset leaves it: no feed rate (F0; the
  // job's moves set one). True too when grbl does not say (erring towards redrawing).
  bool parser_reset();
  // Streams job lines [start, end) after `preamble`. Throws DeviceError / TransportError;
  // the journal is synced first, so `plot --resume` can continue.
  StreamResult stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                      const ProgressFn& progress = {}, StreamControls* controls = nullptr);
  // $C check mode: every line parsed, nothing moves. Returns (line index, error code).
  std::vector<std::pair<long, int>> check_job(const Job& job);

 private:
  class JobRun;  // one stream() call: sending, answers, controls
  void note(const std::string& s);
  // Feed hold ('!') and wait for Hold:0, before a reset that must not catch a move (a
  // reset in motion raises ALARM:3). True if grbl moved or was moving meanwhile.
  bool hold_for_reset();
  // Reads lines until grbl's start-up banner, at most `timeout`; false if none came.
  bool wait_for_banner(Millis timeout, Millis slice = Millis(100));
  // Until what an earlier session left in grbl has run (connect).
  void wait_until_done(Status st);
  // Sends a '$' command and returns its answer (ok or error:N), waiting at most
  // `timeout` for each line; the lines grbl prints before the answer go to `lines`.
  std::string system_command(const std::string& cmd, Millis timeout, std::vector<std::string>* lines = nullptr);
  Transport& t_;
  Options o_;
  LineReader reader_;
  Status last_status_;
  bool restarted_ = false;
};

}  // namespace stipplot::io::grbl
