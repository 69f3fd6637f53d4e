// Transports: what can be tested without hardware.
#include <libserialport.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <thread>

#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/segments.hpp"
#include "drivers/stream/journal.hpp"
#include "drivers/stream/resume.hpp"
#include "drivers/transport/devices.hpp"
#include "drivers/transport/file_sink.hpp"
#include "drivers/transport/loopback.hpp"
#include "drivers/transport/posix_serial.hpp"
#include "drivers/transport/sp_serial.hpp"
#include "drivers/transport/usb_bulk.hpp"
#include "sim/link.hpp"

using namespace stipplot;
using namespace stipplot::io;

TEST_CASE("libserialport: settings map to its enums, enumeration works, a missing port is a clear error", "[drivers][transport]") {
  SerialSettings s;
  s.baud = 9600;
  s.parity = Parity::Even;
  s.flow = FlowControl::RtsCts;
  s.stop_bits = 2;
  s.data_bits = 7;
  SpConfig c = to_sp_config(s);
  CHECK(c.baud == 9600);
  CHECK(c.bits == 7);
  CHECK(c.stop_bits == 2);
  CHECK(c.parity == SP_PARITY_EVEN);
  CHECK(c.flowcontrol == SP_FLOWCONTROL_RTSCTS);
  s.flow = FlowControl::XonXoff;
  s.parity = Parity::None;
  CHECK(to_sp_config(s).flowcontrol == SP_FLOWCONTROL_XONXOFF);
  CHECK(to_sp_config(s).parity == SP_PARITY_NONE);
  CHECK(parse_flow_control("rtscts") == FlowControl::RtsCts);
  CHECK_THROWS_WITH(parse_flow_control("cts"), Catch::Contains("flow control"));
  auto ports = list_serial_ports();  // may be empty here; must not throw
  for (const auto& p : ports) CHECK_FALSE(p.name.empty());
  CHECK_THROWS_WITH(SpSerial("/dev/ttyNOPE99", {}), Catch::Contains("/dev/ttyNOPE99"));
}

TEST_CASE("libusb: listing works without devices, a missing device says so", "[drivers][transport]") {
  std::string err;
  auto devs = list_usb_devices(&err);  // a container may have no USB at all: then err says why
  for (const auto& d : devs) CHECK(d.vid >= 0);
  CHECK(parse_usb_selector("usb:0403:6001").vid == 0x0403);
  CHECK(parse_usb_selector("usb:0403:6001:2").index == 2);
  CHECK_THROWS_AS(parse_usb_selector("usb:xyz"), UserError);
  try {
    UsbBulk u(parse_usb_selector("usb:f00d:beef"));
    FAIL("opened a device that does not exist");
  } catch (const TransportError& e) {
    CHECK(e.kind() == TransportError::Kind::NotFound);
    CHECK(std::string(e.what()).find("no such USB device f00d:beef") != std::string::npos);
  }
}

TEST_CASE("device listing and port choice", "[drivers][transport]") {
  DeviceList none;
  CHECK(plausible_ports(none).empty());
  CHECK_THROWS_WITH(choose_port(none), Catch::Contains("no plotter found"));
  CHECK(format_devices(none).find("none found") != std::string::npos);
  DeviceList one;
  SerialPortInfo adapter;
  adapter.name = "/dev/ttyUSB0";
  adapter.transport = "usb";
  adapter.vid = 0x1a86;
  adapter.pid = 0x7523;
  SerialPortInfo builtin;
  builtin.name = "/dev/ttyS0";
  builtin.transport = "native";
  one.serial = {builtin, adapter};
  UsbDeviceInfo same;  // the adapter as libusb sees it: not a second plotter
  same.vid = 0x1a86;
  same.pid = 0x7523;
  same.has_bulk_out = true;
  one.usb = {same};
  CHECK(choose_port(one) == "/dev/ttyUSB0");
  DeviceList two = one;
  UsbDeviceInfo printer;
  printer.vid = 0x03f0;
  printer.pid = 0x0107;
  printer.has_bulk_out = true;
  two.usb.push_back(printer);
  CHECK_THROWS_WITH(choose_port(two), Catch::Contains("/dev/ttyUSB0") && Catch::Contains("usb:03f0:0107"));
  // A USB printer node (usblp): a write-only sink, listed as one and plausible.
  DeviceList lp;
  lp.printer_nodes = {"/dev/usb/lp0"};
  CHECK(choose_port(lp) == "/dev/usb/lp0");
  CHECK(format_devices(lp).find("/dev/usb/lp0") != std::string::npos);
  CHECK(format_devices(lp).find("write-only") != std::string::npos);
  // Real listing: never throws, says something either way.
  CHECK_FALSE(format_devices(list_devices()).empty());
}

