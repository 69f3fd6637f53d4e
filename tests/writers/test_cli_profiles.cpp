// `stipplot profiles` through the real executable.
#include <catch2/catch.hpp>

#include "test_util.hpp"

#include <cstdio>
#include <sstream>
#include <string>

namespace {
}  // namespace

TEST_CASE("stipplot profiles lists every shipped profile, name first", "[profiles][cli]") {
  int status = 0;
  std::string out = test::run_cli_merged("profiles", status);
  CHECK(status == 0);
  std::istringstream in(out);
  std::string line;
  std::vector<std::string> names;
  while (std::getline(in, line)) names.push_back(line.substr(0, line.find(' ')));
  CHECK(names == std::vector<std::string>{"axidraw-minikit", "axidraw-v3", "axidraw-v3-a3", "grbl-laser", "grbl-servo",
                                          "grbl-z", "hp7475a-a3", "hp7475a-a4", "idraw-a3", "idraw-a4", "nextdraw-1117",
                                          "nextdraw-2234", "nextdraw-8511", "roland-dxy1300"});
  out = test::run_cli_merged("profiles --json", status);
  CHECK(status == 0);
  CHECK(out.find("\"name\":\"hp7475a-a4\"") != std::string::npos);
  out = test::run_cli_merged("profiles --show no-such-device", status);
  CHECK(status != 0);
  CHECK(out.find("no such profile") != std::string::npos);
}
