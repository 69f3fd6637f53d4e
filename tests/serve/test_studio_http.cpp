// The studio over real HTTP on the loopback: the guard, uploads, the file route, and one
// preview and one simulated plot run through the CLI children.
#include <httplib.h>

#include <catch2/catch.hpp>
#include <functional>
#include <thread>

#include "cli/commands.hpp"
#include "image/image.hpp"
#include "serve/child.hpp"
#include "serve/option_schema.hpp"
#include "serve/studio.hpp"
#include "test_util.hpp"

using namespace stipplot::serve;
using nlohmann::json;

namespace {

struct RunningStudio {
  std::unique_ptr<Studio> studio;
  std::thread thread;
  explicit RunningStudio(StudioConfig c) : studio(std::make_unique<Studio>(std::move(c))) {
    REQUIRE(studio->bind());
    thread = std::thread([this] { studio->run(); });
  }
  ~RunningStudio() {
    studio->stop();
    thread.join();
  }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", studio->port());
    c.set_read_timeout(120, 0);
    return c;
  }
};

StudioConfig config(const test::TempDir& dir) {
  StudioConfig c;
  c.guard.port = 0;
  c.workdir = dir.path;
  c.executable = STIPPLOT_BIN;
  CLI::App app;
  stipplot::cli::register_stipple(app);
  c.methods["stipple"] = {{"description", "stipple"},
                          {"options", option_schema(*app.get_subcommand("stipple"), {"--output", "--preview", "--json"})}};
  c.profiles = json::array({{{"name", "grbl-servo"}, {"description", ""}, {"dialect", "gcode"}}});
  c.max_pixels = 50'000'000;
  c.max_upload_bytes = 4u << 20;
  c.sim_speedup = 100;  // quick, yet not so fast that a loaded machine starves the simulated wire
  return c;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A PNG whose header says 10000 x 10000 (100 MP): the limit is checked from the header,
// before any decoding, as the CLI's --max-pixels is.
std::string png_header_100mp() {
  std::string s("\x89PNG\r\n\x1a\n", 8);
  const unsigned char ihdr[] = {0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0, 0x27, 0x10, 0, 0, 0x27, 0x10, 8, 0, 0, 0, 0, 0, 0, 0, 0};
  s.append(reinterpret_cast<const char*>(ihdr), sizeof ihdr);
  return s;
}

}  // namespace

TEST_CASE("serve http: a non-local bind refuses requests without the token", "[serve]") {
  test::TempDir dir;
  StudioConfig c = config(dir);
  c.guard.bind = "0.0.0.0";
  c.guard.token = "t0ken-for-test";
  RunningStudio s(c);
  auto cl = s.client();
  auto r = cl.Get("/api/config");
  REQUIRE(r);
  CHECK(r->status == 401);
  r = cl.Get("/api/config", {{"X-Stipplot-Token", "wrong"}});
  CHECK(r->status == 401);
  r = cl.Get("/api/config", {{"X-Stipplot-Token", "t0ken-for-test"}});
  CHECK(r->status == 200);
  // The printed address: the page sets the cookie its own requests then carry.
  r = cl.Get("/?token=t0ken-for-test");
  CHECK(r->status == 200);
  CHECK(r->get_header_value("Set-Cookie").find("SameSite=Strict") != std::string::npos);
  r = cl.Get("/api/state", {{"Cookie", "stipplot_token=t0ken-for-test"}});
  CHECK(r->status == 200);
}

