#pragma once
// The real grbl 1.1h firmware as a test oracle. grbl_avr (grbl's AVR binary, as flashed
// to an Arduino Uno, on the simavr instruction-level simulator: ../shared/validators/
// grbl-avr/build.sh) runs on a pseudo-terminal of its own; a
// relay thread copies bytes between that pty and a second one whose path the code under
// test opens like a serial port. Owning both ends lets a test drop the link (the client's
// pty hangs up, the firmware runs on, as a board with its own power does), cut the power
// (freeze and kill the firmware), power it on again, and keep a transcript of every line
// each side sent and every reply. What the firmware did comes from its own logs: see
// firmware_record.hpp.
//
//   firmware::GrblFirmware fw("grbl-servo");
//   run("stipplot plot job.gcode --profile grbl-servo --port " + fw.port());
//   firmware::FirmwareRecord rec = fw.record();
#include <sys/types.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "firmware/firmware_record.hpp"

namespace firmware {

// Builds grbl-avr into `dir` (by default the build tree's grbl-avr/) once; build.sh is
// idempotent and a lock file serialises test processes that start at the same time.
// Returns the path of grbl_avr. Throws std::runtime_error with the build log's tail.
std::string ensure_grbl_avr(const std::string& dir = "");
// The shared validators' settings/<name>.nc for a name ("grbl-servo"); a path with a '/'
// is returned as it is.
std::string settings_file(const std::string& name_or_path);

struct FirmwareOptions {
  std::string settings;     // settings file (name or path) sent after every boot; "" = grbl's defaults
  // grbl_avr -t: simulated time runs at this many times the wall clock (0: as fast as it
  // can, about 2.4x here). 1, as a real board: the host's latency is what grbl would see,
  // and the simulation needs under half a core, so a busy machine does not slow it.
  double timescale = 1;
  // The relay paces both directions like a UART at this rate (8N1), in wall time;
  // 0 = no pacing (grbl_avr's own wire runs at 115200 baud in simulated time).
  double baud = 0;
  double latency_ms = 0;  // one-way delay the relay adds (USB-serial adapters: about 1-2 ms; FTDI up to 16)
  std::string dir;          // work dir (eeprom.bin, session-N/ logs); "" = a temp dir, removed at the end
  // Switch off (cleanly) and on again after the settings, so they act as at power-on:
  // with homing on ($22=1) grbl then starts locked in ALARM (HOMING_INIT_LOCK).
  bool power_cycle_after_settings = false;
};

enum class Cut {
  DropLink,  // the client's pty hangs up; the firmware runs on (board on its own power, cable pulled)
  PowerCut,  // the firmware is frozen and killed, and the client's pty hangs up (USB-powered board)
};

class GrblFirmware {
 public:
  // Builds grbl-avr if needed, starts the firmware, waits for its banner, sends the
  // settings and opens the client pty. Throws std::runtime_error.
  explicit GrblFirmware(FirmwareOptions options = {});
  explicit GrblFirmware(const std::string& settings) : GrblFirmware(with_settings(settings)) {}
  static FirmwareOptions with_settings(const std::string& settings) {
    FirmwareOptions o;
    o.settings = settings;
    return o;
  }
  ~GrblFirmware();
  GrblFirmware(const GrblFirmware&) = delete;
  GrblFirmware& operator=(const GrblFirmware&) = delete;

  // Path of the client pty of the current link; "" while the link is down.
  std::string port() const;

  // --- faults ---
  void drop_link();         // the client's pty hangs up now; the firmware keeps running
  std::string reconnect();  // a new client pty to the same firmware; returns its path
  void power_cut();         // freeze the firmware, hang up the client, kill the firmware
  // A new firmware process (same EEPROM image, so settings persist; position 0 = the machine
  // re-zeroed or homed), banner, settings, a new client pty; returns its path.
  std::string power_on();
  // Switch off cleanly (grbl_avr exits once idle, EEPROM written) and on again, without
  // sending the settings; returns the new client pty.
  std::string power_cycle();
  // Cut the link or the power right after the client's n-th counted line (counted: `counts`
  // returns true; all lines if unset; called in the relay thread) has been read by the
  // firmware; bytes after it are lost. drop_link() and power_cut() cut at once instead:
  // bytes still in the relay are lost, a line may reach grbl in part.
  void cut_after_client_lines(size_t n, Cut how, std::function<bool(const std::string&)> counts = {});
  bool cut_done() const;

  // --- the harness as the host (only while no client pty is open) ---
  // Sends a line, returns grbl's reply lines up to and including ok / error:N.
  std::vector<std::string> command(const std::string& line, double timeout_s = 10);
  // Character counting as grbl's docs describe it: keep at most 127 unanswered bytes in
  // grbl's 128-byte RX buffer. Returns grbl's reply to each line (ok, error:N).
  std::vector<std::string> stream(const std::vector<std::string>& lines, double timeout_s = 120);
  std::string status(double timeout_s = 5);  // '?' -> "<Idle|MPos:...>"
  // Real-time bytes onto grbl's wire now, whoever has the port (a noisy line, a second
  // program, the board's own reset button): "\x18" resets grbl in mid-plot.
  void inject(const std::string& realtime_bytes);
  void reset();                              // Ctrl-X, waits for the banner
  bool wait_idle(double timeout_s);          // polls '?' until Idle and the planner is empty

  // --- what happened ---
  std::vector<HostLine> host_lines() const;
  std::vector<DeviceLine> device_lines() const;
  // Parses every session's step log with the transcript (see FirmwareRecord). Take it
  // with the firmware idle or off; with it running, this first waits until the log on
  // disk (grbl_avr writes it out once a second) reaches where grbl says it stands.
  FirmwareRecord record();
  MachineSettings settings() const;  // from the settings file ($100.., $110.., $120.., $10)
  const std::string& dir() const;
  pid_t pid() const;  // the running firmware, -1 after a power cut

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace firmware
