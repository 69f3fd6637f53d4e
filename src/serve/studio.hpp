#pragma once
// `stipplot serve`: the local web studio. One page (web/studio.html, built into the
// binary) over a small JSON API; every drawing, download and plot is a `stipplot` child
// process run with the command line the page shows, in the server's working folder.
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "serve/guard.hpp"

namespace stipplot::serve {

struct StudioConfig {
  GuardConfig guard;
  std::filesystem::path workdir;  // uploads and outputs; no request reaches outside it
  std::string executable;         // the stipplot binary the children run
  // {"stipple": {"description": ..., "options": option_schema(...)}, ...}
  nlohmann::json methods = nlohmann::json::object();
  nlohmann::json profiles = nlohmann::json::array();  // [{"name", "description", "dialect"}]
  std::string default_profile = "grbl-servo";
  uint64_t max_upload_bytes = 64ull << 20;
  uint64_t max_pixels = 50'000'000;    // the CLI's --max-pixels check, on every upload
  uint64_t draft_pixels = 500'000;     // the reduced photo previewed while a control moves
  double sim_speedup = 20;
  // The ports a plotter could be on (what `stipplot devices` finds plausible).
  std::function<std::vector<std::string>()> list_ports;
};

class Studio {
 public:
  explicit Studio(StudioConfig cfg);
  ~Studio();
  Studio(const Studio&) = delete;
  Studio& operator=(const Studio&) = delete;
  // Binds the configured address and port (0: any free port). False when it cannot.
  bool bind();
  int port() const;
  // Serves until stop(); call after bind().
  void run();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The page itself (web/studio.html).
extern const char* const kStudioPage;

}  // namespace stipplot::serve
