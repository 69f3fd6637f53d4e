// Photo methods run on transparent huge pages: main() runs the program again with
// glibc.malloc.hugetlb=1 unless GLIBC_TUNABLES already names it (util/executable.hpp).
#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <string>

#include "test_util.hpp"
#include "util/executable.hpp"

using namespace stipplot;

namespace {
std::string tunables_in(const std::vector<std::string>& env) {
  for (const auto& v : env)
    if (v.rfind("GLIBC_TUNABLES=", 0) == 0) return v;
  return "";
}

// Runs `stipplot <method> FIFO` with `env_prefix`, reads the process's environment while
// it waits for the photo on the FIFO (after any re-run: the same process id), then feeds
// the photo. Returns the GLIBC_TUNABLES it had, "exit N" if it failed.
std::string tunables_of_running(const std::string& env_prefix, const std::string& method) {
  test::TempDir t;
  const std::string script = t.file("run.sh");
  const std::string photo = std::string(STIPPLOT_SHARED_DIR) + "/images/coffee.png";
  {
    std::ofstream s(script);
    s << "set -u\ncd '" << t.path.string() << "'\nmkfifo in.png\n"
      << env_prefix << " '" << STIPPLOT_BIN << "' " << method << " in.png -o o.svg -q --time 5m & pid=$!\n"
      << "seen=''\nfor i in $(seq 1 200); do\n"
      << "  seen=$(tr '\\0' '\\n' < /proc/$pid/environ | grep '^GLIBC_TUNABLES=' || true)\n"
      << "  case \"$seen\" in *hugetlb*) break;; esac\n  sleep 0.05\ndone\n"
      << "cat '" << photo << "' > in.png\nwait $pid || { echo \"exit $?\" > seen.txt; exit 0; }\n"
      << "printf '%s' \"$seen\" > seen.txt\n";
  }
  REQUIRE(std::system(("sh '" + script + "'").c_str()) == 0);
  return test::read_file(t.file("seen.txt"));
}
}  // namespace

TEST_CASE("the huge-page environment adds the tunable once and keeps a user's own", "[threads][cli]") {
  const char* before = std::getenv("GLIBC_TUNABLES");
  const std::string saved = before ? before : "";
  ::unsetenv("GLIBC_TUNABLES");
  CHECK(tunables_in(environment_on_huge_pages()) == "GLIBC_TUNABLES=glibc.malloc.hugetlb=1");
  ::setenv("GLIBC_TUNABLES", "glibc.malloc.arena_max=2", 1);
  CHECK(tunables_in(environment_on_huge_pages()) == "GLIBC_TUNABLES=glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
  ::setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=0", 1);
  CHECK(tunables_in(environment_on_huge_pages()) == "GLIBC_TUNABLES=glibc.malloc.hugetlb=0");
  if (before) ::setenv("GLIBC_TUNABLES", saved.c_str(), 1);
  else ::unsetenv("GLIBC_TUNABLES");
}

TEST_CASE("a photo method runs itself again on huge pages and a user's GLIBC_TUNABLES stands", "[cli]") {
  CHECK(tunables_of_running("env -u GLIBC_TUNABLES", "tree") == "GLIBC_TUNABLES=glibc.malloc.hugetlb=1");
  CHECK(tunables_of_running("env GLIBC_TUNABLES=glibc.malloc.hugetlb=0", "stipple") ==
        "GLIBC_TUNABLES=glibc.malloc.hugetlb=0");
}
