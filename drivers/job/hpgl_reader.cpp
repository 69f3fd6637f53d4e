#include "drivers/job/hpgl_reader.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "util/error.hpp"

namespace stipplot::io {

std::vector<double> hpgl_numbers(std::string_view params) {
  std::vector<double> nums;
  std::string cur;
  auto flush = [&] {
    if (!cur.empty()) nums.push_back(std::strtod(cur.c_str(), nullptr));
    cur.clear();
  };
  for (char c : params) {
    if (c == ',' || c == ';' || c == ' ' || c == '\n' || c == '\r' || c == '\t') flush();
    else if ((c == '-' || c == '+') && !cur.empty()) {
      flush();
      cur.push_back(c);
    } else cur.push_back(c);
  }
  flush();
  return nums;
}

namespace {
constexpr std::string_view kPausePrefix = "CO\"stipplot pause: ";
}  // namespace

std::string hpgl_pause_instruction(const std::string& message) {
  std::string m = message;
  for (char& c : m)
    if (c == '"' || c == ';' || c == '\n' || c == '\r') c = ' ';
  return std::string(kPausePrefix) + m + "\";";
}

std::optional<std::string> hpgl_pause_message(std::string_view instruction) {
  if (instruction.substr(0, kPausePrefix.size()) != kPausePrefix) return std::nullopt;
  std::string_view rest = instruction.substr(kPausePrefix.size());
  const size_t close = rest.find('"');
  if (close == std::string_view::npos) return std::nullopt;
  return std::string(rest.substr(0, close));
}

namespace {

bool is_alpha(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; }

// Walks the text one instruction at a time, keeping the pen and position the plotter
// would have after each.
class HpglReader {
 public:
  explicit HpglReader(const std::string& text) : text_(text) {}

  Job read() {
    Job job;
    job.dialect = Dialect::Hpgl;
    while (true) {
      skip_separators();
      if (i_ >= text_.size()) break;
      JobLine line = text_[i_] == 0x1b ? device_control() : instruction();
      job.est_total_s += line.est_s;
      if (line.text.rfind("SP", 0) == 0) {
        const std::vector<double> n = hpgl_numbers(std::string_view(line.text).substr(2));
        if (!n.empty() && n[0] > 0) job.pens.push_back({job.lines.size(), "pen " + std::to_string(static_cast<int>(n[0]))});
      }
      job.lines.push_back(std::move(line));
    }
    return job;
  }

 private:
  void skip_separators() {
    while (i_ < text_.size() &&
           (text_[i_] == ' ' || text_[i_] == '\n' || text_[i_] == '\r' || text_[i_] == '\t' || text_[i_] == ';'))
      ++i_;
  }

  JobLine passed_through(size_t start) const {
    JobLine jl;
    jl.text = text_.substr(start, i_ - start);
    jl.pen_down = down_;
    jl.x = x_;
    jl.y = y_;
    return jl;
  }

  // ESC . x [params] terminator: passed through as its own "line". An ESC that starts no
  // complete device-control instruction would leave the plotter waiting for the rest.
  JobLine device_control() {
    const size_t start = i_;
    if (i_ + 2 >= text_.size() || text_[i_ + 1] != '.')
      throw UserError("HPGL: the ESC at byte " + std::to_string(i_) +
                      " starts no device-control instruction (ESC . letter); the plotter would wait for the rest");
    i_ += 2;
    while (i_ < text_.size() && !(is_alpha(text_[i_]) || text_[i_] == ':')) ++i_;
    if (i_ >= text_.size())
      throw UserError("HPGL: the device-control instruction at byte " + std::to_string(start) + " has no terminator");
    ++i_;
    return passed_through(start);
  }

