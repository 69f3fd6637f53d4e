// Hostile input, as a user (or a fuzzer) would give it: every case exits 1 with one
// error line naming the problem, never crashes or hangs, and leaves no output and no
// temporary file; outputs never overwrite the inputs or each other.
#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include <stb_image_write.h>
#include <sys/wait.h>
#include <unistd.h>

#include "test_util.hpp"

namespace {
namespace fs = std::filesystem;

// Every file in `dir` but the ones named.
std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string svg_with(const std::string& body) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\" width=\"100mm\" "
         "height=\"100mm\" viewBox=\"0 0 100 100\">" + body + "</svg>";
}

// Ten <use> of the level below, fifteen levels deep: 10^15 copies if nothing stops it.
std::string use_bomb() {
  std::string s = "<defs><path id=\"a0\" d=\"M1 1 L2 2\" stroke=\"black\"/>";
  for (int i = 1; i <= 15; ++i) {
    s += "<g id=\"a" + std::to_string(i) + "\">";
    for (int k = 0; k < 10; ++k) s += "<use href=\"#a" + std::to_string(i - 1) + "\"/>";
    s += "</g>";
  }
  return svg_with(s + "</defs><use href=\"#a15\"/>");
}

struct Case {
  std::string args;    // after the binary; DIR is the case's directory
  std::string expect;  // in the one error line
};

std::string expand(std::string s, const std::string& dir) {
  for (size_t p; (p = s.find("DIR")) != std::string::npos;) s.replace(p, 3, dir);
  return s;
}

// Runs each case in a fresh directory holding in.png, in.svg (a plain drawing) and the
// hostile SVGs; afterwards the directory holds exactly what it held before.
void run_cases(const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    test::TempDir t;
    const std::string dir = t.path.string();
    fs::copy_file(test::example("horse.png"), t.file("in.png"));
    write(t.file("in.svg"), svg_with("<path d=\"M10 10 L90 90\" stroke=\"black\"/>"));
    write(t.file("far.svg"), svg_with("<circle cx=\"20\" cy=\"1.7e308\" r=\"10\" stroke=\"black\" fill=\"none\"/>"));
    write(t.file("e18.svg"), svg_with("<path d=\"M1e18 1e18 L2e18 2e18\" stroke=\"black\"/>"));
    write(t.file("bomb.svg"), use_bomb());
    write(t.file("nanmatrix.svg"),
          svg_with("<g transform=\"matrix(1e300 0 0 1e300 0 0) scale(1e300)\"><path d=\"M1 1 L2 2\" stroke=\"black\"/></g>"));
    const std::string png = test::read_file(test::example("horse.png"));
    write(t.file("truncated.png"), png.substr(0, png.size() / 2));
    const std::string jpg = test::read_file(std::string(STIPPLOT_SHARED_DIR) + "/images/rocket.jpg");
    write(t.file("truncated.jpg"), jpg.substr(0, jpg.size() / 2));
    const auto before = files_in(dir);
    const auto before_in = test::read_file(t.file("in.png"));
    auto r = test::run_cli(expand(c.args, dir));
    INFO(c.args << "\n -> exit " << r.exit_code << ": " << r.err);
    CHECK(r.exit_code == 1);
    CHECK(test::count_lines(r.err) == 1);
    CHECK(r.err.rfind("stipplot: error: ", 0) == 0);
    CHECK(r.err.find(expand(c.expect, dir)) != std::string::npos);
    CHECK(files_in(dir) == before);  // no output, no temporary
    CHECK(test::read_file(t.file("in.png")) == before_in);
  }
}
}  // namespace

