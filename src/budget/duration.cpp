#include "budget/duration.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>

#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::budget {

namespace {
double seconds_per_unit(const std::string& u) {
  if (u == "s" || u == "sec" || u == "secs") return 1;
  if (u == "m" || u == "min" || u == "mins") return 60;
  if (u == "h" || u == "hr" || u == "hrs" || u == "hour" || u == "hours") return 3600;
  return 0;
}
bool is_unit_char(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; }
}  // namespace

double parse_duration(std::string_view text, const char* option) {
  const std::string shown(text);
  auto fail = [&](const std::string& why) -> double {
    throw UserError(std::string(option) + " '" + shown + "': " + why + " (e.g. 45min, 1h, 1.5h, 1h30min)");
  };
  double total = 0;
  size_t parts = 0;
  std::string_view rest = text;
  while (true) {
    while (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.front()))) rest.remove_prefix(1);
    if (rest.empty()) break;
    // One part: the number and the letters after it.
    size_t i = 0;
    while (i < rest.size() && !is_unit_char(rest[i])) ++i;
    while (i < rest.size() && is_unit_char(rest[i])) ++i;
    double v = 0;
    std::string unit;
    if (!split_number_unit(rest.substr(0, i), v, unit)) return fail("cannot read a duration");
    if (unit.empty()) return fail("a duration needs a unit: s, min or h");
    const double per = seconds_per_unit(unit);
    if (per == 0) return fail("unknown unit '" + unit + "'");
    if (!(v >= 0) || !std::isfinite(v)) return fail("must not be negative");
    total += v * per;
    ++parts;
    rest.remove_prefix(i);
  }
  if (parts == 0) return fail("empty");
  if (!(total >= 1) || total > 1000 * 3600.0) return fail("must be between 1 s and 1000 h");
  return total;
}

std::string format_duration(double seconds) {
  char buf[64];
  if (!(seconds >= 0) || !std::isfinite(seconds)) return "?";
  if (seconds < 120) {
    std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  } else if (seconds < 3600) {
    std::snprintf(buf, sizeof buf, "%.0f min", seconds / 60);
  } else {
    long minutes = std::lround(seconds / 60);
    std::snprintf(buf, sizeof buf, "%ld h %02ld min", minutes / 60, minutes % 60);
  }
  return buf;
}

}  // namespace stipplot::budget
