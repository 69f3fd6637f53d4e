#pragma once
// Streams an EiBotBoard job (drivers/writers/ebb_writer.hpp) to an EBB (AxiDraw, EggBot):
//  - connect(): `V` must name an EBB firmware 2.x or 3.x (anything else is refused before
//    a command that moves is sent); on 3.x the motion FIFO is lengthened with CU,4.
//  - stream(): each command is answered "OK" once the firmware has queued it (it waits
//    while its FIFO is full), so a line is journalled as done when its OK arrives: a board
//    that keeps power runs everything it queued. A few commands are kept in flight so the
//    FIFO never runs dry between an OK and the next command. An error reply ("!8 Err:
//    ...") stops the plot at that line. The end is known from QG: queue empty, motors idle.
//  - While streaming, a QS every proof_interval (in the in-flight window: it is answered
//    after the commands before it are queued) gives the carriage's position, on the path
//    of an SM already acknowledged: the first such line since the board surely ran the
//    ones before (ebb/reset.hpp) is journalled as a proof (StreamSession::proven). One
//    more once the board stands (the job's end, a pause, a hold): the point it stopped at.
//  - resume(): after a dropped link the board still holds its position (QS) and pen (QP):
//    the job goes on after the line the board's state matches, found among the lines the
//    journal had not heard back about. A board that was reset (power cycle, reboot) stands
//    at 0,0 matching none of them: its FIFO is lost, so the job goes on from the
//    journal's last proof or the first line it may not have run (plan_reset_resume), the
//    carriage taken to be at home, where the plot began.
// Both reply syntaxes are read: the legacy one (2.x, and 3.x by default: "OK\r\n", data
// lines ended by "\r\n" or "\n\r") and 3.x's standardized one after CU,10,1 (one line
// per command, starting with its name).
#include <array>
#include <functional>
#include <string>

#include "drivers/device/profile.hpp"
#include "drivers/job/job.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/stream/stream.hpp"
#include "drivers/transport/transport.hpp"

namespace stipplot::io::ebb {

struct Firmware {
  int major = 0, minor = 0, patch = 0;
  std::string text;  // the V reply
};
// The V reply "EBBv13_and_above EB Firmware Version 3.0.2"; throws UserError for a reply
// that is not an EBB's, or a version this driver does not know (before 2.5 or after 3.x).
Firmware parse_firmware(const std::string& reply);

struct Options {
  int fifo = 32;              // CU,4 on 3.x (2.x keeps its FIFO of 1)
  size_t in_flight = 6;       // commands sent and not yet answered
  Millis reply_timeout{3000}; // a query's answer
  // A command unanswered this long beyond the time of the commands queued before it: the
  // board is stuck or gone.
  Millis watchdog{20000};
  bool standardized = false;  // 3.x: CU,10,1 replies
  // connect() lengthens the FIFO (CU,4); off for a look at a board (V, QT) that leaves its
  // motion settings as they are.
  bool setup = true;
  // A QS this often while streaming proves where the carriage is (0: never); a few a
  // second cost the stream nothing (a query in the in-flight window).
  Millis proof_interval{300};
  // A QB this often while streaming asks whether the board's PRG button was pressed (0:
  // never). Pressed, the plot stops as axicli's does: what the board queued runs out, the
  // pen goes up, the journal is kept, and `plot --resume` goes on from the board's place.
  Millis button_interval{500};
  double steps_per_mm = 80;  // the job's positions (mm) from QS's motor steps
  PauseFn on_pause;
  std::function<void(const std::string&)> log;
};
Options options_for(const DeviceProfile& p);

class Streamer {
 public:
  Streamer(Transport& t, Options o);
  // Reads the firmware version and sets the board up (FIFO, reply syntax). Throws
  // UserError for a port that is not an EBB, an unknown firmware or an error reply.
  void connect();
  const Firmware& firmware() const { return fw_; }
  // Sends one command and reads its reply: the data line of a query (QS, QP, QG, V), ""
  // for a plain OK. An error reply throws DeviceError naming the command.
  std::string command(const std::string& cmd);
  std::array<int64_t, 2> position();  // QS: motor steps
  bool pen_up();                      // QP
  bool idle();                        // QG: FIFO empty, nothing executing
  std::string nickname();             // QT: the name ST gave the board ("" for none)
  void wait_idle(double max_seconds);
  // Where a job left on this board goes on: the first line after the one whose end the
  // board's position and pen match, from the journal's last acknowledged line up to the
  // commands that were in flight; the preamble restores the pen's servo settings (and
  // the pen, when the host lifted it). A board at 0,0 that matches none was reset: the
  // plan of plan_reset_resume (ebb/reset.hpp), its note saying the carriage is taken to
  // be at home. Throws UserError when a board elsewhere matches none (it was moved).
  // O(window), O(job size) after a reset.
  ResumePlan resume(const Job& job, const JournalState& journal, const DeviceProfile& profile);
  StreamResult stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                      const ProgressFn& progress = {}, StreamControls* controls = nullptr);

 private:
  class JobRun;
  bool read_line(std::string& out, Millis timeout);
  // Reads the reply to `cmd`: its data line (or ""), throwing DeviceError on an error.
  std::string reply(const std::string& cmd, Millis timeout, long job_line = -1);
  void note(const std::string& s) {
    if (o_.log) o_.log(s);
  }
  Transport& t_;
  Options o_;
  Firmware fw_;
  std::string incoming_;
  std::string heard_;  // what a device that is not an EBB said
};

}  // namespace stipplot::io::ebb
