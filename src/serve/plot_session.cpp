#include "serve/plot_session.hpp"

#include <fstream>
#include <sstream>

#include "drivers/device/pen_rule.hpp"
#include "drivers/device/profile.hpp"
#include "drivers/job/ebb_reader.hpp"
#include "drivers/job/gcode_reader.hpp"
#include "drivers/job/hpgl_reader.hpp"
#include "serve/plot_trace.hpp"

namespace stipplot::serve {

namespace fs = std::filesystem;
using nlohmann::json;

void PlotSession::set(const char* key, const json& v) {
  std::lock_guard<std::mutex> lock(m_);
  state_[key] = v;
}

void PlotSession::start() {
  {
    std::lock_guard<std::mutex> lock(m_);
    state_ = {{"port", req_.port},         {"job", req_.job},   {"profile", req_.profile},
              {"status", req_.resume ? "plotting" : "preparing"}, {"lines", 0}, {"lines_acked", 0},
              {"percent", 0.0},            {"eta_s", -1},       {"resumed", req_.resume}};
  }
  thread_ = std::thread([this] {
    try {
      run();
    } catch (const std::exception& e) {  // e.g. no process could be started: the tabs see why
      std::lock_guard<std::mutex> lock(m_);
      child_.reset();
      state_["status"] = "failed";
      state_["message"] = e.what();
    }
  });
}

void PlotSession::run() {
  if (!req_.resume && !make_job()) return;
  load_trace();
  auto child = std::make_shared<Child>();
  {
    std::lock_guard<std::mutex> lock(m_);
    if (aborted_) {
      state_["status"] = "stopped";
      state_["message"] = "aborted before the plot started";
      return;
    }
    child_ = child;
    state_["status"] = "plotting";
    std::vector<std::string> shown = plot_argv();
    shown[0] = "stipplot";
    std::string line;
    for (const auto& a : shown) line += (line.empty() ? "" : " ") + a;
    state_["command"] = line;
  }
  child->start(plot_argv(), req_.workdir.string());
  const ChildResult r = child->wait([this](const std::string& l) { on_progress_line(l); });
  finish(r);
}

// The method's command line with -o JOB: the job is exactly what the CLI writes.
bool PlotSession::make_job() {
  Child c;
  {
    std::lock_guard<std::mutex> lock(m_);
    std::vector<std::string> shown = req_.make_job;
    shown[0] = "stipplot";
    std::string line;
    for (const auto& a : shown) line += (line.empty() ? "" : " ") + a;
    state_["make_command"] = line;
  }
  c.start(req_.make_job, req_.workdir.string());
  const ChildResult r = c.wait();
  if (r.exit_code == 0) {
    // Without a summary the progress is drawn as if the job lay on the sheet unchanged.
    const json summary = last_json_line(r.out);
    std::lock_guard<std::mutex> lock(m_);
    req_.method_summary = summary;
    return true;
  }
  std::lock_guard<std::mutex> lock(m_);
  state_["status"] = "failed";
  const size_t at = r.err.rfind("stipplot:");
  state_["message"] = at == std::string::npos ? "the job could not be made" : r.err.substr(at);
  return false;
}

void PlotSession::load_trace() {
  try {
    std::ifstream in(req_.workdir / req_.job, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    const DeviceProfile dev = find_profile(req_.profile);
    const std::string ext = fs::path(req_.job).extension().string();
    const bool hpgl = ext == ".hpgl";
    // EBB jobs read back in machine mm, as G-code's are.
    const io::Job job = hpgl ? io::parse_hpgl_job(ss.str())
                        : ext == ".ebb" ? io::parse_ebb_job(ss.str(), dev.ebb.steps_per_mm)
                                        : io::parse_gcode_job(ss.str(), gcode_pen_rule(dev));
    json summary;
    {
      std::lock_guard<std::mutex> lock(m_);
      summary = req_.method_summary;
    }
    json t = job_trace(job, dev, hpgl, placement_from_summary(summary, dev));
    std::lock_guard<std::mutex> lock(m_);
    trace_ = std::move(t);
    state_["lines"] = job.lines.size();
  } catch (const std::exception& e) {
    set("trace_error", e.what());  // the plot itself still runs; the page shows no drawing
  }
}

std::vector<std::string> PlotSession::plot_argv() const {
  std::vector<std::string> a = {req_.executable, "plot"};
  if (req_.resume) a.push_back("--resume");
  a.push_back(req_.job);
  for (const char* s : {"--json", "--control"}) a.push_back(s);
  a.push_back("--profile=" + req_.profile);
  if (req_.port == "sim") {
    a.push_back("--sim");
    std::ostringstream sp;
    sp << req_.sim_speedup;
    a.push_back("--sim-speedup=" + sp.str());
  } else {
    a.push_back("--port=" + req_.port);
  }
  return a;
}

void PlotSession::on_progress_line(const std::string& line) {
  const json j = json::parse(line, nullptr, false);
  std::lock_guard<std::mutex> lock(m_);
  if (j.is_discarded() || !j.is_object()) {
    if (line.rfind("stipplot: ", 0) == 0) state_["log"] = line.substr(10);
    return;
  }
  if (j.contains("pen_change")) {
    state_["status"] = "pen_change";
    state_["pen_change"] = j["pen_change"];
    return;
  }
  if (!j.contains("progress")) return;
  state_["lines"] = j.value("lines", 0);
  state_["lines_acked"] = j.value("lines_acked", 0);
  state_["percent"] = 100.0 * j.value("progress", 0.0);
  state_["eta_s"] = j.value("eta_s", -1.0);
  state_["elapsed_s"] = j.value("elapsed_s", 0.0);
  state_["device_state"] = j.value("state", "");
}

void PlotSession::finish(const ChildResult& r) {
  const size_t end = r.out.find_last_not_of('\n');
  json summary = json::object();
  if (end != std::string::npos) {
    const size_t start = r.out.rfind('\n', end);
    summary = json::parse(r.out.substr(start == std::string::npos ? 0 : start + 1, end + 1), nullptr, false);
    if (summary.is_discarded()) summary = json::object();
  }
  std::lock_guard<std::mutex> lock(m_);
  child_.reset();
  const bool completed = r.exit_code == 0 && summary.value("completed", false);
  state_["status"] = completed ? "done" : "stopped";
  state_["result"] = summary;
  if (completed) {
    state_["percent"] = 100.0;
    state_["lines_acked"] = state_["lines"];
    state_["eta_s"] = 0;
  } else {
    const size_t at = r.err.rfind("stipplot: error: ");
    state_["message"] = at == std::string::npos ? "the plot stopped" : r.err.substr(at + 17, r.err.find('\n', at) - at - 17);
  }
  if (summary.contains("sim_png")) {
    // Paths in the working folder, for /files/.
    state_["sim_png"] = fs::path(summary["sim_png"].get<std::string>()).lexically_relative(".").string();
    state_["sim_svg"] = fs::path(summary["sim_svg"].get<std::string>()).lexically_relative(".").string();
  }
  state_["can_resume"] = !completed && fs::exists(req_.workdir / (req_.job + ".journal"));
}

json PlotSession::state() const {
  std::lock_guard<std::mutex> lock(m_);
  return state_;
}

std::shared_ptr<PlotSession> PlotSession::left_unfinished(PlotRequest r, size_t acked, size_t lines) {
  auto s = std::make_shared<PlotSession>(std::move(r));
  s->state_ = {{"port", s->req_.port}, {"job", s->req_.job}, {"profile", s->req_.profile}, {"status", "stopped"},
               {"lines", lines}, {"lines_acked", acked}, {"percent", lines ? 100.0 * double(acked) / double(lines) : 0.0},
               {"eta_s", -1}, {"resumed", false}, {"can_resume", true},
               {"message", "left unfinished by an earlier server: " + std::to_string(acked) + " of " + std::to_string(lines) +
                               " lines plotted; resume from the journal"}};
  return s;
}

json PlotSession::method_summary() const {
  std::lock_guard<std::mutex> lock(m_);
  return req_.method_summary;
}

json PlotSession::trace() const {
  std::lock_guard<std::mutex> lock(m_);
  return trace_;
}

bool PlotSession::busy() const {
  std::lock_guard<std::mutex> lock(m_);
  const std::string s = state_.value("status", "");
  return s == "preparing" || s == "plotting" || s == "paused" || s == "pen_change";
}

bool PlotSession::can_resume() const {
  std::lock_guard<std::mutex> lock(m_);
  return state_.value("can_resume", false);
}

bool PlotSession::command(const std::string& what) {
  std::lock_guard<std::mutex> lock(m_);
  const std::string s = state_.value("status", "");
  if (what == "abort" && s == "preparing") {
    aborted_ = true;
    return true;
  }
  if (!child_) return false;
  if (what == "pause" && s != "plotting") return false;
  if (what == "resume" && s != "paused") return false;
  if (what == "continue" && s != "pen_change") return false;
  if (!child_->send_line(what)) return false;
  if (what == "pause") state_["status"] = "paused";
  if (what == "resume" || what == "continue") state_["status"] = "plotting";
  return true;
}

void PlotSession::join() {
  if (thread_.joinable()) thread_.join();
}

void PlotSession::abort_and_join() {
  {
    std::lock_guard<std::mutex> lock(m_);
    aborted_ = true;
    if (child_) child_->cancel();
  }
  join();
}

}  // namespace stipplot::serve