TEST_CASE("serve http: foreign Origin and Host are refused", "[serve]") {
  test::TempDir dir;
  RunningStudio s(config(dir));
  auto cl = s.client();
  const std::string self = "http://127.0.0.1:" + std::to_string(s.studio->port());
  auto r = cl.Post("/api/plot/start", {{"Origin", "http://evil.example"}}, R"({"port":"sim"})", "application/json");
  REQUIRE(r);
  CHECK(r->status == 403);
  r = cl.Get("/api/download/gcode", {{"Sec-Fetch-Site", "cross-site"}});
  CHECK(r->status == 403);
  r = cl.Get("/api/config", {{"Origin", self}});
  CHECK(r->status == 200);
  r = cl.Get("/api/config", {{"Host", "rebound.evil.example:" + std::to_string(s.studio->port())}});
  CHECK(r->status == 421);
  r = cl.Get("/");
  CHECK(r->status == 200);
  CHECK(r->body.find("stipplot") != std::string::npos);
  CHECK(r->get_header_value("Content-Security-Policy").find("default-src 'self'") != std::string::npos);
}

TEST_CASE("serve http: no path leads out of the working folder", "[serve]") {
  test::TempDir dir;
  RunningStudio s(config(dir));
  auto cl = s.client();
  std::ofstream(dir.file("inside.txt")) << "inside";
  auto r = cl.Get("/files/inside.txt");
  REQUIRE(r);
  CHECK(r->status == 200);
  CHECK(r->body == "inside");
  for (const char* p : {"/files/../../../../etc/passwd", "/files/..%2F..%2F..%2F..%2Fetc%2Fpasswd", "/files//etc/passwd",
                        "/files/previews/../../x"}) {
    r = cl.Get(p);
    REQUIRE(r);
    INFO(p);
    CHECK((r->status == 403 || r->status == 400));
    CHECK(r->body.find("root:") == std::string::npos);
  }
  r = cl.Get("/files/missing.png");
  CHECK(r->status == 404);
}

TEST_CASE("serve http: uploads that are too big, too many pixels or no image are refused", "[serve]") {
  test::TempDir dir;
  RunningStudio s(config(dir));
  auto cl = s.client();
  auto r = cl.Post("/api/photo", png_header_100mp(), "image/png");
  REQUIRE(r);
  CHECK(r->status == 413);
  CHECK(r->body.find("more than the limit") != std::string::npos);
  r = cl.Post("/api/photo", "GIF? no: plain text, not a photo", "image/png");
  CHECK(r->status == 415);
  r = cl.Post("/api/photo", std::string("\x89PNG\r\n\x1a\n", 8) + "truncated", "image/png");
  CHECK(r->status == 415);
  r = cl.Post("/api/photo", std::string(5u << 20, 'x'), "image/png");  // over the byte limit
  CHECK(r->status == 413);
  r = cl.Post("/api/preview", R"({"method":"stipple"})", "application/json");
  CHECK(r->status == 409);  // no photo yet
  CHECK_FALSE(std::filesystem::exists(dir.file("photo.png")));
}