TEST_CASE("termios serial on a pty: bytes both ways, timeouts, hang-up is a disconnect", "[drivers][transport]") {
  auto link = std::make_unique<sim::PtyLink>();
  PosixSerial port(link->name(), {});
  static_cast<Transport&>(port).write("hello\n");
  char buf[64];
  long n = 0;
  for (int i = 0; i < 100 && n < 6; ++i) {
    long r = link->read(buf + n, sizeof buf - static_cast<size_t>(n), 0.05);
    if (r > 0) n += r;
  }
  REQUIRE(n == 6);
  CHECK(std::string(buf, 6) == "hello\n");
  CHECK(port.read(buf, sizeof buf, Millis(20)) == 0);  // silence is not an error
  link->write("ok\r\nerror:2\r\n");
  LineReader lr(port);
  CHECK(lr.expect_line(Millis(2000), "reply") == "ok");
  CHECK(lr.expect_line(Millis(2000), "reply") == "error:2");
  CHECK_THROWS_AS(lr.expect_line(Millis(50), "reply"), TransportError);
  link->close();
  try {
    for (int i = 0; i < 50; ++i) port.read(buf, sizeof buf, Millis(20));
    FAIL("no disconnect noticed");
  } catch (const TransportError& e) {
    CHECK(e.kind() == TransportError::Kind::Disconnected);
  }
  CHECK_THROWS_WITH(PosixSerial("/nonexistent/tty", {}), Catch::Contains("cannot open serial port /nonexistent/tty"));
  CHECK_THROWS_WITH(PosixSerial(link->name(), SerialSettings{12345}), Catch::Contains("baud"));
}

TEST_CASE("loopback pipe and file sink", "[drivers][transport]") {
  auto [a, b] = make_pipe();
  LoopbackTransport t(a);
  static_cast<Transport&>(t).write("abc");
  char buf[8];
  CHECK(b->read(buf, sizeof buf, Millis(100)) == 3);
  b->write("xy");
  b->close();
  CHECK(t.read(buf, sizeof buf, Millis(100)) == 2);  // what was sent still arrives
  CHECK_THROWS_AS(t.read(buf, sizeof buf, Millis(100)), TransportError);
  auto path = std::filesystem::temp_directory_path() / ("stipplot-sink-" + std::to_string(::getpid()));
  {
    FileSink f(path.string());
    static_cast<Transport&>(f).write("G21\n");
    CHECK(f.read(buf, sizeof buf, Millis(1)) == 0);
  }
  std::ifstream in(path);
  std::string s;
  std::getline(in, s);
  CHECK(s == "G21");
  std::filesystem::remove(path);
  CHECK_THROWS_AS(FileSink("/nonexistent/dir/x"), TransportError);
}

