#include <catch2/catch.hpp>

#include "serve/guard.hpp"
#include "test_util.hpp"

using namespace stipplot::serve;

TEST_CASE("serve guard: loopback names are recognised and others are not", "[serve]") {
  CHECK(is_loopback_address("127.0.0.1"));
  CHECK(is_loopback_address("127.1.2.3"));
  CHECK(is_loopback_address("localhost"));
  CHECK(is_loopback_address("::1"));
  CHECK_FALSE(is_loopback_address("0.0.0.0"));
  CHECK_FALSE(is_loopback_address("192.168.1.5"));
  CHECK_FALSE(is_loopback_address("127.0.0.1.evil.example"));
  CHECK_FALSE(is_loopback_address("localhost.evil.example"));
}

TEST_CASE("serve guard: Host must be this server and Origin this page", "[serve]") {
  GuardConfig cfg;
  cfg.port = 8080;
  CHECK(check_request(cfg, {"127.0.0.1:8080", "", "", "", "", ""}).allowed());
  CHECK(check_request(cfg, {"localhost:8080", "http://localhost:8080", "", "", "", ""}).allowed());
  CHECK(check_request(cfg, {"[::1]:8080", "", "", "", "", ""}).allowed());
  // DNS rebinding: a foreign name resolved to 127.0.0.1.
  CHECK(check_request(cfg, {"evil.example:8080", "", "", "", "", ""}).status == 421);
  CHECK(check_request(cfg, {"127.0.0.1:9999", "", "", "", "", ""}).status == 421);
  CHECK(check_request(cfg, {"", "", "", "", "", ""}).status == 421);
  // CSRF: a foreign page posting to the studio.
  CHECK(check_request(cfg, {"127.0.0.1:8080", "http://evil.example", "", "", "", ""}).status == 403);
  CHECK(check_request(cfg, {"127.0.0.1:8080", "http://localhost:8080", "", "", "", ""}).status == 403);
  CHECK(check_request(cfg, {"127.0.0.1:8080", "null", "", "", "", ""}).status == 403);
  // Another site's <img> or link sends no Origin, but the browser says where it comes from.
  CHECK(check_request(cfg, {"127.0.0.1:8080", "", "", "", "", "cross-site"}).status == 403);
  CHECK(check_request(cfg, {"127.0.0.1:8080", "", "", "", "", "same-origin"}).allowed());
  CHECK(check_request(cfg, {"127.0.0.1:8080", "", "", "", "", "none"}).allowed());  // typed into the address bar
}

TEST_CASE("serve guard: with a token every request must carry it", "[serve]") {
  GuardConfig cfg;
  cfg.bind = "0.0.0.0";
  cfg.port = 8080;
  cfg.token = "s3cret";
  CHECK(check_request(cfg, {"192.168.1.5:8080", "", "", "", "", ""}).status == 401);
  CHECK(check_request(cfg, {"192.168.1.5:8080", "", "wrong", "", "", ""}).status == 401);
  CHECK(check_request(cfg, {"192.168.1.5:8080", "", "s3cret", "", "", ""}).allowed());
  CHECK(check_request(cfg, {"192.168.1.5:8080", "", "", "s3cret", "", ""}).allowed());
  CHECK(check_request(cfg, {"192.168.1.5:8080", "", "", "", "s3cret", ""}).allowed());
  CHECK(check_request(cfg, {"192.168.1.5:8080", "http://evil.example", "s3cret", "", "", ""}).status == 403);
  GuardConfig named = cfg;
  named.bind = "10.0.0.7";
  CHECK(check_request(named, {"10.0.0.7:8080", "", "s3cret", "", "", ""}).allowed());
  CHECK(check_request(named, {"evil.example:8080", "", "s3cret", "", "", ""}).status == 421);
  CHECK(cookie_value("a=1; stipplot_token=s3cret; b=2", "stipplot_token") == "s3cret");
  CHECK(cookie_value("xstipplot_token=1", "stipplot_token").empty());
  CHECK(random_token().size() == 32);
  CHECK(random_token() != random_token());
}

TEST_CASE("serve guard: file names stay inside the working folder", "[serve]") {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path / "previews");
  std::ofstream(dir.file("previews/p1.png")) << "x";
  const auto ok = resolve_inside(dir.path, "previews/p1.png");
  REQUIRE(ok);
  CHECK(ok->filename() == "p1.png");
  CHECK_FALSE(resolve_inside(dir.path, "../etc/passwd"));
  CHECK_FALSE(resolve_inside(dir.path, "previews/../../x"));
  CHECK_FALSE(resolve_inside(dir.path, "/etc/passwd"));
  CHECK_FALSE(resolve_inside(dir.path, ""));
  CHECK_FALSE(resolve_inside(dir.path, "."));
  // A sibling whose name starts like the folder's is outside it.
  CHECK_FALSE(resolve_inside(dir.path, "../" + dir.path.filename().string() + "x/f"));
  // A symlink leading out is followed, and refused.
  std::filesystem::create_symlink("/etc", dir.path / "out");
  CHECK_FALSE(resolve_inside(dir.path, "out/passwd"));
}
