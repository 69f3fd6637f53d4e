#include "drivers/stream/ebb/nickname.hpp"

#include "drivers/stream/ebb/streamer.hpp"
#include "util/error.hpp"

namespace stipplot::io::ebb {

namespace {
constexpr const char* kPrefix = "ebb:";
}

std::optional<std::string> read_nickname(const std::string& port, const SerialSettings& s) {
  try {
    auto t = open_port(port, s);
    Options o;
    o.setup = false;
    o.reply_timeout = Millis(1000);  // three tries of V: a silent port costs about 3 s
    Streamer st(*t, o);
    st.connect();
    return st.nickname();
  } catch (const UserError&) {  // not an EBB, or the port cannot be opened (transport errors too)
    return std::nullopt;
  }
}

std::map<std::string, std::string> read_nicknames(const std::vector<std::string>& ports, const SerialSettings& s) {
  std::map<std::string, std::string> out;
  for (const std::string& p : ports)
    if (auto n = read_nickname(p, s)) out[p] = *n;
  return out;
}

std::string find_by_nickname(const std::string& name, const std::vector<std::string>& candidates,
                             const SerialSettings& s) {
  std::vector<std::string> found;
  std::string heard;
  for (const auto& [port, nick] : read_nicknames(candidates, s)) {
    if (nick == name) found.push_back(port);
    heard += (heard.empty() ? "" : ", ") + port + (nick.empty() ? " (no nickname)" : " '" + nick + "'");
  }
  if (found.size() == 1) return found[0];
  if (found.size() > 1) {
    std::string list;
    for (const auto& p : found) list += (list.empty() ? "" : ", ") + p;
    throw UserError("--port ebb:" + name + ": several EiBotBoards are called '" + name + "' (" + list +
                    "): give one a new nickname, or the port itself");
  }
  throw UserError("--port ebb:" + name + ": no EiBotBoard is called '" + name + "' (" +
                  (candidates.empty() ? std::string("none is connected")
                   : heard.empty()    ? "none of " + std::to_string(candidates.size()) + " EBB port(s) answered"
                                      : "heard: " + heard) +
                  ")");
}

std::vector<std::string> ebb_ports(const DeviceList& d) {
  std::vector<std::string> out;
  for (const auto& p : d.serial)
    if (p.vid == 0x04d8 && p.pid == 0xfd92) out.push_back(p.name);
  return out;
}

std::string resolve_port(const std::string& port, const SerialSettings& s) {
  if (port.rfind(kPrefix, 0) != 0) return port;
  const std::string name = port.substr(std::string(kPrefix).size());
  if (name.empty()) throw UserError("--port ebb:NAME needs the board's nickname after 'ebb:'");
  return find_by_nickname(name, ebb_ports(list_devices()), s);
}

}  // namespace stipplot::io::ebb
