#pragma once
// Who may talk to the studio. A local web server that moves a machine is a target for
// any page the user has open: a foreign page may post to 127.0.0.1 (CSRF) or resolve its
// own name to it (DNS rebinding). So every request is checked before any handler runs:
//  - Host must name this server (a loopback name, or the bound address) with its port;
//  - Origin, when a browser sends one, must be this server itself, and no request may
//    come from another site (Sec-Fetch-Site);
//  - on a non-loopback bind every request carries the token (header, cookie or query).
// File names from requests are resolved inside the working folder or refused.
#include <filesystem>
#include <optional>
#include <string>

namespace stipplot::serve {

struct GuardConfig {
  std::string bind = "127.0.0.1";
  int port = 8080;
  std::string token;  // required on every request when not empty
};

// 127.0.0.0/8, ::1 and "localhost".
bool is_loopback_address(const std::string& host);

// What a request carries that the guard looks at (empty when absent).
struct RequestFacts {
  std::string host, origin;
  std::string token_header, token_cookie, token_query;
  // Sec-Fetch-Site: "cross-site" also for what sends no Origin (an <img> of another page).
  std::string fetch_site;
};

struct Verdict {
  int status = 200;   // 200 = allowed; else 401 (token), 403 (Origin), 421 (Host)
  std::string reason;
  bool allowed() const { return status == 200; }
};

// O(length of the headers).
Verdict check_request(const GuardConfig& cfg, const RequestFacts& req);

// The value of cookie `name` in a Cookie header, if present.
std::string cookie_value(const std::string& cookie_header, const std::string& name);

// A random token of 32 hex digits from the system's random device.
std::string random_token();

// `relative` resolved inside `root` (both made absolute, symlinks followed), or nullopt
// when it is absolute, empty, or leads outside `root`.
std::optional<std::filesystem::path> resolve_inside(const std::filesystem::path& root, const std::string& relative);

}  // namespace stipplot::serve
