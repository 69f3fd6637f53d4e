#include "drivers/job/ebb_reader.hpp"

#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "drivers/motion/ebb_motion.hpp"
#include "util/error.hpp"

namespace stipplot::io {

namespace {
constexpr const char* kPause = "# pause: ";
}

std::string ebb_pause_line(const std::string& note) { return kPause + note; }

std::optional<std::string> ebb_pause_note(std::string_view line) {
  const std::string_view p(kPause);
  if (line.substr(0, p.size()) == p) return std::string(line.substr(p.size()));
  return std::nullopt;
}

std::array<int64_t, 2> ebb_motor_steps(double x, double y, double spm) {
  return {std::llround(spm * (x + y)), std::llround(spm * (x - y))};
}

std::string ebb_command_name(std::string_view text) {
  std::string n;
  for (char ch : text.substr(0, text.find(','))) n += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return n;
}

bool ebb_motion_command(std::string_view name) { return name == "SM" || name == "LM"; }

EbbCommand parse_ebb_command(std::string_view text, size_t line_no) {
  auto fail = [&](const std::string& why) -> EbbCommand {
    throw UserError("EBB job line " + std::to_string(line_no) + " `" + std::string(text) + "`: " + why);
  };
  EbbCommand c;
  const size_t comma = text.find(',');
  c.name = ebb_command_name(text);
  for (size_t i = comma; i != std::string_view::npos;) {
    const size_t next = text.find(',', i + 1);
    const std::string num(text.substr(i + 1, next == std::string_view::npos ? std::string_view::npos : next - i - 1));
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(num.c_str(), &end, 10);
    if (num.empty() || *end != '\0') return fail("'" + num + "' is not an integer");
    // No EBB argument comes near 2^40; past it the step sums below would overflow.
    if (errno == ERANGE || v > (1LL << 40) || v < -(1LL << 40)) return fail("'" + num + "' is out of range");
    c.args.push_back(v);
    i = next;
  }
  const size_t n = c.args.size();
  if (c.name == "SM") {
    if (n != 3) return fail("SM takes a duration and two step counts");
    c.ms = c.args[0], c.s1 = c.args[1], c.s2 = c.args[2];
    if (c.ms < 1 || c.ms > 16777215) return fail("an SM lasts 1 to 16777215 ms");
    if (std::llabs(c.s1) > 25 * c.ms || std::llabs(c.s2) > 25 * c.ms)
      return fail("steps faster than the firmware's 25 per ms");
    if (c.s1 == 0 && c.s2 == 0 && c.ms > 100000) return fail("a delay SM lasts at most 100000 ms");
    c.ticks = c.ms * 25;
  } else if (c.name == "LM") {
    if (n != 6 && n != 7) return fail("LM takes a rate, steps and accel for each motor, and an optional clear");
    motion::EbbMove m;
    m.lm = true;
    m.r1 = c.args[0], m.s1 = c.args[1], m.a1 = c.args[2], m.r2 = c.args[3], m.s2 = c.args[4], m.a2 = c.args[5];
    if (n == 7 && (c.args[6] < 0 || c.args[6] > 3)) return fail("an LM's clear is 0 to 3");
    if (!motion::lm_ok(m))
      return fail("an LM must move, within 32-bit terms, its rate in (0, 2^31) until its last step (not stalling or reversing)");
    c.s1 = m.s1, c.s2 = m.s2;
    c.ticks = motion::lm_ticks(m);
  } else if (c.name == "SP") {
    if (n < 1 || n > 3 || c.args[0] < 0 || c.args[0] > 1)
      return fail("SP takes 0 (down) or 1 (up), a delay and a pin");
    c.pen = static_cast<int>(c.args[0]);
    c.ms = n >= 2 ? c.args[1] : 0;
    if (c.ms < 0 || c.ms > 65535) return fail("an SP delay is 0 to 65535 ms");
    if (n == 3 && (c.args[2] < 0 || c.args[2] > 7)) return fail("an SP pin is 0 to 7 (port B)");
    c.ticks = c.ms * 25;
  } else if (c.name == "EM" || c.name == "SC" || c.name == "CU") {
    if (n < 1 || n > 2) return fail(c.name + " takes one or two numbers");
  } else {
    return fail("a job holds only SM, LM, SP, EM, SC and CU commands");
  }
  return c;
}

Job parse_ebb_job(const std::string& text, double spm) {
  Job job;
  job.dialect = Dialect::Ebb;
  int64_t m1 = 0, m2 = 0;
  bool down = false;
  size_t pos = 0, line_no = 0;
  while (pos < text.size()) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view l(text.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    while (!l.empty() && (l.back() == '\r' || l.back() == ' ')) l.remove_suffix(1);
    if (l.empty()) continue;
    JobLine jl;
    jl.text = std::string(l);
    if (l[0] == '#') {
      jl.host_only = true;
      if (auto note = ebb_pause_note(l)) {
        jl.pause = true;
        jl.note = *note;
        job.pens.push_back({job.lines.size(), *note});
      }
    } else {
      const EbbCommand c = parse_ebb_command(l, line_no);
      if (ebb_motion_command(c.name)) {
        m1 += c.s1, m2 += c.s2;
        jl.motion = c.s1 != 0 || c.s2 != 0;
      } else if (c.name == "SP") {
        down = c.pen == 0;
      } else if (c.name == "EM") {
        m1 = m2 = 0;  // the firmware zeroes its step counters
      }
    }
    jl.pen_down = down;
    jl.x = static_cast<double>(m1 + m2) / (2 * spm);
    jl.y = static_cast<double>(m1 - m2) / (2 * spm);
    job.lines.push_back(std::move(jl));
  }
  return job;
}

}  // namespace stipplot::io