TEST_CASE("journal: records survive, a torn record is ignored, rollback wins", "[drivers][journal]") {
  auto path = (std::filesystem::temp_directory_path() / ("stipplot-j-" + std::to_string(::getpid()))).string();
  JournalHeader h;
  h.job_path = "a.gcode";
  h.job_hash = "123";
  h.dialect = "gcode";
  h.total_lines = 10;
  {
    Journal j(path, h, false, 0);
    j.ack(3);
    j.ack(5);
    j.rollback_to(4);
  }
  JournalState s = Journal::load(path);
  CHECK(s.header.job_path == "a.gcode");
  CHECK(s.header.total_lines == 10);
  CHECK(s.last_acked == 4);
  CHECK_FALSE(s.complete);
  {
    std::ofstream torn(path, std::ios::app);
    torn << Journal::record("ack 9");  // a last record without its newline still counts when whole
  }
  CHECK(Journal::load(path).last_acked == 9);
  CHECK_FALSE(Journal::load(path).torn);
  {
    std::ofstream torn(path, std::ios::app);
    torn << "\n" << Journal::record("ack 7").substr(0, 6);  // cut mid-write
  }
  CHECK(Journal::load(path).last_acked == 9);
  CHECK(Journal::load(path).torn);
  {
    Journal j(path, {}, true);  // the torn tail is cut off before appending
    j.ack(9);
    j.done();
  }
  CHECK(Journal::load(path).complete);
  CHECK_FALSE(Journal::load(path).torn);
  std::filesystem::remove(path);
  CHECK_THROWS_WITH(Journal::load(path), Catch::Contains("no journal"));
}

TEST_CASE("journal: a damaged record, an ack beyond the job or a torn number is refused, naming the line", "[drivers][journal]") {
  auto path = (std::filesystem::temp_directory_path() / ("stipplot-jd-" + std::to_string(::getpid()))).string();
  JournalHeader h;
  h.job_path = "a.gcode";
  h.job_hash = "123";
  h.dialect = "gcode";
  h.total_lines = 2451;
  auto fresh = [&] {
    Journal j(path, h, false, 0);
    j.ack(2450);
  };
  auto append = [&](const std::string& raw) { std::ofstream(path, std::ios::app) << raw; };
  fresh();
  CHECK(Journal::load(path).last_acked == 2450);
  // A record appended by hand (no checksum) is damage, not progress.
  append("ack 99999999\n");
  CHECK_THROWS_WITH(Journal::load(path), Catch::Contains("line 3 fails its checksum"));
  // Even with a valid checksum, an ack beyond the job is refused.
  fresh();
  append(Journal::record("ack 99999999") + "\n");
  CHECK_THROWS_WITH(Journal::load(path), Catch::Contains("`ack 99999999` is not a line of the job (it has 2451 lines)"));
  // A record torn mid-number ("ack 2451" -> "ack 24") fails its checksum: the last one
  // is ignored as torn, never read as line 24.
  fresh();
  append(Journal::record("ack 2440").substr(0, 6));
  JournalState st = Journal::load(path);
  CHECK(st.torn);
  CHECK(st.last_acked == 2450);
  // A flipped byte in the middle of the file.
  fresh();
  append(Journal::record("ack 2450") + "\n" + Journal::record("done") + "\n");
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const size_t at = all.find("ack 2450");
    f.seekp(static_cast<std::streamoff>(at + 4));
    f.put('3');
  }
  CHECK_THROWS_WITH(Journal::load(path), Catch::Contains("is damaged: line 2 fails its checksum"));
  // The journal of another job, dialect or profile.
  fresh();
  st = Journal::load(path);
  CHECK_THROWS_WITH(Journal::check_belongs(st, "a.gcode", "124", "gcode", 2451, ""), Catch::Contains("changed since"));
  CHECK_THROWS_WITH(Journal::check_belongs(st, "a.gcode", "123", "gcode", 2452, ""), Catch::Contains("job of 2451 lines"));
  h.profile = "grbl-servo";
  fresh();
  st = Journal::load(path);
  CHECK_THROWS_WITH(Journal::check_belongs(st, "a.gcode", "123", "gcode", 2451, "grbl-z"),
                    Catch::Contains("--profile grbl-servo"));
  CHECK_NOTHROW(Journal::check_belongs(st, "a.gcode", "123", "gcode", 2451, "grbl-servo"));
  std::filesystem::remove(path);
}