TEST_CASE("serve http: a photo previews and plots on the simulator as the CLI does", "[serve]") {
  test::TempDir dir;
  RunningStudio s(config(dir));
  auto cl = s.client();
  const std::string png = read_all(std::string(STIPPLOT_SHARED_DIR) + "/images/coffee.png");
  REQUIRE(!png.empty());
  auto r = cl.Post("/api/photo", png, "image/png");
  REQUIRE(r);
  REQUIRE(r->status == 200);
  const json photo = json::parse(r->body);
  CHECK(photo["width"].get<int>() > 0);
  const std::string settings = R"({"method":"stipple","options":{"-b":"20px","--seed":"3"}})";
  r = cl.Post("/api/preview", settings, "application/json");
  REQUIRE(r->status == 200);
  const json p = json::parse(r->body);
  CHECK(p["marks"].get<int>() > 100);
  CHECK(p["plot_s"].get<double>() > 0);
  CHECK(p["fidelity"].get<double>() > 0);
  CHECK(p["fidelity"].get<double>() < 1);
  // While a control moves: the reduced photo, the method's own plan time, no measure.
  r = cl.Post("/api/preview", R"({"method":"stipple","options":{"-b":"24px","--seed":"3"},"draft":true})",
              "application/json");
  REQUIRE(r->status == 200);
  const json d = json::parse(r->body);
  CHECK(d["draft"] == true);
  CHECK(d["marks"].get<int>() > 50);
  CHECK(d["plot_s"].get<double>() > 0);
  CHECK_FALSE(d.contains("fidelity"));
  // The full preview again: the downloads and the plot below are its drawing.
  r = cl.Post("/api/preview", settings, "application/json");
  REQUIRE(r->status == 200);
  // The profile is named: its sheet is the page, as for the plot's job.
  CHECK(p["command"] == "stipplot stipple photo.png -o drawing.svg --preview drawing.png -b 20px --seed=3 --profile=grbl-servo");
  auto png_r = cl.Get(("" + p["preview"].get<std::string>()).c_str());
  CHECK(png_r->status == 200);
  CHECK(png_r->get_header_value("Content-Type") == "image/png");
  r = cl.Get("/api/download/svg");
  CHECK(r->status == 200);
  CHECK(r->body.find("<svg") != std::string::npos);

  r = cl.Post("/api/plot/start", R"({"port":"sim"})", "application/json");
  REQUIRE(r->status == 200);
  json st;
  for (int i = 0; i < 1200; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    st = json::parse(cl.Get("/api/state")->body)["plots"]["sim"];
    if (st["status"] == "done" || st["status"] == "stopped" || st["status"] == "failed") break;
  }
  INFO(st.dump());
  REQUIRE(st["status"] == "done");
  CHECK(st["result"]["sim_exact"] == true);
  // The job is what the command line the studio ran writes.
  const std::string job = st["job"];
  test::TempDir cli;
  std::filesystem::copy_file(dir.file("photo.png"), cli.file("photo.png"));
  const auto run = run_child({STIPPLOT_BIN, "stipple", "photo.png", "-o", "job.gcode", "-b", "20px", "--seed=3",
                              "--profile=grbl-servo"}, cli.path.string());
  REQUIRE(run.exit_code == 0);
  CHECK(read_all(cli.file("job.gcode")) == read_all(dir.file(job)));
  // The trace names every drawn line, placed on the preview's page: each of its dots lies
  // on ink in the preview (the page draws the plot's progress over it).
  const json trace = json::parse(cl.Get("/api/plot/trace?port=sim")->body);
  REQUIRE(trace["segments"].size() > 100);
  const stipplot::Image shown = stipplot::decode_image(reinterpret_cast<const uint8_t*>(png_r->body.data()),
                                                       png_r->body.size(), "preview.png");
  const double pw = trace["page_mm"][0], ph = trace["page_mm"][1];
  auto inked_near = [&](double x_mm, double y_mm) {
    const int cx = static_cast<int>(x_mm / pw * shown.width), cy = static_cast<int>(y_mm / ph * shown.height);
    for (int y = cy - 1; y <= cy + 1; ++y)
      for (int x = cx - 1; x <= cx + 1; ++x)
        if (x >= 0 && y >= 0 && x < shown.width && y < shown.height &&
            stipplot::luma601(shown.channel(x, y, 0), shown.channel(x, y, 1), shown.channel(x, y, 2)) < 128)
          return true;
    return false;
  };
  size_t on_ink = 0, shifted_on_ink = 0;
  for (const auto& seg : trace["segments"]) {
    on_ink += inked_near(seg[3], seg[4]);
    shifted_on_ink += inked_near(seg[3].get<double>() + 3, seg[4].get<double>() + 3);  // 3 mm off: the control
  }
  const double n = static_cast<double>(trace["segments"].size());
  INFO("trace points on the preview's ink: " << on_ink << " of " << n << ", 3 mm off: " << shifted_on_ink);
  CHECK(on_ink >= 0.98 * n);
  CHECK(shifted_on_ink < 0.5 * n);
}

