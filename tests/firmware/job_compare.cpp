#include "firmware/job_compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

namespace firmware {

namespace {

using Key = std::tuple<int, long, long, long, long>;

Key key_of(const Mark& m) {
  if (m.kind == Mark::Kind::Dot) return {1, m.a.x, m.a.y, m.a.x, m.a.y};
  auto p = std::make_pair(m.a.x, m.a.y), q = std::make_pair(m.b.x, m.b.y);
  if (q < p) std::swap(p, q);
  return {0, p.first, p.second, q.first, q.second};
}

}  // namespace

MarkComparison compare_marks(const std::vector<Mark>& expected, const std::vector<Mark>& drawn) {
  MarkComparison c;
  std::map<Key, std::pair<std::vector<const Mark*>, size_t>> m;  // expected marks, times drawn
  for (const Mark& e : expected) {
    (e.kind == Mark::Kind::Dot ? c.expected_dots : c.expected_segments)++;
    m[key_of(e)].first.push_back(&e);
  }
  for (const Mark& d : drawn) {
    if (d.kind == Mark::Kind::Partial) {
      ++c.partial;
      continue;
    }
    (d.kind == Mark::Kind::Dot ? c.drawn_dots : c.drawn_segments)++;
    auto it = m.find(key_of(d));
    if (it == m.end()) {
      ++c.extra;
      c.extra_marks.push_back(d);
    } else {
      ++it->second.second;
    }
  }
  for (const auto& [k, v] : m) {
    const size_t want = v.first.size(), got = v.second;
    for (size_t i = got; i < want; ++i) c.lost_marks.push_back(*v.first[i]);
    for (size_t i = want; i < got; ++i) c.doubled_marks.push_back(*v.first[0]);
  }
  c.lost = c.lost_marks.size();
  c.doubled = c.doubled_marks.size();
  return c;
}

std::vector<Mark> bare_on_paper(const std::vector<Mark>& lost, const std::vector<Mark>& drawn, double tol) {
  std::vector<Mark> bare;
  for (const Mark& m : lost) {
    const double ax = static_cast<double>(m.a.x), ay = static_cast<double>(m.a.y);
    const double dx = static_cast<double>(m.b.x) - ax, dy = static_cast<double>(m.b.y) - ay, len = std::hypot(dx, dy);
    if (m.kind == Mark::Kind::Dot || len == 0) {
      bare.push_back(m);
      continue;
    }
    // A point's place along the mark, and its distance from the mark's line, in steps.
    auto along = [&](const Steps& p) { return ((static_cast<double>(p.x) - ax) * dx + (static_cast<double>(p.y) - ay) * dy) / len; };
    auto off = [&](const Steps& p) { return std::abs((static_cast<double>(p.x) - ax) * dy - (static_cast<double>(p.y) - ay) * dx) / len; };
    std::vector<std::pair<double, double>> spans;
    for (const Mark& d : drawn) {
      if (d.kind == Mark::Kind::Dot || off(d.a) > tol || off(d.b) > tol) continue;
      const double u = along(d.a), v = along(d.b);
      spans.emplace_back(std::min(u, v), std::max(u, v));
    }
    std::sort(spans.begin(), spans.end());
    double reached = 0;  // covered from the mark's start up to here
    for (const auto& [from, to] : spans)
      if (from <= reached + tol) reached = std::max(reached, to);
    if (reached < len - tol) bare.push_back(m);
  }
  return bare;
}

std::string MarkComparison::summary() const {
  char b[256];
  std::snprintf(b, sizeof b,
                "expected %zu segments + %zu dots, drawn %zu + %zu; lost %zu, doubled %zu, extra %zu, partial %zu",
                expected_segments, expected_dots, drawn_segments, drawn_dots, lost, doubled, extra, partial);
  return b;
}

JobCheck check_job(const std::string& gcode, const FirmwareRecord& r, const PenRule& rule,
                   const std::vector<Steps>& offsets) {
  JobCheck j;
  j.firmware = interpret(r, rule, offsets);
  j.marks = compare_marks(expected_marks(gcode, r.settings, rule), j.firmware.marks);
  return j;
}

std::string describe(const Mark& m, const MachineSettings& s) {
  char b[160];
  const double kx = s.steps_per_mm[0], ky = s.steps_per_mm[1];
  if (m.kind == Mark::Kind::Dot)
    std::snprintf(b, sizeof b, "dot %.2f,%.2f mm", m.a.x / kx, m.a.y / ky);
  else
    std::snprintf(b, sizeof b, "%s %.2f,%.2f - %.2f,%.2f mm", m.kind == Mark::Kind::Partial ? "partial" : "segment",
                  m.a.x / kx, m.a.y / ky, m.b.x / kx, m.b.y / ky);
  return b;
}

std::string explain(const JobCheck& j, const MachineSettings& s) {
  std::string out;
  for (const auto& i : j.firmware.inconsistencies) out += "\n" + i;
  for (const Mark& m : j.marks.lost_marks) out += "\nlost " + describe(m, s);
  for (const Mark& m : j.marks.extra_marks) out += "\nextra " + describe(m, s);
  return out;
}

}  // namespace firmware
