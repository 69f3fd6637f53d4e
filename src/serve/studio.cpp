#include "serve/studio.hpp"

#include <httplib.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include "drivers/stream/journal.hpp"
#include "serve/child.hpp"
#include "serve/draft_worker.hpp"
#include "serve/photo.hpp"
#include "serve/plot_session.hpp"
#include "serve/settings.hpp"

namespace stipplot::serve {

namespace fs = std::filesystem;
using nlohmann::json;

extern const char* const kStudioScript;

namespace {

void send_json(httplib::Response& res, const json& j, int status = 200) {
  res.status = status;
  res.set_content(j.dump(), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message) {
  send_json(res, {{"error", message}}, status);
}

json parse_body(const httplib::Request& req) {
  json j = json::parse(req.body, nullptr, false);
  if (j.is_discarded()) throw RequestError(400, "the request body is not JSON");
  return j;
}

// The last "stipplot: error: ..." line a child wrote: the CLI's own one-line diagnosis.
std::string error_line(const ChildResult& r) {
  std::istringstream in(r.err);
  std::string line, last;
  while (std::getline(in, line))
    if (line.rfind("stipplot:", 0) == 0 && line.find("error") != std::string::npos) last = line;
  if (last.empty()) return "the command failed (exit " + std::to_string(r.exit_code) + ")";
  return last.substr(std::string("stipplot: ").size());
}

const char* content_type_of(const fs::path& p) {
  const std::string e = p.extension().string();
  if (e == ".png") return "image/png";
  if (e == ".svg") return "image/svg+xml";
  if (e == ".json" || e == ".journal") return "application/json";
  return "text/plain";
}

}  // namespace

struct Studio::Impl {
  StudioConfig cfg;
  httplib::Server server;
  int bound_port = 0;

  std::mutex m;                   // guards everything below
  std::optional<Photo> photo;     // the uploaded photo and its reduced copy
  uint64_t preview_gen = 0;       // the newest preview asked for
  std::vector<std::function<void()>> preview_cancels;  // end its work when superseded
  std::optional<Settings> settings;  // the last full-size settings: downloads and plots use them
  json last_preview = nullptr;
  std::map<std::string, std::shared_ptr<PlotSession>> plots;  // by port: one plot per device
  int plot_count = 0;

  explicit Impl(StudioConfig c) : cfg(std::move(c)) {}

  std::string path_in_work(const std::string& name) const { return (cfg.workdir / name).string(); }

  // Drafts run in forks of one started worker: no program start each (draft_worker.hpp).
  DraftWorker drafts{{cfg.executable, kDraftWorkerArg}};

  // Runs argv as part of preview `gen`; nullopt when a newer preview superseded it. A
  // draft runs in the draft worker, or as a process of its own if the worker fails.
  std::optional<ChildResult> run_for_preview(uint64_t gen, const std::vector<std::string>& argv, bool draft = false) {
    if (draft) {
      auto job = std::make_shared<DraftWorker::Job>();
      {
        std::lock_guard<std::mutex> lock(m);
        if (gen != preview_gen) return std::nullopt;
        preview_cancels.push_back([this, job] { drafts.cancel(*job); });
      }
      try {
        ChildResult r = drafts.run(argv, cfg.workdir.string(), *job);
        if (r.cancelled) return std::nullopt;
        return r;
      } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "stipplot serve: %s; the draft runs as a process of its own\n", e.what());
        if (job->cancelled.load()) return std::nullopt;
      }
    }
    auto child = std::make_shared<Child>();
    {
      std::lock_guard<std::mutex> lock(m);
      if (gen != preview_gen) return std::nullopt;
      preview_cancels.push_back([child] { child->cancel(); });
    }
    child->start(argv, cfg.workdir.string());
    ChildResult r = child->wait();
    if (r.cancelled) return std::nullopt;
    return r;
  }

  uint64_t begin_preview(const Settings& s, bool draft) {
    std::lock_guard<std::mutex> lock(m);
    for (auto& cancel : preview_cancels) cancel();
    preview_cancels.clear();
    if (!draft) settings = s;
    return ++preview_gen;
  }

  std::string profile_for(const Settings& s, const std::string& dialect) const {
    const std::string chosen = s.value_of("--profile", cfg.default_profile);
    if (dialect.empty()) return chosen;
    for (const auto& p : cfg.profiles)
      if (p["name"] == chosen) {
        if (p["dialect"] == dialect) return chosen;
        break;
      }
    for (const auto& p : cfg.profiles)
      if (p["dialect"] == dialect) return p["name"];
    throw RequestError(400, "no " + dialect + " profile to write that file for");
  }

