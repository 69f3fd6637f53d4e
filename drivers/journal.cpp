#include "drivers/journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "util/error.hpp"

namespace stipplot::io {

const char* to_string(Dialect d) { return d == Dialect::Hpgl ? "hpgl" : "gcode"; }

uint64_t fnv1a64(const std::string& data) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : data) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// ---- G-code -------------------------------------------------------------------

namespace {

struct GcodeState {
  // Z is unknown until the job sets it; until then the pen counts as up (a Z plotter
  // whose "down" height is 0 must not read as down before its first Z move).
  double x = 0, y = 0, z = std::numeric_limits<double>::infinity();
  double scale = 1;  // G20: 25.4
  bool absolute = true;
  int motion = 0;  // 0 or 1
  double feed = 0;
  bool spindle = false;
  double s = 0;
};

// Strips ( ) and ; comments and whitespace, upper-cases.
std::string clean_gcode_line(const std::string& raw) {
  std::string out;
  bool paren = false;
  for (char c : raw) {
    if (paren) {
      if (c == ')') paren = false;
      continue;
    }
    if (c == '(') {
      paren = true;
      continue;
    }
    if (c == ';') break;
    if (c == '\r') continue;
    out.push_back(c);
  }
  auto b = out.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  auto e = out.find_last_not_of(" \t");
  return out.substr(b, e - b + 1);
}

struct Word {
  char letter;
  double value;
};

std::vector<Word> gcode_words(const std::string& line) {
  std::vector<Word> w;
  size_t i = 0;
  while (i < line.size()) {
    char c = static_cast<char>(std::toupper(static_cast<unsigned char>(line[i])));
    if (c == ' ' || c == '\t') {
      ++i;
      continue;
    }
    if (c == '$' || c == '%') return {};  // system command or tape marker: no words
    ++i;
    size_t start = i;
    while (i < line.size() && (std::isdigit(static_cast<unsigned char>(line[i])) || line[i] == '.' ||
                               line[i] == '-' || line[i] == '+' || line[i] == ' '))
      ++i;
    std::string num;
    for (size_t k = start; k < i; ++k)
      if (line[k] != ' ') num.push_back(line[k]);
    w.push_back({c, num.empty() ? 0.0 : std::strtod(num.c_str(), nullptr)});
  }
  return w;
}

}  // namespace

bool gcode_pen_down(bool spindle_on, double s, double z, const GcodePenRule& rule) {
  bool servo_down = spindle_on && s > 0 && !(rule.servo_up_s > 0 && std::abs(s - rule.servo_up_s) < 1e-9);
  return servo_down || z < rule.z_down_below;
}

Job parse_gcode_job(const std::string& text, const GcodePenRule& rule) {
  Job job;
  job.dialect = Dialect::GCode;
  GcodeState st;
  std::istringstream in(text);
  std::string raw;
  constexpr double rapid_mm_s = 100;
  while (std::getline(in, raw)) {
    std::string line = clean_gcode_line(raw);
    if (line.empty()) continue;
    JobLine jl;
    jl.text = line;
    double nx = st.x, ny = st.y, nz = st.z;
    bool axis = false;
    double dwell = 0;
    bool is_dwell = false;
    for (const Word& w : gcode_words(line)) {
      switch (w.letter) {
        case 'G': {
          int g = static_cast<int>(std::lround(w.value * 10));
          if (g == 0 || g == 10) st.motion = g / 10;
          else if (g == 40) is_dwell = true;
          else if (g == 200) st.scale = 25.4;
          else if (g == 210) st.scale = 1;
          else if (g == 900) st.absolute = true;
          else if (g == 910) st.absolute = false;
          break;
        }
        case 'M': {
          int m = static_cast<int>(std::lround(w.value));
          if (m == 3 || m == 4) st.spindle = true;
          if (m == 5 || m == 2 || m == 30) st.spindle = false;
          break;
        }
        case 'S': st.s = w.value; break;
        case 'F': st.feed = w.value * st.scale; break;
        case 'P': dwell = w.value; break;
        case 'X': nx = st.absolute ? w.value * st.scale : st.x + w.value * st.scale; axis = true; break;
        case 'Y': ny = st.absolute ? w.value * st.scale : st.y + w.value * st.scale; axis = true; break;
        case 'Z':
          nz = st.absolute || !std::isfinite(st.z) ? w.value * st.scale : st.z + w.value * st.scale;
          axis = true;
          break;
        default: break;
      }
    }
    if (axis && !is_dwell) {
      double dz = std::isfinite(st.z) && std::isfinite(nz) ? nz - st.z : 0;
      double d = std::hypot(nx - st.x, ny - st.y, dz);
      double v = st.motion == 0 || st.feed <= 0 ? rapid_mm_s : st.feed / 60.0;
      jl.est_s = d / v;
      jl.motion = true;
      st.x = nx;
      st.y = ny;
      st.z = nz;
    }
    if (is_dwell) jl.est_s = dwell;
    jl.x = st.x;
    jl.y = st.y;
    jl.pen_down = gcode_pen_down(st.spindle, st.s, st.z, rule);
    job.est_total_s += jl.est_s;
    job.lines.push_back(std::move(jl));
  }
  return job;
}

