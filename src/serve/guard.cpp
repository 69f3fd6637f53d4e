#include "serve/guard.hpp"

#include <algorithm>
#include <random>

namespace stipplot::serve {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// "host:port" or "[v6]:port" split; the port is empty when not given.
std::pair<std::string, std::string> split_host_port(const std::string& hp) {
  if (!hp.empty() && hp[0] == '[') {
    const size_t close = hp.find(']');
    if (close == std::string::npos) return {hp, ""};
    std::string port = close + 1 < hp.size() && hp[close + 1] == ':' ? hp.substr(close + 2) : "";
    return {hp.substr(1, close - 1), port};
  }
  const size_t colon = hp.rfind(':');
  if (colon == std::string::npos) return {hp, ""};
  return {hp.substr(0, colon), hp.substr(colon + 1)};
}

// Constant-time comparison: the token's check leaks nothing through its timing.
bool same_secret(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

bool host_is_ours(const GuardConfig& cfg, const std::string& host_header) {
  auto [host, port] = split_host_port(lower(host_header));
  if (port != std::to_string(cfg.port)) return false;
  if (is_loopback_address(host)) return true;
  // A non-loopback bind answers under its address; a wildcard bind under any name, where
  // the token (not the name) is what keeps a rebound page out.
  if (!is_loopback_address(cfg.bind)) return cfg.bind == "0.0.0.0" || cfg.bind == "::" || host == lower(cfg.bind);
  return false;
}

}  // namespace

bool is_loopback_address(const std::string& host) {
  const std::string h = lower(host);
  if (h == "localhost" || h == "::1" || h == "[::1]") return true;
  // 127.0.0.0/8 in dotted quad form only.
  if (h.rfind("127.", 0) != 0) return false;
  int dots = 0;
  for (char c : h) {
    if (c == '.') ++dots;
    else if (c < '0' || c > '9') return false;
  }
  return dots == 3;
}

Verdict check_request(const GuardConfig& cfg, const RequestFacts& req) {
  if (req.host.empty() || !host_is_ours(cfg, req.host))
    return {421, "Host '" + req.host + "' is not this server (DNS rebinding is refused)"};
  if (!req.origin.empty()) {
    // The page's own origin is http://<the Host it was loaded from>.
    if (lower(req.origin) != "http://" + lower(req.host))
      return {403, "Origin '" + req.origin + "' is not this server (cross-site requests are refused)"};
  }
  if (req.fetch_site == "cross-site") return {403, "requests from another site are refused"};
  if (!cfg.token.empty()) {
    const std::string& given = !req.token_header.empty() ? req.token_header
                               : !req.token_query.empty() ? req.token_query
                                                          : req.token_cookie;
    if (given.empty()) return {401, "this server needs its token (open the address it printed, with ?token=...)"};
    if (!same_secret(given, cfg.token)) return {401, "wrong token"};
  }
  return {};
}

std::string cookie_value(const std::string& header, const std::string& name) {
  size_t pos = 0;
  while (pos < header.size()) {
    size_t end = header.find(';', pos);
    if (end == std::string::npos) end = header.size();
    std::string item = header.substr(pos, end - pos);
    const size_t first = item.find_first_not_of(' ');
    if (first != std::string::npos) item = item.substr(first);
    if (item.size() > name.size() && item.compare(0, name.size(), name) == 0 && item[name.size()] == '=')
      return item.substr(name.size() + 1);
    pos = end + 1;
  }
  return "";
}

std::string random_token() {
  std::random_device rd;
  static const char* hexdigits = "0123456789abcdef";
  std::string t;
  for (int i = 0; i < 32; ++i) t += hexdigits[rd() & 15u];
  return t;
}

std::optional<std::filesystem::path> resolve_inside(const std::filesystem::path& root, const std::string& relative) {
  namespace fs = std::filesystem;
  if (relative.empty() || relative.find('\0') != std::string::npos) return std::nullopt;
  const fs::path rel(relative);
  if (rel.is_absolute() || rel.has_root_name()) return std::nullopt;
  std::error_code ec;
  const fs::path base = fs::weakly_canonical(fs::absolute(root), ec);
  if (ec) return std::nullopt;
  const fs::path full = fs::weakly_canonical(base / rel, ec);
  if (ec) return std::nullopt;
  // Component-wise prefix: /work/studio-x is not inside /work/studio.
  auto b = base.begin(), f = full.begin();
  for (; b != base.end(); ++b, ++f)
    if (f == full.end() || *b != *f) return std::nullopt;
  if (f == full.end()) return std::nullopt;  // the root itself is not a file
  return full;
}

}  // namespace stipplot::serve
