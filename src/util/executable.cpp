#include "util/executable.hpp"

#include <sys/auxv.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

extern char** environ;

namespace stipplot {

namespace {
// The running program's path, empty when /proc/self/exe cannot be read.
std::string read_self_exe() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, static_cast<size_t>(n)) : std::string();
}
}  // namespace

std::filesystem::path executable_dir() {
  const std::string self = read_self_exe();
  return self.empty() ? std::filesystem::path() : std::filesystem::path(self).parent_path();
}

std::string self_executable() {
  std::string self = read_self_exe();
  if (self.empty()) throw std::runtime_error("cannot find the running executable (/proc/self/exe)");
  return self;
}

std::vector<std::string> environment_on_huge_pages() {
  std::vector<std::string> env;
  bool named = false;
  for (char** e = environ; e && *e; ++e) {
    std::string v = *e;
    if (v.rfind("GLIBC_TUNABLES=", 0) == 0) {
      named = true;
      if (v.find("glibc.malloc.hugetlb") == std::string::npos)
        v += std::string(v.back() == '=' ? "" : ":") + "glibc.malloc.hugetlb=1";
    }
    env.push_back(std::move(v));
  }
  if (!named) env.push_back("GLIBC_TUNABLES=glibc.malloc.hugetlb=1");
  return env;
}

void rerun_on_huge_pages(char** argv) {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.hugetlb")) return;  // already, or the user's choice
  if (::getauxval(AT_SECURE)) return;  // glibc drops GLIBC_TUNABLES there: it would run again and again
  std::string self;
  try {
    self = self_executable();
  } catch (const std::runtime_error&) {
    return;
  }
  std::vector<std::string> env = environment_on_huge_pages();
  std::vector<char*> envp;
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  ::execve(self.c_str(), argv, envp.data());  // returns only if it failed: go on as we are
}

}  // namespace stipplot
