#pragma once
// A drawing's settings as the page sends them, checked against the method's option
// schema and turned into the command line's arguments: the page can ask for nothing the
// CLI's options do not offer, and no value can smuggle in another option or a path.
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace stipplot::serve {

// A request the studio refuses, with the HTTP status to answer (400 unless said).
struct RequestError : std::runtime_error {
  RequestError(int status_code, const std::string& what) : std::runtime_error(what), status(status_code) {}
  int status;
};

struct Settings {
  std::string method;
  std::vector<std::pair<std::string, std::string>> options;  // flags have an empty value
  std::vector<bool> is_flag;
  std::string value_of(const std::string& name, const std::string& fallback) const;
  bool has(const std::string& name) const;
};

// {"method": "stipple", "options": {"-a": "3", "--reloop": true}}, checked against
// methods[method].options. Throws RequestError naming the option. O(options).
Settings parse_settings(const nlohmann::json& body, const nlohmann::json& methods);

// The options as arguments ("--seed=3", "-a", "3", "--reloop"), those of `groups` only
// when it is not empty, and never those named in `leave_out`.
std::vector<std::string> option_args(const Settings& s, const nlohmann::json& methods,
                                     const std::vector<std::string>& groups = {},
                                     const std::vector<std::string>& leave_out = {});

// One argument quoted for a POSIX shell when it needs quoting.
std::string shell_quote(const std::string& arg);
std::string shell_line(const std::vector<std::string>& argv);

}  // namespace stipplot::serve
