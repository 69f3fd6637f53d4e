#pragma once
// A stipplot command run with --json that must succeed: its JSON summary.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.hpp"

namespace test {

inline nlohmann::json run_json(const std::string& args) {
  const auto r = test::run_cli(args + " --json");
  INFO(args << "\n" << r.err);
  REQUIRE(r.exit_code == 0);
  return nlohmann::json::parse(r.out);
}

}  // namespace test
