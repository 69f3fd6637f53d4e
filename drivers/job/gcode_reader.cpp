#include "drivers/job/gcode_reader.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::io {

namespace {

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

// The comment text of a raw line: what is inside ( ) and after ';'.
std::string comment_text(const std::string& raw) {
  std::string out;
  bool paren = false;
  for (size_t i = 0; i < raw.size(); ++i) {
    const char c = raw[i];
    if (paren) {
      if (c == ')') paren = false;
      else out.push_back(c);
      continue;
    }
    if (c == '(') paren = true;
    else if (c == ';') {
      out.append(raw, i + 1, std::string::npos);
      break;
    }
  }
  while (!out.empty() && (out.back() == '\r' || out.back() == ' ')) out.pop_back();
  size_t b = out.find_first_not_of(' ');
  return b == std::string::npos ? std::string() : out.substr(b);
}

// A layer comment as the G-code writer writes it: "layer 2 pen red (#ff0000)".
bool is_layer_comment(const std::string& c) { return c.rfind("layer ", 0) == 0 && c.find(" pen ") != std::string::npos; }

int g_code_x10(double value) { return static_cast<int>(std::lround(value * 10)); }  // G0.1 steps: G4 = 40

// Where the tool is and what the spindle does, as the program has set them so far.
struct ToolState {
  // Z is unknown until the job sets it; until then the pen counts as up (a Z plotter
  // whose "down" height is 0 must not read as down before its first Z move).
  double x = 0, y = 0, z = std::numeric_limits<double>::infinity();
  double feed = 0;  // mm/min
  bool spindle = false;
  double s = 0;
};

}  // namespace

std::string_view gcode_line_view(std::string_view raw, std::string& scratch) {
  if (raw.find_first_of("(;\r") != std::string_view::npos) {
    scratch = clean_gcode_line(std::string(raw));
    return scratch;
  }
  const size_t b = raw.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  return raw.substr(b, raw.find_last_not_of(" \t") - b + 1);
}

namespace detail {

double gcode_number(std::string_view digits) {
  // Blanks inside a number are dropped (grbl reads "X1 2.5" as X12.5): rare, copied.
  if (digits.find(' ') != std::string_view::npos) {
    std::string packed;
    for (char c : digits)
      if (c != ' ') packed.push_back(c);
    return packed.empty() ? 0.0 : std::strtod(packed.c_str(), nullptr);
  }
  double v = 0;
  if (short_decimal(digits, v)) return v;  // most numbers: exact without strtod
  return digits.empty() ? 0.0 : std::strtod(std::string(digits).c_str(), nullptr);  // anything else as strtod reads it
}

bool gcode_word_scan(std::string_view line, size_t& i, GcodeWord& w) {
  while (i < line.size()) {
    const char c = line[i] >= 'a' && line[i] <= 'z' ? static_cast<char>(line[i] - 'a' + 'A') : line[i];
    if (c == ' ' || c == '\t') {
      ++i;
      continue;
    }
    ++i;
    const size_t start = i;
    while (i < line.size() && (std::isdigit(static_cast<unsigned char>(line[i])) || line[i] == '.' ||
                               line[i] == '-' || line[i] == '+' || line[i] == ' '))
      ++i;
    w = {c, gcode_number(line.substr(start, i - start))};
    return true;
  }
  return false;
}

}  // namespace detail

std::vector<GcodeWord> gcode_words(std::string_view line) {
  std::vector<GcodeWord> w;
  for_each_gcode_word(line, [&](const GcodeWord& word) { w.push_back(word); });
  return w;
}

bool is_dwell(const GcodeWord& w) { return w.letter == 'G' && g_code_x10(w.value) == 40; }

bool GcodeModes::apply(const GcodeWord& w) {
  if (w.letter != 'G') return false;
  const int g = g_code_x10(w.value);
  if (g == 0 || g == 10) motion = g / 10;
  else if (g == 200) scale = 25.4;
  else if (g == 210) scale = 1;
  else if (g == 900) absolute = true;
  else if (g == 910) absolute = false;
  else return false;
  return true;
}

