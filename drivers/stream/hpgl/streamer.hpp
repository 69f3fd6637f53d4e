#pragma once
// Streams an HPGL job to a pen plotter with the handshake its profile names:
//  - buffer_query (escb): ask for free buffer space with ESC.B and send at most that
//    much (the approach chiplotle takes; it survives USB adapters without RTS/CTS, and
//    tells how far the plotter has got, which the journal records);
//  - xonxoff: in-band XON/XOFF from the plotter (writes should be paced at the baud
//    rate, as a UART does, so XOFF arrives in time);
//  - hardware (RTS/CTS in the serial driver) or none: we just write.
// ESC.O status and OE error queries detect a plotter that is not ready or has an error.
#include <algorithm>
#include <functional>
#include <string>

#include "drivers/device/profile.hpp"
#include "drivers/job/job.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/stream/stream.hpp"
#include "drivers/transport/transport.hpp"

namespace stipplot::io::hpgl {

std::string error_meaning(int code);  // HP-GL OE error numbers

struct Options {
  HpglHandshake handshake = HpglHandshake::buffer_query;
  int buffer_bytes = 0;         // 0: ask the plotter (ESC.L)
  int reserve = 16;             // bytes left free in the plotter's buffer
  bool newline = false;         // end every instruction with '\n' (some cutters need it)
  bool status_queries = true;   // ESC.O / OE where the device has them
  Millis reply_timeout{2000};
  int retries = 3;              // a lost or garbled reply is asked again this often
  Millis poll_interval{20};
  Millis not_ready_timeout{60000};  // plotter not ready (lever up, view mode) this long: give up
  // The plotter's buffer holds data and frees nothing for this long beyond what the
  // instruction under way takes by the timed plan: the plot stops, the journal kept. On
  // connecting, a buffer left with undrawn data that long (a dead host's unfinished
  // instruction) is cleared with ESC.K.
  Millis watchdog{20000};
  // Paced handshakes: how often ESC.B asks what the plotter has taken, the journal's
  // proof of what was drawn (grbl polls its status at 5 Hz).
  Millis proof_interval{200};
  // A pause of the job (the writer's reload comment, not sent): asked once the plotter
  // has drawn everything before it. Unset: continue at once.
  PauseFn on_pause;
  std::function<void(const std::string&)> log;
};

// The profile's handshake and newline.
Options options_for(const DeviceProfile& p);

class Streamer {
 public:
  Streamer(Transport& t, Options o);
  // Checks the plotter answers (escb / status queries) and learns its buffer size.
  void connect();
  // Sends ESC.<c> and reads the number it answers; retries; throws TransportError.
  int query(char c);
  StreamResult stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                      const ProgressFn& progress = {}, StreamControls* controls = nullptr);
  int buffer_bytes() const { return buffer_; }
  // Where the pen is and whether it is down (OA, answered once the buffer has run; the
  // device's own units). Unknown without status queries or an answer.
  DevicePen device_pen();
  // How far a plotter left by a dead host may have drawn past the journal: its buffer;
  // and, paced (the journal has what was written), how far behind it a plotter that lost
  // its buffer may be.
  ResumeWindow resume_window() const {
    const size_t buffer = static_cast<size_t>(std::max(buffer_, 0));
    return {buffer, 0, o_.newline ? 1u : 0u, o_.handshake == HpglHandshake::buffer_query ? 0 : buffer};
  }

 private:
  class JobRun;  // one stream() call
  bool read_reply(std::string& out, Millis timeout);
  void pump(Millis timeout);  // reads incoming bytes: XON/XOFF and reply text
  void note(const std::string& s) {
    if (o_.log) o_.log(s);
  }
  Transport& t_;
  Options o_;
  int buffer_ = 0;
  bool xoff_ = false;
  std::string incoming_;
  std::string heard_;  // the first bytes the device sent: what it is, when it is not HPGL
  std::chrono::steady_clock::time_point xoff_since_{};
};

}  // namespace stipplot::io::hpgl