TEST_CASE("hostile SVGs are refused with one line, before the memory runs out", "[cli][bad-input][svg]") {
  run_cases({
      // once a segfault in the kd-tree
      {"export DIR/far.svg -o DIR/o.gcode", "outside +-1000000 mm"},
      // once signed overflow in the planner's vertex grid
      {"export DIR/e18.svg -o DIR/o.gcode", "outside +-1000000 mm"},
      // once memory without end
      {"export DIR/bomb.svg -o DIR/o.gcode", "more than 1000000 elements drawn through <use>"},
      {"export DIR/nanmatrix.svg -o DIR/o.gcode", "transform"},
      {"plot DIR/far.svg --sim --job DIR/o.gcode", "outside +-1000000 mm"},
  });
}

TEST_CASE("outputs never overwrite inputs or each other", "[cli][bad-input][outputs]") {
  run_cases({
      {"export DIR/in.svg -o DIR/in.svg", "-o DIR/in.svg would overwrite the input"},
      {"export DIR/in.svg -o DIR/./in.svg", "would overwrite the input"},
      {"stipple DIR/in.png -o DIR/o.svg --preview DIR/in.png", "--preview DIR/in.png would overwrite the input"},
      {"stipple DIR/in.png -o DIR/o.svg --preview DIR/o.svg", "--preview DIR/o.svg: expected a .png file"},
      {"tree DIR/in.png -o DIR/o.svg --terrain DIR/in.png", "--terrain DIR/in.png would overwrite the input"},
      {"tree DIR/in.png -o DIR/o.svg --preview DIR/p.png --terrain DIR/p.png", "is also the --preview output"},
      {"pointillism DIR/in.png -o DIR/o.svg --regions-png DIR/in.png", "would overwrite the input"},
      {"stipple DIR/in.png -o DIR/o.svg --preview DIR", "--preview DIR: expected a .png file"},
      {"stipple DIR/in.png -o DIR/o.svg --preview DIR/no/p.png", "directory DIR/no does not exist"},
      {"plot DIR/in.svg --sim --job DIR/o.gcode --sim-out DIR/in", "would overwrite the input"},
      {"plot DIR/in.svg --port usb:1a86:7523 --baud 9600", "has no baud rate or flow control"},
      {"plot DIR/in.svg --port usb:1a86:7523 --flow rtscts", "has no baud rate or flow control"},
  });
}

TEST_CASE("command-line errors exit 1 with one line", "[cli][bad-input]") {
  run_cases({
      {"stipple DIR/in.png -o DIR/o.svg --no-such-option", "--no-such-option"},
      {"stipple DIR/in.png", "-o"},
      {"stipple DIR/in.png -o DIR/o.svg -a ''", "-a: needs a value"},
      {"stipple DIR/in.png -o DIR/o.svg --seed -1", "--seed: must be a whole number from 0 to"},
      {"stipple DIR/in.png -o DIR/o.svg --seed 1e20", "--seed: must be a whole number"},
      {"stipple DIR/in.png -o DIR/o.svg --seed 99999999999999999999", "--seed: must be a whole number"},
      {"stipple DIR/in.png -o DIR/o.svg --max-pixels -1", "--max-pixels: must be a whole number"},
      {"stipple DIR/in.png -o DIR/o.svg -a nan", "-a: expected a length >= 0"},  // a length: mm or px
      {"stipple DIR/in.png -o DIR/o.svg -b inf", "-b: expected a length >= 0"},
      {"tree DIR/in.png -o DIR/o.svg -a nan", "-a: must be a finite decimal number"},
      {"tree DIR/in.png -o DIR/o.svg -b inf", "-b: must be a finite decimal number"},
      {"stipple DIR/in.png -o DIR/o.svg --multipass 1.5", "--multipass: must be a whole number"},
      {"nosuchcommand", "subcommand"},
  });
}

TEST_CASE("damaged images are named for what they are", "[cli][bad-input][image]") {
  run_cases({
      {"stipple DIR/truncated.jpg -o DIR/o.svg", "truncated or corrupt JPEG image"},
      {"stipple DIR/truncated.png -o DIR/o.svg", "truncated or corrupt PNG image"},
      {"stipple DIR/in.png/x.png -o DIR/o.svg", "cannot read: Not a directory"},
      {"stipple DIR/missing.png -o DIR/o.svg", "no such file"},
  });
}

