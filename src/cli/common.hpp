#pragma once
// What the commands share: the page options (method commands and eval), the --json /
// --quiet report, output kinds by extension, and planning a drawing into a device file
// (method commands with -o x.gcode, export, plot).
#include <CLI/CLI.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cli/pen_heights.hpp"
#include "cli/plan_options.hpp"
#include "drivers/device/profile.hpp"
#include "geometry/drawing.hpp"
#include "methods/placement.hpp"

namespace stipplot::cli {

// --page, --margin, --landscape, --pen-width, --dot-size; lengths in the grammar of
// util/units.hpp (bare numbers are mm; --dot-size also takes input pixels, "1.5px").
struct PlacementArgs {
  std::string page = "A4";
  std::string margin = "10";
  bool landscape = false;
  std::string pen_width = "0.3";
  std::string dot_size = "0mm";
  Placement resolve() const;  // throws UserError naming the option
};
void add_placement_options(CLI::App* cmd, PlacementArgs& a);

// --json: the summary as one JSON line; -q/--quiet: nothing on success; else a sentence.
struct ReportArgs {
  bool json = false;
  bool quiet = false;
  void print(const nlohmann::json& summary, const std::string& sentence) const;
};
void add_report_options(CLI::App* cmd, ReportArgs& a);

// Case-insensitive: has_extension("A.PNG", ".png").
bool has_extension(const std::string& path, const char* ext);
// An extra output that must be a PNG in an existing directory; checked before any work.
void require_png_path(const std::string& option, const std::string& path);

// Output kinds by extension: a Drawing as SVG, or planned for a device as G-code/HPGL
// (or, for export, the planned order as SVG).
enum class OutputKind { svg, gcode, hpgl, ebb };
// By extension, case-insensitive (.svg; .gcode .nc .ngc .gc .g; .hpgl .plt .hpg .hgl);
// nullopt for anything else. The one list both writing (-o) and plotting use.
std::optional<OutputKind> kind_of_file(const std::string& path);
// Like kind_of_file, but an unknown extension is a UserError naming `option`.
OutputKind output_kind(const std::string& path, const std::string& option = "-o");
// Checked before any work: a .gcode output needs a grbl profile, .hpgl an HPGL one.
void check_profile_for(OutputKind kind, const std::string& path, const std::string& profile_name);

// Plans the drawing with the profile's motion limits, writes G-code, HPGL or the planned
// SVG (by the extension of `path`) atomically, and adds the profile, the plan's statistics
// (pen-down/up length, lifts, estimated time) and the timings to `summary`. The plan
// written is returned: what a pen-true preview of the output renders. `heights` override
// an EBB profile's pen heights.
Plan write_planned_output(const Drawing& d, const std::string& path, const std::string& profile,
                          const PlanArgs& plan_args, bool show_travel, nlohmann::json& summary,
                          const PenHeightArgs& heights = {});
// The same for a drawing given up: its primitives are freed as the plan takes them.
Plan write_planned_output(Drawing&& d, const std::string& path, const std::string& profile,
                          const PlanArgs& plan_args, bool show_travel, nlohmann::json& summary,
                          const PenHeightArgs& heights = {});

// The planner's options for a profile: the pen starts at machine zero, so planning
// starts from there (in page coordinates).
PlanOptions plan_options_for(const DeviceProfile& profile, const Page& page, const PlanArgs& plan_args);
// Writes an already planned drawing as G-code, HPGL or the planned SVG by the extension
// of `path`, atomically.
// plan_summary, when given, gets the written job's own timed seconds (G-code and HPGL).
void write_plan_file(const Plan& plan, const std::string& path, const DeviceProfile& profile, bool show_travel,
                     nlohmann::json* plan_summary = nullptr);
// The job `profile` would get for `plan`, timed from its lines as write_plan_file times a
// written one (the link's pace included) without writing it: plan_summary's total and
// layer seconds and stops. O(points).
void time_as_job(const Plan& plan, const DeviceProfile& profile, nlohmann::json& plan_summary);
// Whether the link could hold a plan's job back: its lines (about a point each) come
// faster than a quarter of what the profile's serial link carries at 20 bytes a line
// (a 12-MP tree's 900,000 points in an hour; not a stipple's). O(strokes).
bool link_may_bind(const Plan& plan, double plan_seconds, const DeviceProfile& profile);

// "1 layer", "3 layers".
std::string layers_phrase(size_t n);
// "297 x 210 mm".
std::string sheet_phrase(const Page& page);

double seconds_since(std::chrono::steady_clock::time_point t0);

}  // namespace stipplot::cli
