#include "serve/option_schema.hpp"

#include <regex>

namespace stipplot::serve {

std::string unit_of(const std::string& help) {
  static const std::regex px(R"(\bpixels?\b|\bpx\b)"), mm(R"(\bmm\b|a length)"), deg(R"(\bdegrees?\b)"),
      sec(R"(\bseconds?\b)");
  if (std::regex_search(help, mm)) return "mm";
  if (std::regex_search(help, px)) return "px";
  if (std::regex_search(help, deg)) return "deg";
  if (std::regex_search(help, sec)) return "s";
  return "";
}

namespace {

// "random|gray|negative" at the start of a help text, or after "a: b|c|d": the choices.
nlohmann::json choices_of(const std::string& help) {
  static const std::regex list(R"((?:^|: )([a-z0-9-]+(?:\|[a-z0-9-]+)+)(?:$|[ ,;(]))");
  std::smatch m;
  nlohmann::json out = nlohmann::json::array();
  if (!std::regex_search(help, m, list)) return out;
  const std::string s = m[1].str();
  size_t pos = 0;
  while (pos <= s.size()) {
    size_t bar = s.find('|', pos);
    if (bar == std::string::npos) bar = s.size();
    out.push_back(s.substr(pos, bar - pos));
    pos = bar + 1;
  }
  return out;
}

std::string display_name(const CLI::Option& o) {
  std::string best;
  for (const auto& l : o.get_lnames())
    if (l.size() + 2 > best.size()) best = "--" + l;
  if (best.empty() && !o.get_snames().empty()) best = "-" + o.get_snames().front();
  return best;
}

bool skipped(const CLI::Option& o, const std::set<std::string>& skip) {
  for (const auto& l : o.get_lnames())
    if (skip.count("--" + l)) return true;
  for (const auto& s : o.get_snames())
    if (skip.count("-" + s)) return true;
  return false;
}

}  // namespace

nlohmann::json option_schema(const CLI::App& command, const std::set<std::string>& skip) {
  nlohmann::json out = nlohmann::json::array();
  for (const CLI::Option* o : command.get_options()) {
    // Hidden options (no group: the benchmark's --knob) are no studio controls either.
    if (o->get_positional() || o->get_group().empty() || skipped(*o, skip)) continue;
    const std::string name = display_name(*o);
    if (name.empty() || name == "--help") continue;
    const std::string help = o->get_description();
    nlohmann::json j = {{"name", name},
                        {"flag", o->get_expected_min() == 0},
                        {"default", o->get_default_str()},
                        {"help", help},
                        {"group", o->get_group()},
                        {"unit", unit_of(help)},
                        {"choices", choices_of(help)}};
    out.push_back(j);
  }
  return out;
}

}  // namespace stipplot::serve