  // CO"text": a comment for the host. stipplot's reload pauses are written as
  // CO"stipplot pause: load pen ..."; none is sent (HP-GL plotters before HP-GL/2 reject CO).
  JobLine comment(size_t start) {
    while (i_ < text_.size() && text_[i_] == ' ') ++i_;
    if (i_ < text_.size() && text_[i_] == '"') {
      const size_t close = text_.find('"', i_ + 1);
      if (close == std::string::npos)
        throw UserError("HPGL: the comment CO at byte " + std::to_string(start) + " has no closing quote");
      i_ = close + 1;
    }
    while (i_ < text_.size() && text_[i_] != ';' && !is_alpha(text_[i_])) ++i_;
    if (i_ < text_.size() && text_[i_] == ';') ++i_;
    JobLine jl = passed_through(start);
    jl.host_only = true;
    if (std::optional<std::string> m = hpgl_pause_message(jl.text)) {
      jl.pause = true;
      jl.note = *m;
    }
    return jl;
  }

  JobLine instruction() {
    const size_t n = text_.size();
    if (i_ + 1 >= n || !is_alpha(text_[i_]) || !is_alpha(text_[i_ + 1]))
      throw UserError("HPGL: expected a two-letter instruction at byte " + std::to_string(i_));
    const std::string mn = {static_cast<char>(std::toupper(static_cast<unsigned char>(text_[i_]))),
                            static_cast<char>(std::toupper(static_cast<unsigned char>(text_[i_ + 1])))};
    const size_t start = i_;
    i_ += 2;
    if (mn == "LB") {  // a label runs to ETX, whatever it holds
      while (i_ < n && text_[i_] != 0x03) ++i_;
      if (i_ >= n)
        throw UserError("HPGL: the label LB at byte " + std::to_string(start) +
                        " has no terminator (ETX, 0x03); the plotter would take everything after it as text");
      ++i_;
      return passed_through(start);
    }
    if (mn == "CO") return comment(start);
    const size_t params = i_;
    while (i_ < n && text_[i_] != ';' && !is_alpha(text_[i_]) && text_[i_] != 0x1b) ++i_;
    const std::vector<double> nums = hpgl_numbers(std::string_view(text_).substr(params, i_ - params));
    if (i_ < n && text_[i_] == ';') ++i_;
    return execute(mn, nums);
  }

  // The instruction in a normal form (MN n,n,...;) and what it does to the pen.
  JobLine execute(const std::string& mn, const std::vector<double>& nums) {
    // At the boundary: no number beyond any plotter (1 km at 40 units a mm) or not finite.
    for (double v : nums)
      if (!(std::fabs(v) <= 4e7))
        throw UserError("HPGL: " + mn + " has a number that is not finite or beyond +-40000000 plotter units (1 km)");
    JobLine jl;
    jl.text = mn;
    for (size_t k = 0; k < nums.size(); ++k) {
      char b[32];
      std::snprintf(b, sizeof b, "%s%.10g", k ? "," : "", nums[k]);
      jl.text += b;
    }
    jl.text += ";";
    if (mn == "IN") {
      down_ = false;
      absolute_ = true;
      x_ = y_ = 0;
    } else if (mn == "PU" || mn == "PD" || mn == "PA" || mn == "PR") {
      if (mn == "PU") down_ = false;
      if (mn == "PD") down_ = true;
      if (mn == "PA") absolute_ = true;
      if (mn == "PR") absolute_ = false;
      for (size_t k = 0; k + 1 < nums.size(); k += 2) {
        double nx = absolute_ ? nums[k] : x_ + nums[k];
        double ny = absolute_ ? nums[k + 1] : y_ + nums[k + 1];
        jl.est_s += std::hypot(nx - x_, ny - y_) / speed_pu_s_;
        x_ = nx;
        y_ = ny;
        jl.motion = true;
      }
    } else if (mn == "VS" && !nums.empty() && nums[0] > 0) {
      speed_pu_s_ = nums[0] * 400;  // cm/s at 40 units/mm
    }
    jl.pen_down = down_;
    jl.x = x_;
    jl.y = y_;
    return jl;
  }

  const std::string& text_;
  size_t i_ = 0;
  double x_ = 0, y_ = 0;
  bool down_ = false, absolute_ = true;
  double speed_pu_s_ = 400 * 38.1 / 10;  // 38.1 cm/s at 40 units/mm (HP 7475A default)
};

}  // namespace

Job parse_hpgl_job(const std::string& text) { return HpglReader(text).read(); }

}  // namespace stipplot::io