bool gcode_pen_down(bool spindle_on, double s, double z, const GcodePenRule& rule) {
  bool servo_down = spindle_on && s > 0 && !(rule.servo_up_s > 0 && std::abs(s - rule.servo_up_s) < 1e-9);
  return servo_down || z < rule.z_down_below;
}

Job parse_gcode_job(const std::string& text, const GcodePenRule& rule) {
  Job job;
  job.dialect = Dialect::GCode;
  GcodeModes modes;
  ToolState st;
  std::istringstream in(text);
  std::string raw;
  constexpr double rapid_mm_s = 100;
  std::string pending_label;
  while (std::getline(in, raw)) {
    std::string line = clean_gcode_line(raw);
    const std::string comment = comment_text(raw);
    if (line.empty()) {
      if (is_layer_comment(comment)) pending_label = comment;
      continue;
    }
    JobLine jl;
    jl.text = line;
    if (!pending_label.empty()) {
      job.pens.push_back({job.lines.size(), pending_label});
      pending_label.clear();
    }
    double nx = st.x, ny = st.y, nz = st.z;
    bool axis = false, z_word = false;
    double dwell = 0;
    bool is_dwell_line = false;
    for (const GcodeWord& w : gcode_words(line)) {
      switch (w.letter) {
        case 'G':
          if (!modes.apply(w) && is_dwell(w)) is_dwell_line = true;
          break;
        case 'M': {
          int m = static_cast<int>(std::lround(w.value));
          if (m == 3 || m == 4) st.spindle = true;
          if (m == 5 || m == 2 || m == 30) st.spindle = false;
          if (m == 0 || m == 1) {
            // grbl holds at M0 until cycle start: the host asks the operator (a pen change).
            jl.pause = true;
            jl.note = comment.rfind("MSG,", 0) == 0 ? comment.substr(4) : comment;
            if (jl.note.empty()) jl.note = "program pause (M" + std::to_string(m) + ")";
          }
          break;
        }
        case 'S': st.s = w.value; break;
        case 'F': st.feed = w.value * modes.scale; break;
        case 'P': dwell = w.value; break;
        case 'X': nx = modes.absolute ? w.value * modes.scale : st.x + w.value * modes.scale; axis = true; break;
        case 'Y': ny = modes.absolute ? w.value * modes.scale : st.y + w.value * modes.scale; axis = true; break;
        case 'Z':
          nz = modes.absolute || !std::isfinite(st.z) ? w.value * modes.scale : st.z + w.value * modes.scale;
          axis = z_word = true;
          break;
        default: break;
      }
    }
    // At the boundary: no number beyond any machine (1 km, a km a minute) or not finite.
    for (double v : {nx, ny, z_word ? nz : 0.0, st.feed, st.s, dwell})
      if (!(std::fabs(v) <= 1e6))
        throw UserError("G-code line " + std::to_string(job.lines.size() + 1) + " `" + line +
                        "`: a coordinate, feed, S or dwell is not finite or beyond +-1000000 (mm, mm/min, s)");
    if (axis && !is_dwell_line) {
      double dz = std::isfinite(st.z) && std::isfinite(nz) ? nz - st.z : 0;
      double d = std::hypot(nx - st.x, ny - st.y, dz);
      double v = modes.motion == 0 || st.feed <= 0 ? rapid_mm_s : st.feed / 60.0;
      jl.est_s = d / v;
      jl.motion = true;
      st.x = nx;
      st.y = ny;
      st.z = nz;
    }
    if (is_dwell_line) jl.est_s = dwell;
    jl.x = st.x;
    jl.y = st.y;
    jl.pen_down = gcode_pen_down(st.spindle, st.s, st.z, rule);
    if (jl.pause && comment.rfind("MSG,", 0) == 0) job.pens.push_back({job.lines.size(), jl.note});
    job.est_total_s += jl.est_s;
    job.lines.push_back(std::move(jl));
  }
  return job;
}

}  // namespace stipplot::io