  // A job file's extension for a profile: what `stipplot METHOD -o` writes for it.
  std::string job_extension(const std::string& profile) const {
    const std::string d = dialect_of_profile(profile);
    return d == "hpgl" ? ".hpgl" : d == "ebb" ? ".ebb" : ".gcode";
  }

  std::string dialect_of_profile(const std::string& name) const {
    for (const auto& p : cfg.profiles)
      if (p["name"] == name) return p["dialect"];
    return "gcode";
  }

  // The command line that makes the drawing `output` from the full-size photo for
  // `profile`. Always named: the profile's sheet is the page and its speeds are the
  // budget's, so the preview, the downloads and the plot are one drawing.
  std::vector<std::string> method_argv(const Settings& s, const std::string& input, const std::string& output,
                                       const std::string& profile) const {
    std::vector<std::string> argv = {cfg.executable, s.method, input, "-o", output};
    const auto opts = option_args(s, cfg.methods, {}, {"--profile"});
    argv.insert(argv.end(), opts.begin(), opts.end());
    argv.push_back("--profile=" + profile);
    return argv;
  }

  json preview(const Settings& s, bool draft);
  void pick_up_journals();
  void routes();
  void guard_routes();
  void file_routes();
  void photo_route();
  void plot_routes();
  std::shared_ptr<PlotSession> session_for(const httplib::Request& req);
};

// One preview: the method on the photo with the pen-true preview PNG, then, side by side,
// its plan for the profile (the plot time of the job's own lines) and `stipplot eval` of
// the preview (the fidelity). While a control is dragged: the method alone on the reduced
// photo, its own plan's time. Superseded work is ended.
json Studio::Impl::preview(const Settings& s, bool draft) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string input, photo_name;
  {
    std::lock_guard<std::mutex> lock(m);
    if (!photo) throw RequestError(409, "upload a photo first");
    input = draft ? photo->draft_name : photo->name;
    photo_name = photo->name;
  }
  const uint64_t gen = begin_preview(s, draft);
  const std::string stem = "previews/p" + std::to_string(gen);
  const std::string profile = profile_for(s, "");
  std::vector<std::string> argv = method_argv(s, input, stem + ".svg", profile);
  for (const char* a : {"--preview", "", "--preview-dpi", "", "--json"}) argv.push_back(a);
  argv[argv.size() - 4] = stem + ".png";
  argv[argv.size() - 2] = draft ? "80" : "150";  // a draft only has to look right on screen
  if (draft) argv.push_back("--draft");
  auto made = run_for_preview(gen, argv, draft);
  if (!made) return {{"superseded", true}};
  if (made->exit_code != 0) throw RequestError(400, error_line(*made));
  json summary = last_json_line(made->out);

  json out = {{"gen", gen},
              {"draft", draft},
              {"marks", summary.value("primitives", 0)},
              {"layers", summary.value("layers", json::array())},
              {"image_px", summary.value("image_px", json::array())},
              {"preview", "/files/" + stem + ".png"},
              {"seconds_method", summary.value("seconds_method", 0.0)}};
  if (draft) {
    // While a control moves, the method's own plan of its drawing for the profile gives
    // the time (the planner's estimate; the job's lines are timed when the control is let
    // go) and no second process runs: the fidelity waits for the full preview.
    if (summary.contains("plan") && summary["plan"].contains("total")) {
      out["plot_s"] = summary["plan"]["total"].value("seconds", 0.0);
      out["pen_down_mm"] = summary["plan"]["total"].value("pen_down_mm", 0.0);
    }
  } else {
    const std::string job = stem + job_extension(profile);
    std::vector<std::string> plan = {cfg.executable, "export", stem + ".svg", "-o", job, "--profile", profile, "--json"};
    const auto plan_opts = option_args(s, cfg.methods, {"Planning", "Paths"});
    plan.insert(plan.end(), plan_opts.begin(), plan_opts.end());
    // The page shows the SSIM alone: no CIEDE2000 a pixel (most of the measure's time).
    std::vector<std::string> eval = {cfg.executable, "eval", input, stem + ".png", "--view-only", "--no-colour", "--json"};
    // The page the method drew on (the profile's sheet unless --page says otherwise).
    if (summary.contains("page_mm") && summary["page_mm"].size() == 2)
      eval.push_back("--page=" + std::to_string(summary["page_mm"][0].get<double>()) + "x" +
                     std::to_string(summary["page_mm"][1].get<double>()) + "mm");
    for (const char* o : {"--margin", "--pen-width"})
      if (s.has(o)) eval.push_back(std::string(o) + "=" + s.value_of(o, ""));
    std::optional<ChildResult> planned, judged;
    std::exception_ptr judge_failed;
    std::thread judge([&] {
      try {
        judged = run_for_preview(gen, eval);
      } catch (...) {
        judge_failed = std::current_exception();  // rethrown below, not lost with the thread
      }
    });
    try {
      planned = run_for_preview(gen, plan);
    } catch (...) {
      judge.join();
      throw;
    }
    judge.join();
    if (judge_failed) std::rethrow_exception(judge_failed);
    if (!planned || !judged) return {{"superseded", true}};
    if (planned->exit_code == 0) {
      const json p = last_json_line(planned->out);
      out["plot_s"] = p["plan"]["total"]["seconds"];
      out["pen_down_mm"] = p["plan"]["total"]["pen_down_mm"];
    } else {
      out["plan_error"] = error_line(*planned);
    }
    // The viewing-distance SSIM (sigma 1 mm on paper), the figure every quality claim uses.
    if (judged->exit_code == 0) out["fidelity"] = last_json_line(judged->out).value("ssim_view", 0.0);
  }
  std::vector<std::string> shown = method_argv(s, photo_name, "drawing.svg", profile);
  shown[0] = "stipplot";
  shown.insert(shown.begin() + 5, {"--preview", "drawing.png"});
  out["command"] = shell_line(shown);
  out["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::lock_guard<std::mutex> lock(m);
  // Keep the files of the last few previews: the page may still be loading one.
  if (gen > 6)
    for (const char* e : {".svg", ".png", ".gcode", ".hpgl", ".ebb"}) fs::remove(path_in_work("previews/p" + std::to_string(gen - 6) + e));
  if (gen == preview_gen) last_preview = out;
  return out;
}

