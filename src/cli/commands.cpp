#include "cli/commands.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace stipplot::cli {

namespace {

// What CLI11 would accept too loosely for a value of the option's type: "" becomes 0,
// "-1" wraps to the largest unsigned number, "1e20" saturates, "nan" and "inf" pass.
// The empty string for success, else why the value is refused.
std::string check_value(const std::string& type, const std::string& v) {
  if (v.empty()) return "needs a value, got an empty one";
  const char* end = v.data() + v.size();
  const char* digits = v.data() + (v[0] == '+' ? 1 : 0);  // "+5" is 5; from_chars takes no '+'
  if (type == "UINT") {
    uint64_t n = 0;
    const auto r = std::from_chars(digits, end, n);
    if (r.ec != std::errc() || r.ptr != end)
      return "must be a whole number from 0 to 18446744073709551615, got '" + v + "'";
  } else if (type == "INT") {
    int64_t n = 0;
    const auto r = std::from_chars(digits, end, n);
    if (r.ec != std::errc() || r.ptr != end)
      return "must be a whole number from -9223372036854775808 to 9223372036854775807, got '" + v + "'";
  } else if (type == "FLOAT") {
    char* stop = nullptr;
    const double x = std::strtod(v.c_str(), &stop);
    if (stop != end || !std::isfinite(x) || v.find_first_of("xXnNiI") != std::string::npos)
      return "must be a finite decimal number, got '" + v + "'";
  }
  return "";
}

// One check for every option of every command, so no option takes such a value: its
// own range check (where it is used) then sees a number the user wrote.
void guard_option_values(CLI::App& app) {
  for (CLI::Option* o : app.get_options([](CLI::Option* opt) { return opt->get_type_size() > 0; })) {
    const std::string type = o->get_type_name();
    o->check(CLI::Validator([type](std::string& v) { return check_value(type, v); }, ""));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) guard_option_values(*sub);
}

}  // namespace

void register_all(CLI::App& app) {
  register_stipple(app);
  register_eval(app);
  register_tree(app);
  register_sketch(app);
  register_pointillism(app);
  register_hatch(app);
  register_profiles(app);
  register_export(app);
  register_devices(app);
  register_sim(app);
  register_plot(app);
  register_pen(app);
  register_serve(app);
  register_help_export(app);
  guard_option_values(app);  // after every command: it checks all their options
}

}  // namespace stipplot::cli