// ---- HPGL ---------------------------------------------------------------------

Job parse_hpgl_job(const std::string& text) {
  Job job;
  job.dialect = Dialect::Hpgl;
  double x = 0, y = 0;
  bool down = false, absolute = true;
  double speed_pu_s = 400 * 38.1 / 10;  // 38.1 cm/s at 40 units/mm (HP 7475A default)
  size_t i = 0;
  const size_t n = text.size();
  auto skip_sep = [&] {
    while (i < n && (text[i] == ' ' || text[i] == '\n' || text[i] == '\r' || text[i] == '\t' || text[i] == ';'))
      ++i;
  };
  while (true) {
    skip_sep();
    if (i >= n) break;
    if (text[i] == 0x1b) {  // device-control sequence: pass through as its own "line"
      size_t s = i;
      i += 2;
      while (i < n && !(std::isalpha(static_cast<unsigned char>(text[i])) || text[i] == ':')) ++i;
      if (i < n) ++i;
      job.lines.push_back({text.substr(s, i - s), false, down, x, y, 0});
      continue;
    }
    if (i + 1 >= n || !std::isalpha(static_cast<unsigned char>(text[i])) ||
        !std::isalpha(static_cast<unsigned char>(text[i + 1])))
      throw UserError("HPGL: expected a two-letter instruction at byte " + std::to_string(i));
    std::string mn = {static_cast<char>(std::toupper(static_cast<unsigned char>(text[i]))),
                      static_cast<char>(std::toupper(static_cast<unsigned char>(text[i + 1])))};
    size_t s = i;
    i += 2;
    std::string params;
    if (mn == "LB") {
      while (i < n && text[i] != 0x03) params.push_back(text[i++]);
      if (i < n) ++i;
      job.lines.push_back({text.substr(s, i - s), false, down, x, y, 0});
      continue;
    }
    while (i < n && text[i] != ';' && !std::isalpha(static_cast<unsigned char>(text[i])) && text[i] != 0x1b)
      params.push_back(text[i++]);
    if (i < n && text[i] == ';') ++i;
    std::vector<double> nums;
    {
      std::string cur;
      auto flush = [&] {
        if (!cur.empty()) nums.push_back(std::strtod(cur.c_str(), nullptr));
        cur.clear();
      };
      for (char c : params) {
        if (c == ',' || c == ' ' || c == '\n' || c == '\r' || c == '\t') flush();
        else if ((c == '-' || c == '+') && !cur.empty()) {
          flush();
          cur.push_back(c);
        } else cur.push_back(c);
      }
      flush();
    }
    JobLine jl;
    jl.text = mn;
    for (size_t k = 0; k < nums.size(); ++k) {
      char b[32];
      std::snprintf(b, sizeof b, "%s%.10g", k ? "," : "", nums[k]);
      jl.text += b;
    }
    jl.text += ";";
    if (mn == "IN") {
      down = false;
      absolute = true;
      x = y = 0;
    } else if (mn == "PU" || mn == "PD" || mn == "PA" || mn == "PR") {
      if (mn == "PU") down = false;
      if (mn == "PD") down = true;
      if (mn == "PA") absolute = true;
      if (mn == "PR") absolute = false;
      for (size_t k = 0; k + 1 < nums.size(); k += 2) {
        double nx = absolute ? nums[k] : x + nums[k];
        double ny = absolute ? nums[k + 1] : y + nums[k + 1];
        jl.est_s += std::hypot(nx - x, ny - y) / speed_pu_s;
        x = nx;
        y = ny;
        jl.motion = true;
      }
    } else if (mn == "VS" && !nums.empty() && nums[0] > 0) {
      speed_pu_s = nums[0] * 400;  // cm/s at 40 units/mm
    }
    jl.pen_down = down;
    jl.x = x;
    jl.y = y;
    job.est_total_s += jl.est_s;
    job.lines.push_back(std::move(jl));
  }
  return job;
}