namespace {
json wait_for_plot(httplib::Client& cl, const std::function<bool(const json&)>& until) {
  json st;
  for (int i = 0; i < 1200; ++i) {
    st = json::parse(cl.Get("/api/state")->body)["plots"]["sim"];
    if (until(st)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return st;
}
// A photo, a four-pen cmyk preview and a plot on the simulator, run until its first pen change.
json start_cmyk_plot(httplib::Client& cl) {
  REQUIRE(cl.Post("/api/photo", read_all(std::string(STIPPLOT_SHARED_DIR) + "/images/coffee.png"), "image/png")->status == 200);
  REQUIRE(cl.Post("/api/preview", R"({"method":"stipple","options":{"--method":"cmyk","-b":"40px"}})", "application/json")->status == 200);
  REQUIRE(cl.Post("/api/plot/start", R"({"port":"sim"})", "application/json")->status == 200);
  return wait_for_plot(cl, [](const json& j) { return j["status"] == "pen_change" || j["status"] == "done"; });
}
}  // namespace

TEST_CASE("serve http: a plot asks for each pen by name, and an aborted one resumes from its journal", "[serve]") {
  test::TempDir dir;
  RunningStudio s(config(dir));
  auto cl = s.client();
  json st = start_cmyk_plot(cl);
  INFO("the plot's state: " << st.dump().substr(0, 2000));
  CHECK(cl.Post("/api/plot/start", R"({"port":"sim"})", "application/json")->status == 409);  // one plot per device
  REQUIRE(st["status"] == "pen_change");
  // Light inks first: yellow, cyan, magenta, black.
  CHECK(st["pen_change"].get<std::string>().find("pen 2 cyan") != std::string::npos);
  CHECK(cl.Post("/api/plot/pause", R"({"port":"sim"})", "application/json")->status == 409);  // waiting for the pen
  REQUIRE(cl.Post("/api/plot/continue", R"({"port":"sim"})", "application/json")->status == 200);
  st = wait_for_plot(cl, [](const json& j) { return j["status"] == "pen_change" && j["pen_change"].get<std::string>().find("magenta") != std::string::npos; });
  REQUIRE(st["status"] == "pen_change");
  // Abort at the magenta pen: the journal keeps what was done, and the plot goes on from it.
  REQUIRE(cl.Post("/api/plot/abort", R"({"port":"sim"})", "application/json")->status == 200);
  st = wait_for_plot(cl, [](const json& j) { return j["status"] == "stopped" || j["status"] == "done"; });
  REQUIRE(st["status"] == "stopped");
  CHECK(st["can_resume"] == true);
  CHECK(st["message"].get<std::string>().find("--resume") != std::string::npos);
  const auto done_before = st["lines_acked"].get<size_t>();
  REQUIRE(cl.Post("/api/plot/start", R"({"port":"sim","resume":true})", "application/json")->status == 200);
  // The resumed job asks for the pens still to come (magenta again if the abort came before
  // its M0 was acknowledged, then black), by name.
  std::vector<std::string> asked;
  for (int i = 0; i < 3; ++i) {
    st = wait_for_plot(cl, [](const json& j) { return j["status"] != "plotting"; });
    if (st["status"] != "pen_change") break;
    asked.push_back(st["pen_change"]);
    REQUIRE(cl.Post("/api/plot/continue", R"({"port":"sim"})", "application/json")->status == 200);
  }
  INFO(st.dump());
  REQUIRE_FALSE(asked.empty());
  CHECK(asked.back().find("pen 4 black") != std::string::npos);
  REQUIRE(st["status"] == "done");
  CHECK(st["resumed"] == true);
  // It went on from the journal: fewer lines than the job has, none twice.
  CHECK(done_before > 0);
  CHECK(st["result"]["lines_acked"].get<size_t>() < st["lines"].get<size_t>());
}

TEST_CASE("serve http: a plot an earlier server left unfinished is offered for resuming, and new jobs do not overwrite it", "[serve]") {
  test::TempDir dir;
  {
    RunningStudio s(config(dir));
    auto cl = s.client();
    json st = start_cmyk_plot(cl);
    INFO("the plot's state: " << st.dump().substr(0, 2000));
    REQUIRE(st["status"] == "pen_change");
    REQUIRE(cl.Post("/api/plot/abort", R"({"port":"sim"})", "application/json")->status == 200);
    st = wait_for_plot(cl, [](const json& j) { return j["status"] == "stopped" || j["status"] == "done"; });
    REQUIRE(st["status"] == "stopped");
  }  // the server goes; its journal stays
  RunningStudio again(config(dir));
  auto cl = again.client();
  json st = json::parse(cl.Get("/api/state")->body)["plots"]["sim"];
  INFO(st.dump());
  CHECK(st["status"] == "stopped");
  CHECK(st["can_resume"] == true);
  CHECK(st["job"] == "plot-1.gcode");
  CHECK(st["lines_acked"].get<size_t>() > 0);
  REQUIRE(cl.Post("/api/plot/start", R"({"port":"sim","resume":true})", "application/json")->status == 200);
  for (int i = 0; i < 6; ++i) {
    st = wait_for_plot(cl, [](const json& j) { return j["status"] != "plotting"; });
    if (st["status"] != "pen_change") break;
    REQUIRE(cl.Post("/api/plot/continue", R"({"port":"sim"})", "application/json")->status == 200);
  }
  REQUIRE(st["status"] == "done");
  CHECK(st["resumed"] == true);
  CHECK(st["result"]["lines_acked"].get<size_t>() < st["lines"].get<size_t>());
  // A new plot is numbered after the one left behind.
  REQUIRE(cl.Post("/api/photo", read_all(std::string(STIPPLOT_SHARED_DIR) + "/images/coffee.png"), "image/png")->status == 200);
  REQUIRE(cl.Post("/api/preview", R"({"method":"stipple","options":{"-b":"60px"}})", "application/json")->status == 200);
  REQUIRE(cl.Post("/api/plot/start", R"({"port":"sim"})", "application/json")->status == 200);
  CHECK(json::parse(cl.Get("/api/state")->body)["plots"]["sim"]["job"] == "plot-2.gcode");
  REQUIRE(cl.Post("/api/plot/abort", R"({"port":"sim"})", "application/json")->status == 200);
}

TEST_CASE("serve http: an AxiDraw (EBB) profile previews, downloads its .ebb job, and is not sent to the G-code simulator", "[serve]") {
  test::TempDir dir;
  StudioConfig c = config(dir);
  c.profiles.push_back({{"name", "axidraw-v3"}, {"description", ""}, {"dialect", "ebb"}});
  RunningStudio s(std::move(c));
  auto cl = s.client();
  REQUIRE(cl.Post("/api/photo", read_all(std::string(STIPPLOT_SHARED_DIR) + "/images/coffee.png"), "image/png")->status == 200);
  auto r = cl.Post("/api/preview", R"({"method":"stipple","options":{"-b":"40px","--profile":"axidraw-v3"}})", "application/json");
  INFO(r->body);
  REQUIRE(r->status == 200);
  const json p = json::parse(r->body);
  CHECK(p["plot_s"].get<double>() > 0);  // the .ebb job's own time
  CHECK(p["command"].get<std::string>().find("--profile=axidraw-v3") != std::string::npos);
  r = cl.Get("/api/download/ebb");
  REQUIRE(r->status == 200);
  CHECK(r->body.rfind("EM,", 0) == 0);  // the EBB's own commands, motors on first
  CHECK(r->body.find("\nLM,") != std::string::npos);  // the profile's default moves
  r = cl.Post("/api/plot/start", R"({"port":"sim"})", "application/json");
  CHECK(r->status == 400);
  CHECK(r->body.find("EiBotBoard") != std::string::npos);
}