// Plots an earlier server left unfinished (their journals in the working folder): each
// port's newest is offered for resuming, and new jobs are numbered after all of them, so
// none is overwritten. O(files in the folder).
void Studio::Impl::pick_up_journals() {
  std::map<std::string, std::pair<int, std::shared_ptr<PlotSession>>> newest;  // port -> (N, session)
  for (const auto& e : fs::directory_iterator(cfg.workdir)) {
    const std::string name = e.path().filename().string();
    int n = 0;
    char ext[8] = {0};
    if (std::sscanf(name.c_str(), "plot-%d.%5[a-z]", &n, ext) != 2) continue;
    plot_count = std::max(plot_count, n);
    const std::string job = "plot-" + std::to_string(n) + "." + ext;
    if (name != job + ".journal" || !fs::exists(cfg.workdir / job)) continue;
    try {
      const io::JournalState st = io::Journal::load(e.path().string());
      if (st.complete) continue;
      PlotRequest pr;
      pr.executable = cfg.executable;
      pr.workdir = cfg.workdir;
      pr.port = st.header.port.empty() ? "sim" : st.header.port;
      pr.job = job;
      pr.profile = st.header.profile;
      pr.sim_speedup = cfg.sim_speedup;
      auto& slot = newest[pr.port];
      if (n > slot.first)
        slot = {n, PlotSession::left_unfinished(pr, static_cast<size_t>(st.last_acked + 1), st.header.total_lines)};
    } catch (const std::exception&) {
      // A damaged journal: not offered (plot --resume on the command line says why).
    }
  }
  for (auto& [port, entry] : newest) plots[port] = entry.second;
}

Studio::Studio(StudioConfig cfg) : impl_(std::make_unique<Impl>(std::move(cfg))) {
  std::signal(SIGPIPE, SIG_IGN);  // a child or a browser that went away is an error, not the end
  fs::create_directories(impl_->cfg.workdir / "previews");
  impl_->pick_up_journals();
  impl_->routes();
}

Studio::~Studio() {
  stop();
  std::lock_guard<std::mutex> lock(impl_->m);
  for (auto& cancel : impl_->preview_cancels) cancel();
  for (auto& [port, session] : impl_->plots) session->abort_and_join();
}

bool Studio::bind() {
  Impl& I = *impl_;
  if (I.cfg.guard.port == 0) {
    I.bound_port = I.server.bind_to_any_port(I.cfg.guard.bind);
    if (I.bound_port <= 0) return false;
  } else {
    if (!I.server.bind_to_port(I.cfg.guard.bind, I.cfg.guard.port)) return false;
    I.bound_port = I.cfg.guard.port;
  }
  I.cfg.guard.port = I.bound_port;  // the Host check compares with the real port
  return true;
}