// ---- segments -------------------------------------------------------------------

namespace {
// Pen-down moves and pen touches (down and up again without moving) of a job.
struct SegmentTracer {
  std::vector<Segment> out;
  bool down = false, moved = false;
  double x = 0, y = 0;
  int pen_no = 1;
  void pen(bool d) {
    if (down && !d && !moved) out.push_back({x, y, x, y, pen_no});
    if (d && !down) moved = false;
    down = d;
  }
  void move(double nx, double ny) {
    if (down && (nx != x || ny != y)) {
      out.push_back({x, y, nx, ny, pen_no});
      moved = true;
    }
    x = nx;
    y = ny;
  }
};
}  // namespace

std::vector<Segment> job_segments(const Job& job) {
  if (job.dialect == Dialect::GCode) {
    SegmentTracer t;
    for (const auto& l : job.lines) {
      // G-code changes the pen in its own lines (M3/M5 or a Z move), so a line either
      // moves in XY with the pen as it was or changes the pen.
      if (l.motion) t.move(l.x, l.y);
      t.pen(l.pen_down);
    }
    t.pen(false);
    return t.out;
  }
  // HPGL: replay each instruction (PU/PD x,y lists set the pen first, then move).
  SegmentTracer t;
  bool absolute = true;
  for (const auto& l : job.lines) {
    const std::string& s = l.text;
    if (s.size() < 2 || s[0] == 0x1b) continue;
    std::string mn = s.substr(0, 2);
    if (mn == "IN") {
      t.pen(false);
      t.x = t.y = 0;
      absolute = true;
      continue;
    }
    std::vector<double> nums;
    {
      std::string p = s.substr(2);
      if (!p.empty() && p.back() == ';') p.pop_back();
      std::stringstream ss(p);
      std::string tok;
      while (std::getline(ss, tok, ',')) if (!tok.empty()) nums.push_back(std::strtod(tok.c_str(), nullptr));
    }
    if (mn == "SP") {  // a pen change lifts the pen
      t.pen(false);
      t.pen_no = nums.empty() ? 0 : static_cast<int>(nums[0]);
      continue;
    }
    if (mn == "PU") t.pen(false);
    if (mn == "PD") t.pen(true);
    if (mn == "PA") absolute = true;
    if (mn == "PR") absolute = false;
    if (mn == "PU" || mn == "PD" || mn == "PA" || mn == "PR")
      for (size_t k = 0; k + 1 < nums.size(); k += 2)
        t.move(absolute ? nums[k] : t.x + nums[k], absolute ? nums[k + 1] : t.y + nums[k + 1]);
  }
  t.pen(false);
  return t.out;
}

// ---- resume ---------------------------------------------------------------------

namespace {
bool is_gcode_pen_line(const std::string& text) {
  bool xy = false, z = false, pen = false;
  for (const Word& w : gcode_words(text)) {
    if (w.letter == 'X' || w.letter == 'Y') xy = true;
    if (w.letter == 'Z') z = true;
    if (w.letter == 'S') pen = true;
    if (w.letter == 'M' && (std::lround(w.value) == 3 || std::lround(w.value) == 4 || std::lround(w.value) == 5))
      pen = true;
  }
  return pen || (z && !xy);
}
bool is_dwell_line(const std::string& text) {
  for (const Word& w : gcode_words(text))
    if (w.letter == 'G' && std::lround(w.value * 10) == 40) return true;
  return false;
}
}  // namespace

