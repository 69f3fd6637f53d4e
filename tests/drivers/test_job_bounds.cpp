// The job readers' boundary: numbers a job file gives are finite and within a km of the
// origin, or the file is refused naming the line.
#include <catch2/catch.hpp>

#include <string>

#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "util/error.hpp"

using namespace stipplot;

TEST_CASE("job files with numbers beyond any machine are refused", "[drivers][bad-input]") {
  const std::string big(400, '9');  // 1e400: infinity once read
  CHECK_THROWS_WITH(io::parse_gcode_job("G1 X1 Y1\nG1 X" + big + " Y1\n"), Catch::Contains("G-code line 2"));
  CHECK_THROWS_WITH(io::parse_gcode_job("G1 X2000000 Y1\n"), Catch::Contains("beyond +-1000000"));
  CHECK_THROWS_WITH(io::parse_gcode_job("G91\nG1 X900000\nG1 X900000\n"), Catch::Contains("G-code line 3"));
  CHECK_THROWS_AS(io::parse_gcode_job("G1 Z-" + big + "\n"), UserError);
  CHECK_THROWS_AS(io::parse_gcode_job("G1 X1 F" + big + "\n"), UserError);
  CHECK_THROWS_AS(io::parse_gcode_job("G4 P" + big + "\n"), UserError);
  CHECK(io::parse_gcode_job("G21 G90\nG0 X999999 Y-999999 Z5 F60000\n").lines.size() == 2);
  CHECK_THROWS_WITH(io::parse_hpgl_job("IN;PA" + big + ",1;"), Catch::Contains("PA has a number"));
  CHECK_THROWS_WITH(io::parse_hpgl_job("IN;PA1,1;PR1,-" + big + ";"), Catch::Contains("PR has a number"));
  CHECK(io::parse_hpgl_job("IN;PA40000000,-40000000;").lines.size() == 2);
}
