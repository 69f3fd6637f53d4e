#pragma once
// Device profiles: what a writer or driver needs to know about one plotter, read from a
// TOML file (drivers/profiles/*.toml). Every key is required unless noted, and unknown
// keys are refused, so a typo never silently falls back to a default; errors name the
// file and the key.
#include <filesystem>
#include <string>
#include <vector>

#include "geometry/drawing.hpp"
#include "drivers/motion/motion_params.hpp"
#include "plan/plan.hpp"

namespace stipplot {

enum class Protocol { grbl, hpgl };
// Corner of the page at machine zero; coordinates grow away from it along each axis,
// times the axis sign (grbl machines homed to "negative space" use -1).
enum class Origin { top_left, bottom_left };
enum class PenMethod { servo, z_axis, laser, hpgl };
enum class FlowControl { none, xonxoff, rtscts };
// How the host avoids overrunning an HPGL plotter's buffer (for the streaming driver).
enum class HpglHandshake { none, xonxoff, hardware, buffer_query };

struct DeviceProfile {
  std::string name;         // profile name (the file's stem for shipped ones)
  std::string description;  // one line
  std::filesystem::path source;
  Protocol protocol = Protocol::grbl;

  // [machine] travel limits in machine coordinates (mm): x in [0, travel_x], y in [0, travel_y]
  // when both signs are +1; with a sign of -1 the range is [-travel, 0].
  double travel_x_mm = 0, travel_y_mm = 0;
  Origin origin = Origin::top_left;
  int x_sign = 1, y_sign = 1;
  // Where machine zero sits, measured from the page's origin corner into the page (mm).
  double origin_offset_x_mm = 0, origin_offset_y_mm = 0;
  double resolution_mm = 0.01;  // coordinates are rounded to this
  double units_per_mm = 1;      // HPGL: 40 plotter units per mm

  // [motion]
  MotionParams motion;

  // [pen]
  PenMethod pen_method = PenMethod::servo;
  int pen_count = 1;          // pens the machine holds (carousel), 1 = change by hand
  std::vector<int> pen_map;   // layer i -> pen number pen_map[i]; empty = 1, 2, 3, ...
  double servo_down_s = 0;    // servo: M3 S<down> lowers the pen
  double servo_up_s = 0;      //        M3 S<up> lifts it; 0 means M5
  double z_up_mm = 0, z_down_mm = 0, z_feed_mm_s = 0;  // z_axis
  double laser_power_s = 0;   // laser: M4 S<power> while "down", M5 otherwise
  double dot_dwell_s = 0;     // extra time the pen rests on a single-point stroke

  // [hpgl] (protocol hpgl only)
  bool hpgl_velocity = false;        // VS allowed
  double hpgl_max_velocity_cm_s = 0; // VS upper limit of the device
  int hpgl_max_points_per_command = 0;

  // [serial] for the drivers issue
  int baud = 115200;
  FlowControl flow_control = FlowControl::none;
  int rx_buffer_bytes = 128;  // grbl's serial RX buffer; HPGL: the plotter's buffer
  HpglHandshake hpgl_handshake = HpglHandshake::none;
  bool newline = true;        // end every command with '\n'

  // Pen number for layer i (0-based) or throws UserError when the machine has no pen for it.
  int pen_for_layer(size_t layer) const;
};

// Parses and validates a profile file; throws UserError naming the file and key.
// O(file size).
DeviceProfile load_profile_file(const std::filesystem::path& path);
// Parses profile text (for tests); `origin` names it in errors.
DeviceProfile parse_profile(const std::string& toml_text, const std::string& origin);

// Directories searched for shipped profiles, in order: $STIPPLOT_PROFILES, a profiles/
// folder next to the executable, ../share/stipplot/profiles, the source tree's.
std::vector<std::filesystem::path> profile_dirs();
// Shipped profiles by name (each *.toml in the first directory holding it), sorted by name.
// O(total size of the profile files).
std::vector<DeviceProfile> list_profiles();
// NAME (a shipped profile) or PATH (anything with a '/' or ending in .toml).
DeviceProfile find_profile(const std::string& name_or_path);

inline constexpr const char* kDefaultProfile = "grbl-servo";

// The time model's view of the device.
MotionParams motion_params(const DeviceProfile& p);

std::string to_string(Protocol p);
std::string to_string(PenMethod m);

}  // namespace stipplot
