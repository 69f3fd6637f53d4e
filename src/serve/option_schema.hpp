#pragma once
// The studio's controls come from the command line's own option definitions, so the page
// offers exactly what `stipplot <method>` accepts, with the same defaults and help.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

namespace stipplot::serve {

// One subcommand's options as JSON: [{name, flag, default, help, group, unit, choices}],
// in definition order; `name` is the longest long name ("--seed") or the short one
// ("-a"). Options in `skip` (any of their names) and positionals are left out.
// O(options).
nlohmann::json option_schema(const CLI::App& command, const std::set<std::string>& skip);

// The unit a help text states ("in pixels" -> "px", "mm"/"a length" -> "mm",
// "degrees" -> "deg", "seconds" -> "s"), or "" when it states none.
std::string unit_of(const std::string& help);

}  // namespace stipplot::serve