ResumePlan plan_resume(const Job& job, size_t next, const DevicePen& device) {
  ResumePlan rp;
  const auto& L = job.lines;
  next = std::min(next, L.size());
  auto down_at = [&](size_t k) { return k == 0 ? false : L[k - 1].pen_down; };  // pen state before line k
  bool in_place = device.known && next > 0 && device.down == down_at(next) &&
                  std::abs(device.x - L[next - 1].x) < 0.01 && std::abs(device.y - L[next - 1].y) < 0.01;
  if (in_place && job.dialect == Dialect::GCode) {
    // Pen already as it was: only the modal state needs restoring.
    ResumePlan full = plan_resume(job, next);
    rp.next = next;
    for (const auto& l : full.preamble)
      if (l == "G21" || l == "G90" || l == "G20" || l == "G0" || l.rfind("G1 F", 0) == 0) rp.preamble.push_back(l);
    return rp;
  }
  // A resume point right after the pen went down, before it moved: for a dot, the
  // dot is finished by the lift (skip to after its pen-up); for a stroke, start the
  // stroke again from its pen-down line.
  if (down_at(next)) {
    size_t d = next;
    while (d > 0 && L[d - 1].pen_down) --d;  // L[d] is the line that put the pen down
    bool moved = false;
    for (size_t k = d + 1; k < next; ++k) moved |= L[k].motion;
    if (L[d].motion && job.dialect == Dialect::Hpgl) moved = true;  // PD x,y moves as it lands
    if (!moved) {
      size_t u = next;
      bool moves_ahead = false;
      while (u < L.size() && L[u].pen_down) moves_ahead |= L[u++].motion;
      if (u < L.size()) moves_ahead |= L[u].motion && job.dialect == Dialect::Hpgl;
      next = moves_ahead ? d : std::min(u + 1, L.size());
    }
  }
  rp.next = next;
  bool down = down_at(next);
  double x = next ? L[next - 1].x : 0, y = next ? L[next - 1].y : 0;
  char buf[128];
  if (job.dialect == Dialect::GCode) {
    // Modal state at the resume point, and the job's own pen commands.
    GcodeState st;
    long pen_up = -1, pen_down = -1;
    for (size_t k = 0; k < L.size(); ++k) {
      if (is_gcode_pen_line(L[k].text)) {
        if (L[k].pen_down && (k < next || pen_down < 0)) pen_down = static_cast<long>(k);
        if (!L[k].pen_down && (k < next || pen_up < 0)) pen_up = static_cast<long>(k);
      }
      if (k >= next) continue;
      for (const Word& w : gcode_words(L[k].text)) {
        if (w.letter == 'G') {
          int g = static_cast<int>(std::lround(w.value * 10));
          if (g == 0 || g == 10) st.motion = g / 10;
          if (g == 200) st.scale = 25.4;
          if (g == 210) st.scale = 1;
          if (g == 900) st.absolute = true;
          if (g == 910) st.absolute = false;
        }
        if (w.letter == 'F') st.feed = w.value;
      }
    }
    if (!st.absolute) throw UserError("cannot resume: the job is in relative mode (G91) at line " + std::to_string(next + 1));
    auto with_dwell = [&](long k) {
      if (k < 0) return;
      rp.preamble.push_back(L[static_cast<size_t>(k)].text);
      if (static_cast<size_t>(k) + 1 < L.size() && is_dwell_line(L[static_cast<size_t>(k) + 1].text))
        rp.preamble.push_back(L[static_cast<size_t>(k) + 1].text);
    };
    rp.preamble.push_back("G21");
    rp.preamble.push_back("G90");
    if (pen_up < 0) throw UserError("cannot resume: the job never lifts the pen, so there is no pen-up command to use");
    with_dwell(pen_up);
    std::snprintf(buf, sizeof buf, "G0 X%.4f Y%.4f", x, y);
    rp.preamble.push_back(buf);
    if (down) with_dwell(pen_down);
    if (st.scale != 1) rp.preamble.push_back("G20");
    if (st.motion == 1 && st.feed > 0) {
      std::snprintf(buf, sizeof buf, "G1 F%.4g", st.feed);
      rp.preamble.push_back(buf);
    } else if (st.motion == 0) {
      rp.preamble.push_back("G0");
    }
  } else {
    std::string sp, vs;
    for (size_t k = 0; k < next; ++k) {
      if (L[k].text.rfind("SP", 0) == 0) sp = L[k].text;
      if (L[k].text.rfind("VS", 0) == 0) vs = L[k].text;
    }
    rp.preamble.push_back("PU;");
    if (!sp.empty()) rp.preamble.push_back(sp);
    if (!vs.empty()) rp.preamble.push_back(vs);
    std::snprintf(buf, sizeof buf, "PA;PU%.10g,%.10g;", x, y);
    rp.preamble.push_back(buf);
    if (down) rp.preamble.push_back("PD;");
  }
  return rp;
}

