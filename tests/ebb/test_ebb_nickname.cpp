// EiBotBoards by nickname on the EBB's own firmware (ebb_sim with a flash image, -f): the
// name ST writes to the board's flash is what QT reads back in a later run, what
// `--port ebb:NAME` picks a board by and what `stipplot devices` shows. Enumerating real
// USB devices is not possible here, so the lookup is tested on the ptys' paths as
// candidates, and the CLI for its answer when no EBB is plugged in.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include "drivers/stream/ebb/nickname.hpp"
#include "drivers/stream/ebb/streamer.hpp"
#include "drivers/transport/devices.hpp"
#include "ebb/ebb_sim.hpp"
#include "test_util.hpp"

using namespace stipplot;

namespace {

// ST,<name> on the board behind `port`, as an owner names a board once.
void set_nickname(const std::string& port, const std::string& name) {
  auto t = io::open_port(port, io::SerialSettings{});
  io::ebb::Streamer st(*t, io::ebb::Options{});
  st.connect();
  st.command("ST," + name);
}

io::SerialPortInfo ebb_port_info(const std::string& name) {
  io::SerialPortInfo p;
  p.name = name;
  p.transport = "usb";
  p.vid = 0x04d8;
  p.pid = 0xfd92;
  p.product = "EiBotBoard";
  return p;
}

}  // namespace

TEST_CASE("Port by nickname: ebb:NAME picks the EBB whose nickname (ST, kept in its flash, read by QT) is NAME", "[ebb]") {
  test::TempDir t;
  {  // Named once; the boards' processes end.
    ebbtest::EbbBoard a(t.file("a0.log"), false, t.file("a.flash")), b(t.file("b0.log"), false, t.file("b.flash"));
    set_nickname(a.port(), "studio");
    set_nickname(b.port(), "garage");
  }
  // New firmware processes: the names come from the flash images.
  ebbtest::EbbBoard a(t.file("a.log"), false, t.file("a.flash")), b(t.file("b.log"), false, t.file("b.flash"));
  ebbtest::EbbBoard unnamed(t.file("c.log"), false, t.file("c.flash"));
  const int m = ::posix_openpt(O_RDWR | O_NOCTTY);  // a port where nothing answers V
  REQUIRE(m >= 0);
  REQUIRE(::grantpt(m) == 0);
  REQUIRE(::unlockpt(m) == 0);
  const std::string silent = ::ptsname(m);
  const io::SerialSettings s;
  CHECK(io::ebb::read_nickname(a.port(), s) == std::optional<std::string>("studio"));
  CHECK(io::ebb::read_nickname(unnamed.port(), s) == std::optional<std::string>(""));
  CHECK(!io::ebb::read_nickname(silent, s));
  // The silent port costs about 3 s a look: once here, once below.
  CHECK(io::ebb::find_by_nickname("garage", {silent, unnamed.port(), a.port(), b.port()}, s) == b.port());
  const std::vector<std::string> ports{unnamed.port(), a.port(), b.port()};
  CHECK(io::ebb::find_by_nickname("studio", ports, s) == a.port());
  try {
    io::ebb::find_by_nickname("attic", ports, s);
    FAIL("an unknown nickname was found");
  } catch (const UserError& e) {
    const std::string w = e.what();
    CHECK(w.find("no EiBotBoard is called 'attic'") != std::string::npos);
    CHECK(w.find(a.port() + " 'studio'") != std::string::npos);
    CHECK(w.find(unnamed.port() + " (no nickname)") != std::string::npos);
    CHECK(w.find(b.port() + " 'garage'") != std::string::npos);
  }
  set_nickname(unnamed.port(), "studio");  // two boards of one name: neither is guessed
  CHECK_THROWS_WITH(io::ebb::find_by_nickname("studio", ports, s), Catch::Contains("several EiBotBoards are called 'studio'"));
  set_nickname(unnamed.port(), "spare");
  // stipplot devices: each EBB port's nickname, asked of the board.
  io::DeviceList d;
  for (const auto& p : {a.port(), unnamed.port()}) d.serial.push_back(ebb_port_info(p));
  d.ebb_nicknames = io::ebb::read_nicknames(io::ebb::ebb_ports(d), s);
  const std::string listing = io::format_devices(d);
  INFO(listing);
  CHECK(listing.find("nickname 'studio' (--port ebb:studio)") != std::string::npos);
  CHECK(listing.find("nickname 'spare' (--port ebb:spare)") != std::string::npos);
  ::close(m);
  // The CLI looks among what is plugged in: here no EBB is, which it says in one line.
  auto r = test::run_cli("pen up --profile axidraw-v3 --port ebb:studio");
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("--port ebb:studio: no EiBotBoard is called 'studio'") != std::string::npos);
  CHECK(test::count_lines(r.err) == 1);
  auto empty = test::run_cli("pen up --profile axidraw-v3 --port ebb:");
  CHECK(empty.exit_code == 1);
  CHECK(empty.err.find("needs the board's nickname") != std::string::npos);
}
