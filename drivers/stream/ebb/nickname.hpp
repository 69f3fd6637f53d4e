#pragma once
// EiBotBoards by nickname: the name a board keeps in its flash (set with ST, read with QT),
// as axicli's --port NAME uses it. `--port ebb:NAME` is the connected EBB of that name, and
// `stipplot devices` shows each EBB's.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "drivers/transport/devices.hpp"
#include "drivers/transport/transport.hpp"

namespace stipplot::io::ebb {

// The nickname of the EBB on `port` ("" for a board without one), or nullopt where no EBB
// answers (something else, busy, gone). Opens the port, asks V and QT, closes it; the
// board's motion settings are left as they are. A second or so where nothing answers.
std::optional<std::string> read_nickname(const std::string& port, const SerialSettings& s);

// The port among `candidates` whose EBB is called `name` (exactly, as QT gives it). Throws
// UserError when none is (naming the boards that answered and their names) or several are.
// O(candidates) port openings.
std::string find_by_nickname(const std::string& name, const std::vector<std::string>& candidates,
                             const SerialSettings& s);

// Serial ports with the EiBotBoard's USB id (04d8:fd92), in listing order.
std::vector<std::string> ebb_ports(const DeviceList& d);

// Each EBB port's nickname, where a board answered (for `stipplot devices`).
std::map<std::string, std::string> read_nicknames(const std::vector<std::string>& ports, const SerialSettings& s);

// `--port ebb:NAME`: the port of the connected EBB called NAME (among ebb_ports of what is
// plugged in); any other port name as it is.
std::string resolve_port(const std::string& port, const SerialSettings& s);

}  // namespace stipplot::io::ebb