int Studio::port() const { return impl_->bound_port; }
void Studio::run() { impl_->server.listen_after_bind(); }
void Studio::stop() { impl_->server.stop(); }

// Limits, security headers and the guard, which every request passes before any handler
// (and before its body is used).
void Studio::Impl::guard_routes() {
  server.set_payload_max_length(cfg.max_upload_bytes);
  server.set_default_headers({{"X-Content-Type-Options", "nosniff"},
                              {"X-Frame-Options", "DENY"},
                              {"Referrer-Policy", "no-referrer"},
                              {"Cache-Control", "no-store"},
                              {"Content-Security-Policy",
                               "default-src 'self'; img-src 'self' blob: data:; style-src 'self' 'unsafe-inline'; "
                               "script-src 'self'; frame-ancestors 'none'"}});
  // Every request passes the guard before any handler (and before any body is used).
  server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    RequestFacts f{req.get_header_value("Host"), req.get_header_value("Origin"),
                   req.get_header_value("X-Stipplot-Token"),
                   cookie_value(req.get_header_value("Cookie"), "stipplot_token"), req.get_param_value("token"),
                   req.get_header_value("Sec-Fetch-Site")};
    const Verdict v = check_request(cfg.guard, f);
    if (!v.allowed()) {
      send_error(res, v.status, v.reason);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    try {
      std::rethrow_exception(ep);
    } catch (const RequestError& e) {
      send_error(res, e.status, e.what());
    } catch (const std::exception& e) {
      send_error(res, 500, e.what());
    }
  });
}

void Studio::Impl::routes() {
  guard_routes();
  server.Get("/", [this](const httplib::Request& req, httplib::Response& res) {
    // The printed address carries the token once; the page's own requests then carry it
    // as a cookie no other site's request gets (SameSite=Strict).
    if (!cfg.guard.token.empty() && req.has_param("token"))
      res.set_header("Set-Cookie", "stipplot_token=" + cfg.guard.token + "; Path=/; HttpOnly; SameSite=Strict");
    res.set_content(kStudioPage, "text/html; charset=utf-8");
  });
  server.Get("/studio.js", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(kStudioScript, "text/javascript; charset=utf-8");
  });
  server.Get("/api/config", [this](const httplib::Request&, httplib::Response& res) {
    json ports = json::array({"sim"});
    if (cfg.list_ports)
      for (const auto& p : cfg.list_ports()) ports.push_back(p);
    send_json(res, {{"methods", cfg.methods},
                    {"profiles", cfg.profiles},
                    {"default_profile", cfg.default_profile},
                    {"ports", ports},
                    {"max_upload_bytes", cfg.max_upload_bytes},
                    {"max_pixels", cfg.max_pixels}});
  });
  server.Post("/api/preview", [this](const httplib::Request& req, httplib::Response& res) {
    const json body = parse_body(req);
    const Settings s = parse_settings(body, cfg.methods);
    json out = preview(s, body.value("draft", false));
    send_json(res, out, out.contains("superseded") ? 409 : 200);
  });
  server.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
    std::lock_guard<std::mutex> lock(m);
    json plots_json = json::object();
    for (const auto& [port, session] : plots) plots_json[port] = session->state();
    send_json(res, {{"photo", photo ? photo->to_json() : json(nullptr)}, {"preview", last_preview}, {"plots", plots_json}});
  });
  photo_route();
  file_routes();
  plot_routes();
}

// The working folder's files (previews, simulator records) and the downloads, each made
// at full size by the command line the page shows.
void Studio::Impl::file_routes() {
  server.Get(R"(/files/(.+))", [this](const httplib::Request& req, httplib::Response& res) {
    const auto p = resolve_inside(cfg.workdir, req.matches[1].str());
    if (!p) return send_error(res, 403, "that path is outside the studio's working folder");
    std::ifstream in(*p, std::ios::binary);
    if (!in || fs::is_directory(*p)) return send_error(res, 404, "no such file");
    std::ostringstream ss;
    ss << in.rdbuf();
    res.set_content(ss.str(), content_type_of(*p));
  });
  server.Get(R"(/api/download/(svg|gcode|hpgl|ebb))", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string kind = req.matches[1].str();
    Settings s;
    std::string input;
    {
      std::lock_guard<std::mutex> lock(m);
      if (!photo || !settings) throw RequestError(409, "upload a photo and make a preview first");
      s = *settings;
      input = photo->name;
    }
    const std::string name = "drawing." + kind;
    const std::vector<std::string> argv = method_argv(s, input, name, profile_for(s, kind == "svg" ? "" : kind));
    Child c;
    c.start(argv, cfg.workdir.string());
    const ChildResult r = c.wait();
    if (r.exit_code != 0) throw RequestError(400, error_line(r));
    std::ifstream in(path_in_work(name), std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    res.set_header("Content-Disposition", "attachment; filename=\"" + fs::path(input).stem().string() + "-" + s.method + "." + kind + "\"");
    res.set_content(ss.str(), kind == "svg" ? "image/svg+xml" : "text/plain");
  });
}

