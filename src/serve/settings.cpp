#include "serve/settings.hpp"

#include <algorithm>
#include <regex>

namespace stipplot::serve {

namespace {

const nlohmann::json* find_option(const nlohmann::json& options, const std::string& name) {
  for (const auto& o : options)
    if (o["name"] == name) return &o;
  return nullptr;
}

// Values are words, numbers, lengths, lists and sizes ("0.3mm", "210x297mm", "1,3",
// "A4", "auto"): no '/', so no path leaves the working folder, and no leading '-'
// unless a number, so no value reads as another option.
void check_value(const std::string& name, const std::string& v) {
  static const std::regex number(R"(-?[0-9]*\.?[0-9]+(e-?[0-9]+)?[a-z%]*)");
  static const std::regex word(R"([A-Za-z0-9_.,:+#%= x-]{1,200})");
  if (v.empty()) throw RequestError(400, "option " + name + " needs a value");
  if (v.find("..") != std::string::npos || !std::regex_match(v, word))
    throw RequestError(400, "option " + name + ": value '" + v + "' has characters the studio does not pass on");
  if (v[0] == '-' && !std::regex_match(v, number))
    throw RequestError(400, "option " + name + ": value '" + v + "' would read as an option");
}

}  // namespace

std::string Settings::value_of(const std::string& name, const std::string& fallback) const {
  for (const auto& [n, v] : options)
    if (n == name) return v;
  return fallback;
}

bool Settings::has(const std::string& name) const {
  return std::any_of(options.begin(), options.end(), [&](const auto& p) { return p.first == name; });
}

Settings parse_settings(const nlohmann::json& body, const nlohmann::json& methods) {
  if (!body.is_object() || !body.contains("method") || !body["method"].is_string())
    throw RequestError(400, "settings need a \"method\"");
  Settings s;
  s.method = body["method"].get<std::string>();
  if (!methods.contains(s.method)) throw RequestError(400, "no method '" + s.method + "'");
  const nlohmann::json& schema = methods[s.method]["options"];
  if (!body.contains("options")) return s;
  if (!body["options"].is_object()) throw RequestError(400, "\"options\" must be an object");
  const nlohmann::json& given = body["options"];
  for (const auto& [name, value] : given.items())
    if (!find_option(schema, name)) throw RequestError(400, s.method + " has no option " + name);
  // In the schema's order (the CLI's help order), so the command line reads the same
  // whatever order the page sent.
  for (const auto& o : schema) {
    const std::string name = o["name"];
    if (!given.contains(name)) continue;
    const nlohmann::json& value = given[name];
    if (o["flag"].get<bool>()) {
      if (!value.is_boolean()) throw RequestError(400, "option " + name + " is a flag: true or false");
      if (value.get<bool>()) {
        s.options.emplace_back(name, "");
        s.is_flag.push_back(true);
      }
      continue;
    }
    if (!value.is_string() && !value.is_number()) throw RequestError(400, "option " + name + " needs a value");
    const std::string v = value.is_string() ? value.get<std::string>() : value.dump();
    check_value(name, v);
    s.options.emplace_back(name, v);
    s.is_flag.push_back(false);
  }
  return s;
}

std::vector<std::string> option_args(const Settings& s, const nlohmann::json& methods,
                                     const std::vector<std::string>& groups, const std::vector<std::string>& leave_out) {
  const nlohmann::json& schema = methods[s.method]["options"];
  std::vector<std::string> out;
  for (size_t i = 0; i < s.options.size(); ++i) {
    const auto& [name, value] = s.options[i];
    if (std::find(leave_out.begin(), leave_out.end(), name) != leave_out.end()) continue;
    if (!groups.empty()) {
      const nlohmann::json* o = find_option(schema, name);
      const std::string g = o ? (*o)["group"].get<std::string>() : "";
      if (std::find(groups.begin(), groups.end(), g) == groups.end()) continue;
    }
    if (s.is_flag[i]) {
      out.push_back(name);
    } else if (name.rfind("--", 0) == 0) {
      out.push_back(name + "=" + value);  // one word: the value cannot be taken for an option
    } else if (value[0] == '-') {
      out.push_back(name + value);  // "-a-1": a separate "-1" could read as an option
    } else {
      out.push_back(name);
      out.push_back(value);
    }
  }
  return out;
}

std::string shell_quote(const std::string& a) {
  static const std::regex plain(R"([A-Za-z0-9_./:=,+%@-]+)");
  if (!a.empty() && std::regex_match(a, plain)) return a;
  std::string q = "'";
  for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string shell_line(const std::vector<std::string>& argv) {
  std::string line;
  for (const auto& a : argv) line += (line.empty() ? "" : " ") + shell_quote(a);
  return line;
}

}  // namespace stipplot::serve
