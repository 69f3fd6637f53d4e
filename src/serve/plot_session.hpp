#pragma once
// One plot on one port, run by `stipplot plot --control` as a child process: the job is
// made first (the method's command line with -o JOB), then streamed; the child's JSON
// progress lines become the state every browser tab polls, and the page's pause, resume,
// abort and pen-change answers are written to its standard input.
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "serve/child.hpp"

namespace stipplot::serve {

struct PlotRequest {
  std::string executable;
  std::filesystem::path workdir;
  std::string port;     // "sim": the built-in simulator
  std::string job;      // plot-N.gcode / .hpgl, in the working folder
  std::string profile;
  std::vector<std::string> make_job;  // empty when resuming
  // The job maker's --json summary (its page and layout: where the progress is drawn
  // over the preview); a resumed plot carries the first session's.
  nlohmann::json method_summary = nullptr;
  bool resume = false;  // continue the job from its journal
  double sim_speedup = 20;
};

class PlotSession {
 public:
  explicit PlotSession(PlotRequest r) : req_(std::move(r)) {}
  // A plot an earlier server left unfinished: stopped, with `acked` of `lines` done,
  // resumable from its journal.
  static std::shared_ptr<PlotSession> left_unfinished(PlotRequest r, size_t acked, size_t lines);
  ~PlotSession() { abort_and_join(); }
  void start();
  // The state every tab sees: status (preparing|plotting|paused|pen_change|done|stopped|
  // failed), lines, percent, ETA, the pen change asked for, the message, the result.
  nlohmann::json state() const;
  // What the job draws, line by line (plot_trace.hpp); null until the job is made.
  nlohmann::json trace() const;
  // pause | resume | abort | continue (a pen change); false when it does not apply now.
  bool command(const std::string& what);
  bool busy() const;
  bool can_resume() const;
  const std::string& job() const { return req_.job; }
  const std::string& profile() const { return req_.profile; }
  nlohmann::json method_summary() const;
  void join();
  void abort_and_join();

 private:
  void run();
  bool make_job();
  void load_trace();
  std::vector<std::string> plot_argv() const;
  void on_progress_line(const std::string& line);
  void finish(const ChildResult& r);
  void set(const char* key, const nlohmann::json& v);

  PlotRequest req_;
  mutable std::mutex m_;
  nlohmann::json state_ = nlohmann::json::object();
  nlohmann::json trace_ = nullptr;
  std::shared_ptr<Child> child_;
  bool aborted_ = false;
  std::thread thread_;
};

}  // namespace stipplot::serve