TEST_CASE("out-of-range numbers name the option, its unit and its range", "[cli][bad-input]") {
  run_cases({
      {"stipple DIR/in.png -o DIR/o.svg --page 210x297in --preview DIR/p.png", "lower --preview-dpi"},
      {"stipple DIR/in.png -o DIR/o.svg --preview DIR/p.png --dot-size 1e308mm", "--dot-size"},
      {"sketch DIR/in.png -o DIR/o.svg --cell 2147483648mm", "--cell"},
      {"pointillism DIR/in.png -o DIR/o.svg --fidelity-sigma 1e308", "--fidelity-sigma"},
  });
}

TEST_CASE("an unreadable input is not reported missing", "[cli][bad-input][image]") {
  if (::geteuid() == 0) return;  // root reads anything
  test::TempDir t;
  fs::copy_file(test::example("horse.png"), t.file("in.png"));
  fs::permissions(t.file("in.png"), fs::perms::none);
  auto r = test::run_cli("stipple " + t.file("in.png") + " -o " + t.file("o.svg"));
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("Permission denied") != std::string::npos);
}

TEST_CASE("a signal during the write leaves no temporary file", "[cli][outputs]") {
  test::TempDir t;
  const std::string bin = STIPPLOT_BIN;
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    // A large enough job that the signal lands while outputs are being made.
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      ::setpgid(0, 0);
      const std::string in = test::example("horse.png"), out = t.file("o.gcode"), pv = t.file("p.png");
      // --dots: the dot stipple starts writing within seconds (the connected drawing, the
      // default for horse at 1 h, spends longer on its pilot and tour first).
      ::execl(bin.c_str(), bin.c_str(), "stipple", in.c_str(), "--dots", "-o", out.c_str(), "--preview", pv.c_str(),
              "--preview-dpi", "600", "-q", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Wait until a temporary appears (the run is writing), then signal it.
    bool seen = false;
    for (int i = 0; i < 3000 && !seen; ++i) {
      for (const auto& name : files_in(t.path.string()))
        if (name.find(".tmp-") != std::string::npos) seen = true;
      if (!seen) std::this_thread::sleep_for(std::chrono::milliseconds(5));
      int st;
      if (!seen && ::waitpid(pid, &st, WNOHANG) == pid) FAIL("the run ended before it wrote anything");
    }
    CHECK(seen);
    ::kill(pid, sig);
    int status = 0;
    ::waitpid(pid, &status, 0);
    INFO("signal " << sig);
    CHECK(WIFSIGNALED(status));
    CHECK(files_in(t.path.string()).empty());
  }
}

TEST_CASE("eval of a one-pixel-tall image ends in seconds", "[cli][bad-input]") {
  // Once 8 minutes in GaussianBlur: no dots, so the blur was the image's length, 10^6 px.
  test::TempDir t;
  std::vector<uint8_t> row(1'000'000);
  for (size_t i = 0; i < row.size(); ++i) row[i] = static_cast<uint8_t>(i * 7);
  REQUIRE(stbi_write_png(t.file("long.png").c_str(), 1'000'000, 1, 1, row.data(), 1'000'000));
  const auto t0 = std::chrono::steady_clock::now();
  auto r = test::run_cli("eval " + t.file("long.png") + " " + t.file("long.png") + " --cropped --json");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(s < 30);
  // A sigma far past the image blurs it to its mean, at the same bounded cost.
  r = test::run_cli("eval " + t.file("long.png") + " " + t.file("long.png") + " --cropped --sigma 1000 --json");
  CHECK(r.exit_code == 0);
  CHECK(test::run_cli("eval " + t.file("long.png") + " " + t.file("long.png") + " --sigma 1e308").err.find(
            "--sigma (input px) must be a number in [0, 1000]") != std::string::npos);
}