// ---- journal --------------------------------------------------------------------

namespace {
int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

Journal::Journal(std::string path, const JournalHeader& h, bool append, int sync_interval_ms)
    : path_(std::move(path)), sync_ms_(sync_interval_ms) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (append ? O_APPEND : O_TRUNC), 0644);
  if (fd_ < 0) throw UserError("cannot write the journal " + path_ + ": " + std::strerror(errno));
  if (append) {
    JournalState st = load(path_);
    last_ = last_written_ = st.last_acked;
    append_record("session resume", true);
  } else {
    nlohmann::json j = {{"stipplot_journal", 1},   {"job", h.job_path}, {"hash", h.job_hash},
                        {"dialect", h.dialect},    {"profile", h.profile}, {"port", h.port},
                        {"lines", h.total_lines}};
    append_record(j.dump(), true);
  }
}

Journal::~Journal() {
  try {
    sync();
  } catch (...) {
  }
  if (fd_ >= 0) ::close(fd_);
}

void Journal::append_record(const std::string& rec, bool force_sync) {
  std::string line = rec + "\n";
  const char* p = line.data();
  size_t left = line.size();
  while (left) {
    ssize_t w = ::write(fd_, p, left);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw UserError("cannot write the journal " + path_ + ": " + std::strerror(errno));
    }
    p += w;
    left -= static_cast<size_t>(w);
  }
  int64_t t = now_ns();
  if (force_sync || t - last_sync_ns_ >= int64_t(sync_ms_) * 1000000) {
    ::fdatasync(fd_);
    last_sync_ns_ = t;
  }
}

void Journal::ack(size_t line) {
  last_ = static_cast<long>(line);
  if (now_ns() - last_sync_ns_ >= int64_t(sync_ms_) * 1000000) {
    append_record("ack " + std::to_string(last_), false);
    last_written_ = last_;
  }
}

void Journal::rollback_to(long line) {
  last_ = line;
  append_record("ack " + std::to_string(last_), true);
  last_written_ = last_;
}

void Journal::sync() {
  if (fd_ < 0) return;
  if (last_ != last_written_) {
    append_record("ack " + std::to_string(last_), true);
    last_written_ = last_;
  } else {
    ::fdatasync(fd_);
  }
}

void Journal::done() {
  sync();
  append_record("done", true);
}

JournalState Journal::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw UserError("no journal " + path + " (was the job started with stipplot plot?)");
  JournalState st;
  std::string line;
  if (!std::getline(in, line)) throw UserError("journal " + path + " is empty");
  try {
    auto j = nlohmann::json::parse(line);
    st.header.job_path = j.at("job").get<std::string>();
    st.header.job_hash = j.at("hash").get<std::string>();
    st.header.dialect = j.at("dialect").get<std::string>();
    st.header.profile = j.value("profile", "");
    st.header.port = j.value("port", "");
    st.header.total_lines = j.at("lines").get<size_t>();
  } catch (const std::exception& e) {
    throw UserError("journal " + path + " has a malformed header: " + e.what());
  }
  while (std::getline(in, line)) {
    if (line.rfind("ack ", 0) == 0) {
      char* end = nullptr;
      long v = std::strtol(line.c_str() + 4, &end, 10);
      if (end && *end == '\0') st.last_acked = v;  // a torn last record is ignored
    } else if (line == "done") {
      st.complete = true;
    }
  }
  return st;
}

}  // namespace stipplot::io