// Found on the real grbl firmware: a link dropped after the board had travelled, pen up,
// back to a point a stroke of the journal's window starts from. The pen standing at the
// stroke's start, lifted, has not begun it: the resume is where the board stopped, not
// the stroke drawn again.
TEST_CASE("resume point: a lifted pen at a stroke's start has not begun it", "[drivers][journal]") {
  // lines: 0 G21, 1 G90, 2 M5, 3 G0 X10 Y10, 4 M3 S30, 5 G1 X20 Y10 F600, 6 G1 X20 Y20,
  //        7 M5, 8 G0 X10 Y10, 9 M3 S30, 10 G1 X0 Y10, 11 M5
  Job job = parse_gcode_job("G21\nG90\nM5\nG0 X10 Y10\nM3 S30\nG1 X20 Y10 F600\nG1 X20 Y20\nM5\nG0 X10 Y10\nM3 S30\n"
                            "G1 X0 Y10\nM5\n");
  REQUIRE(job.lines.size() == 12);
  JournalState journal;
  journal.last_acked = 4;  // the journal ends at the first pen-down; the board ran on to line 8
  const ResumeWindow window{128, 0, 1, 0};
  CHECK(resume_point(job, journal, DevicePen{true, false, 10, 10}, window) == 9);
  // Pen down there: the first stroke's pen-down (line 4) left it so, and that comes first.
  CHECK(resume_point(job, journal, DevicePen{true, true, 10, 10}, window) == 5);
  // Part way along the first stroke, pen lifted by a hold: that move again.
  CHECK(resume_point(job, journal, DevicePen{true, false, 15, 10}, window) == 5);
}

// A board that restarted (a dead host's connect found it held and reset it) stands with
// its pen lifted where a pen-down move ended: the reset stopped the spindle after the move
// ran. The resume goes on after that move, not from the window's start (which drew a whole
// stroke twice on the real firmware). Only when nothing matches as it is.
TEST_CASE("resume point: a restarted board's lifted pen at a pen-down move's end has drawn that move", "[drivers][journal]") {
  // lines: 0 G21, 1 G90, 2 M5, 3 G0 X10 Y10, 4 M3 S30, 5 G1 X20 Y10 F600, 6 G1 X20 Y20,
  //        7 M5, 8 G0 X10 Y10, 9 M3 S30, 10 G1 X0 Y10, 11 M5
  Job job = parse_gcode_job("G21\nG90\nM5\nG0 X10 Y10\nM3 S30\nG1 X20 Y10 F600\nG1 X20 Y20\nM5\nG0 X10 Y10\nM3 S30\n"
                            "G1 X0 Y10\nM5\n");
  JournalState journal;
  journal.last_acked = 5;  // the journal ends with the first move; the board ran it and was reset
  const ResumeWindow restarted{128, 15, 1, 0};
  CHECK(resume_point(job, journal, DevicePen{true, false, 20, 10}, restarted) == 6);
  // Not restarted: a lifted pen there matches nothing, the window's start as before.
  CHECK(resume_point(job, journal, DevicePen{true, false, 20, 10}, ResumeWindow{128, 0, 1, 0}) == 6);
  // A point where a pen-up travel also ends matches that, as it is, first.
  CHECK(resume_point(job, journal, DevicePen{true, false, 10, 10}, restarted) == 4);
}

TEST_CASE("resume: a pen standing where the path passes twice resumes from the earlier pass and announces the redraw", "[drivers][journal]") {
  // A tree edge drawn back along: lines 0 G21, 1 G90, 2 M5, 3 G0 X10 Y10, 4 M3 S30,
  // 5 G1 X20 Y10 F600, 6 G1 X20 Y13, 7 G1 X20 Y10, 8 G1 X30 Y10, 9 M5. (20, 10) ends 5 and 7.
  Job job = parse_gcode_job("G21\nG90\nM5\nG0 X10 Y10\nM3 S30\nG1 X20 Y10 F600\nG1 X20 Y13\nG1 X20 Y10\nG1 X30 Y10\nM5\n");
  JournalState journal;
  journal.last_acked = 4;  // the link dropped; the board ran on with what it held
  const ResumeWindow dropped{128, 15, 1, 0};
  const DevicePen at_node{true, true, 20, 10};
  CHECK(resume_point(job, journal, at_node, dropped) == 6);  // the earlier: nothing lost
  const ResumePlan rp = resume_from_journal(job, journal, at_node, dropped);
  CHECK(rp.next == 6);
  CHECK(rp.redraw == Approx(6.0));  // up to 20,13 and back: what a board at the later pass gets twice
  CHECK_THAT(rp.note, Catch::Contains("passes the pen's point again"));
  // A point the path reaches once: nothing announced.
  const ResumePlan once = resume_from_journal(job, journal, DevicePen{true, true, 20, 13}, dropped);
  CHECK(once.next == 7);
  CHECK(once.redraw == 0);
}