void Studio::Impl::photo_route() {
  server.Post("/api/photo", [this](const httplib::Request& req, httplib::Response& res) {
    Photo p = accept_photo(req.body, cfg.workdir, cfg.max_pixels, cfg.draft_pixels);
    p.original_name = req.get_header_value("X-Filename");
    std::lock_guard<std::mutex> lock(m);
    for (auto& cancel : preview_cancels) cancel();
    preview_cancels.clear();
    ++preview_gen;
    last_preview = nullptr;
    photo = p;
    send_json(res, p.to_json());
  });
}

std::shared_ptr<PlotSession> Studio::Impl::session_for(const httplib::Request& req) {
  const json body = parse_body(req);
  const std::string port = body.value("port", "sim");
  std::lock_guard<std::mutex> lock(m);
  auto it = plots.find(port);
  if (it == plots.end()) throw RequestError(404, "no plot on " + port);
  return it->second;
}

void Studio::Impl::plot_routes() {
  server.Post("/api/plot/start", [this](const httplib::Request& req, httplib::Response& res) {
    const json body = parse_body(req);
    const std::string port = body.value("port", "sim");
    const bool resume = body.value("resume", false);
    std::lock_guard<std::mutex> lock(m);
    if (port != "sim") {
      const auto known = cfg.list_ports ? cfg.list_ports() : std::vector<std::string>{};
      if (std::find(known.begin(), known.end(), port) == known.end()) throw RequestError(400, "no plotter port " + port);
    }
    auto it = plots.find(port);
    if (it != plots.end() && it->second->busy()) throw RequestError(409, "a plot is running on " + port);
    PlotRequest pr;
    pr.executable = cfg.executable;
    pr.workdir = cfg.workdir;
    pr.port = port;
    pr.sim_speedup = cfg.sim_speedup;
    if (resume) {
      if (it == plots.end() || !it->second->can_resume()) throw RequestError(409, "no stopped plot on " + port + " to resume");
      pr.job = it->second->job();
      pr.profile = it->second->profile();
      pr.method_summary = it->second->method_summary();
      pr.resume = true;
    } else {
      if (!photo || !settings) throw RequestError(409, "upload a photo and make a preview first");
      pr.profile = profile_for(*settings, "");
      if (port == "sim" && dialect_of_profile(pr.profile) == "ebb")
        throw RequestError(400, "the simulated plotter runs G-code and HPGL: plot " + pr.profile +
                                    " (an EiBotBoard) on its port, or choose a grbl or HPGL profile for a dry run");
      pr.job = "plot-" + std::to_string(++plot_count) + job_extension(pr.profile);
      pr.make_job = method_argv(*settings, photo->name, pr.job, pr.profile);
      pr.make_job.push_back("--json");  // its page and layout place the progress over the preview
    }
    if (it != plots.end()) it->second->join();
    auto session = std::make_shared<PlotSession>(pr);
    plots[port] = session;
    session->start();
    send_json(res, session->state());
  });
  server.Get("/api/plot/trace", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string port = req.has_param("port") ? req.get_param_value("port") : "sim";
    std::shared_ptr<PlotSession> s;
    {
      std::lock_guard<std::mutex> lock(m);
      auto it = plots.find(port);
      if (it == plots.end()) throw RequestError(404, "no plot on " + port);
      s = it->second;
    }
    send_json(res, s->trace());
  });
  for (const char* command : {"pause", "resume", "abort", "continue"}) {
    server.Post(std::string("/api/plot/") + command, [this, command](const httplib::Request& req, httplib::Response& res) {
      auto s = session_for(req);
      if (!s->command(command)) throw RequestError(409, std::string("the plot cannot ") + command + " now");
      send_json(res, s->state());
    });
  }
}

}  // namespace stipplot::serve
