#pragma once
// A job against the firmware's record: the marks the job draws (every line once, see
// gcode_model.hpp) against the marks the firmware drew (see firmware_record.hpp), as
// counts of lost, doubled and extra marks.
#include <string>
#include <vector>

#include "firmware/firmware_record.hpp"

namespace firmware {

struct MarkComparison {
  size_t expected_segments = 0, expected_dots = 0;
  size_t drawn_segments = 0, drawn_dots = 0;  // complete marks the firmware drew
  size_t lost = 0;     // expected marks never drawn
  size_t doubled = 0;  // extra copies of expected marks (a mark drawn twice counts 1)
  size_t extra = 0;    // drawn marks the job does not have
  size_t partial = 0;  // moves cut short while the pen was down
  std::vector<Mark> lost_marks, doubled_marks, extra_marks;
  bool exact() const { return lost == 0 && doubled == 0 && extra == 0 && partial == 0; }
  std::string summary() const;  // "expected 12 segments + 30 dots; lost 0, doubled 0, extra 0, partial 0"
};

// Marks are matched as multisets: segments undirected by their XY end points, dots by
// XY. O(n log n).
MarkComparison compare_marks(const std::vector<Mark>& expected, const std::vector<Mark>& drawn);

// The lost segments that the drawn pieces leave bare on paper. A move cut short by a power
// loss and its rest drawn after the resume are two pieces, neither of which is the job's
// mark, yet together they draw it: a segment counts as drawn when pieces lying along it
// (both ends within `tol` steps of its line) cover it end to end, with gaps of at most
// `tol` steps. Lost dots stay lost. O(lost x drawn).
std::vector<Mark> bare_on_paper(const std::vector<Mark>& lost, const std::vector<Mark>& drawn, double tol = 2);

// The job file against everything the firmware drew in all its sessions.
struct JobCheck {
  MarkComparison marks;
  Interpretation firmware;
};
JobCheck check_job(const std::string& gcode, const FirmwareRecord& r, const PenRule& rule,
                   const std::vector<Steps>& offsets = {});

std::string describe(const Mark& m, const MachineSettings& s);  // "segment 10.00,5.00 - 12.00,5.00 mm"
// What a failed check should say, one line each: the firmware's inconsistencies, then the
// lost and the extra marks (for one INFO: an INFO in a loop's body ends with that pass).
std::string explain(const JobCheck& j, const MachineSettings& s);

}  // namespace firmware
