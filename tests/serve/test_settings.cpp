#include <catch2/catch.hpp>

#include "cli/commands.hpp"
#include "serve/option_schema.hpp"
#include "serve/settings.hpp"

using namespace stipplot::serve;
using nlohmann::json;

namespace {
json stipple_methods() {
  CLI::App app;
  stipplot::cli::register_stipple(app);
  return {{"stipple", {{"description", "x"}, {"options", option_schema(*app.get_subcommand("stipple"), {"--output"})}}}};
}
const json* find(const json& options, const std::string& name) {
  for (const auto& o : options)
    if (o["name"] == name) return &o;
  return nullptr;
}
}  // namespace

TEST_CASE("serve schema: the controls are the CLI's own options with their defaults and units", "[serve]") {
  const json m = stipple_methods();
  const json& opts = m["stipple"]["options"];
  const json* a = find(opts, "-a");
  REQUIRE(a);
  // A length in input pixels or on paper: the unit its default is written in ("3px"),
  // which the studio keeps on every value it sends (a bare number is refused).
  CHECK((*a)["unit"] == "px");
  CHECK((*a)["flag"] == false);
  CHECK((*a)["default"] == "3px");
  const json* method = find(opts, "--method");
  REQUIRE(method);
  CHECK((*method)["default"] == "gray");
  CHECK((*method)["choices"] == json({"random", "gray", "negative", "binary", "color", "cmyk"}));
  const json* law = find(opts, "--law");
  REQUIRE(law);
  CHECK((*law)["choices"] == json({"tone", "linear"}));
  CHECK_FALSE(find(opts, "--knob"));  // hidden from --help, so from the studio too
  const json* margin = find(opts, "--margin");
  REQUIRE(margin);
  CHECK((*margin)["unit"] == "mm");
  CHECK((*margin)["group"] == "Page");
  const json* reloop = find(opts, "--reloop");
  REQUIRE(reloop);
  CHECK((*reloop)["flag"] == true);
  CHECK_FALSE(find(opts, "--output"));  // skipped
  CHECK_FALSE(find(opts, "input"));     // positionals are the studio's
  CHECK(unit_of("Hatch angle in degrees") == "deg");
  CHECK(unit_of("Random seed") == "");
}

TEST_CASE("serve settings: only the method's options pass, as single words", "[serve]") {
  const json m = stipple_methods();
  Settings s = parse_settings(json::parse(R"({"method":"stipple","options":{"-a":"3","--seed":7,"--reloop":true,"--landscape":false}})"), m);
  // In the CLI's order of definition: the shared options (--reloop), then the method's.
  CHECK(option_args(s, m) == std::vector<std::string>{"--reloop", "-a", "3", "--seed=7"});
  CHECK(option_args(s, m, {"Paths"}) == std::vector<std::string>{"--reloop"});
  CHECK(option_args(s, m, {}, {"--seed"}) == std::vector<std::string>{"--reloop", "-a", "3"});
  Settings neg = parse_settings(json::parse(R"({"method":"stipple","options":{"-a":"-1"}})"), m);
  CHECK(option_args(neg, m) == std::vector<std::string>{"-a-1"});
  auto refused = [&](const char* body) {
    try {
      parse_settings(json::parse(body), m);
    } catch (const RequestError& e) {
      return e.status;
    }
    return 0;
  };
  CHECK(refused(R"({"method":"rm"})") == 400);
  CHECK(refused(R"({"method":"stipple","options":{"--output":"/etc/passwd"}})") == 400);
  CHECK(refused(R"({"method":"stipple","options":{"--profile":"../../etc/x.toml"}})") == 400);
  CHECK(refused(R"({"method":"stipple","options":{"--profile":"/etc/x.toml"}})") == 400);
  CHECK(refused(R"({"method":"stipple","options":{"-a":"--output=x.svg"}})") == 400);
  CHECK(refused(R"({"method":"stipple","options":{"--reloop":"yes"}})") == 400);
  CHECK(shell_quote("a b") == "'a b'");
  CHECK(shell_quote("it's") == "'it'\\''s'");
  CHECK(shell_line({"stipplot", "stipple", "photo.jpg", "--page=30x20cm"}) == "stipplot stipple photo.jpg --page=30x20cm");
}