TEST_CASE("resume plans: lift, travel, restore the pen, dots are not touched twice", "[drivers][journal]") {
  // lines: 0 G21, 1 G90, 2 M5, 3 G0 X10 Y10, 4 M3 S30, 5 G4 P0.1, 6 G1 X20 Y10 F600, 7 G1 X20 Y20,
  //        8 M5, 9 G0 X50 Y50, 10 M3 S30, 11 G4 P0.1, 12 M5, 13 G0 X0 Y0
  std::string g =
      "G21\nG90\nM5\nG0 X10 Y10\nM3 S30\nG4 P0.1\nG1 X20 Y10 F600\nG1 X20 Y20\nM5\nG0 X50 Y50\nM3 S30\nG4 P0.1\nM5\nG0 X0 Y0\n";
  Job job = parse_gcode_job(g);
  REQUIRE(job.lines.size() == 14);
  // Mid-stroke (after line 6): lift, travel to (20,10), pen down, feed restored.
  ResumePlan a = plan_resume(job, 7);
  CHECK(a.next == 7);
  std::vector<std::string> want = {"G21", "G90", "M5", "G0 X20.0000 Y10.0000", "M3 S30", "G4 P0.1", "G1 F600"};
  CHECK(a.preamble == want);
  // Right after a dot's pen-down: the lift finishes the dot, skip to after its M5.
  ResumePlan b = plan_resume(job, 11);
  CHECK(b.next == 13);
  // Right after a stroke's pen-down (nothing drawn yet): start the stroke again.
  ResumePlan c = plan_resume(job, 5);
  CHECK(c.next == 4);
  // The device still has the pen down at the right place: no lift, no travel.
  DevicePen dev{true, true, 20, 10};
  ResumePlan d = plan_resume(job, 7, dev);
  CHECK(d.next == 7);
  CHECK(std::find(d.preamble.begin(), d.preamble.end(), "M5") == d.preamble.end());
  CHECK_THROWS_WITH(plan_resume(parse_gcode_job("G91\nM3 S30\nG1 X1 F100\nM5\n"), 3), Catch::Contains("G91"));
  // Segments of the job: one stroke of two moves and one dot.
  auto segs = job_segments(job);
  REQUIRE(segs.size() == 3);
  CHECK(segs[2] == Segment{50, 50, 50, 50, 1});
}

TEST_CASE("pen rule: a servo whose up position is M3 S<up>", "[drivers][journal]") {
  GcodePenRule rule;
  rule.servo_up_s = 90;
  Job j = parse_gcode_job("M3 S90\nG0 X1\nM3 S30\nG1 X2 F100\nM3 S90\n", rule);
  REQUIRE(j.lines.size() == 5);
  CHECK_FALSE(j.lines[0].pen_down);
  CHECK(j.lines[2].pen_down);
  CHECK_FALSE(j.lines[4].pen_down);
  auto segs = job_segments(j);
  REQUIRE(segs.size() == 1);
  CHECK(segs[0] == Segment{1, 0, 2, 0, 1});
}

TEST_CASE("Z pen whose down height is 0: up until the job first sets Z", "[drivers][journal]") {
  GcodePenRule rule;
  rule.z_down_below = 1.5;  // up 3, down 0
  Job j = parse_gcode_job("G21\nG90\nG0 Z3\nG0 X10 Y-5\nG1 Z0 F600\nG1 X20 F1200\nG0 Z3\n", rule);
  CHECK_FALSE(j.lines[0].pen_down);
  CHECK(j.lines[4].pen_down);
  auto segs = job_segments(j);
  REQUIRE(segs.size() == 1);
  CHECK(segs[0] == Segment{10, -5, 20, -5, 1});
  CHECK(std::isfinite(j.est_total_s));
}
