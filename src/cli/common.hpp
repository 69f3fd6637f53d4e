#pragma once
// Options shared by the method commands, so --page, --preview, --json ... mean the
// same everywhere, and the one output path every method's Drawing goes through.
#include <CLI/CLI.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/drawing.hpp"
#include "image/image.hpp"
#include "cli/plan_options.hpp"
#include "methods/placement.hpp"

namespace stipplot::cli {

struct PlacementArgs {
  std::string page = "A4";
  std::string margin = "10";
  bool landscape = false;
  std::string pen_width = "0.3";
  std::string dot_size = "0";
  Placement resolve() const;  // throws UserError
};
void add_placement_options(CLI::App* cmd, PlacementArgs& a);

struct OutputArgs {
  std::string input;
  std::string output;
  std::string profile = "grbl-servo";  // for .gcode/.hpgl outputs
  PlanArgs plan;                       // for .gcode/.hpgl outputs
  std::string preview;
  double preview_dpi = 150;
  bool json = false;
  bool quiet = false;
  uint64_t max_pixels = 100'000'000;
  // Checked before any work: output kinds known, directories writable.
  void validate() const;
};
// Adds IN (positional), -o, --profile, the planning options, --preview, --preview-dpi,
// --json, --quiet, --max-pixels.
void add_output_options(CLI::App* cmd, OutputArgs& a);

// Output kinds by extension: a Drawing as SVG, or planned for a device as G-code/HPGL
// (or, for export, the planned order as SVG).
enum class OutputKind { svg, gcode, hpgl };
OutputKind output_kind(const std::string& path, const std::string& option = "-o");

// Plans the drawing with the profile's motion limits, writes G-code, HPGL or the planned
// SVG (by the extension of `path`) atomically, and adds the profile, the plan's statistics
// (pen-down/up length, lifts, estimated time) and the timings to `summary`.
void write_planned_output(const Drawing& d, const std::string& path, const std::string& profile,
                          const PlanArgs& plan_args, bool show_travel, nlohmann::json& summary);

Image load_input(const OutputArgs& a);

// Writes the drawing to -o (by extension) and the preview; fills `summary` with what
// was written (layers, primitives, files). Every file is written atomically.
void write_outputs(const Drawing& d, const OutputArgs& a, nlohmann::json& summary);

// Prints the summary as one JSON line (--json) or a short human sentence.
void report(const OutputArgs& a, const nlohmann::json& summary, const std::string& human);

double seconds_since(std::chrono::steady_clock::time_point t0);

}  // namespace stipplot::cli
