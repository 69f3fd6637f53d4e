#include "drivers/device/profile.hpp"

#include <unistd.h>

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "geometry/page.hpp"
#include "util/error.hpp"
#include "util/executable.hpp"

namespace stipplot {

namespace fs = std::filesystem;

namespace {

// One [section] of a profile: typed getters that remember which keys were read, so
// finish() can refuse the ones nobody asked for (typos, keys of another pen method).
class Section {
 public:
  Section(const toml::table* t, std::string name, const std::string& file)
      : t_(t), name_(std::move(name)), file_(file) {}

  bool has(const char* key) const { return t_ && t_->contains(key); }
  bool present() const { return t_ != nullptr; }

  double number(const char* key, double lo, double hi) {
    const toml::node* n = get(key);
    double v;
    if (auto i = n->value_exact<int64_t>()) {
      v = static_cast<double>(*i);
    } else if (auto d = n->value_exact<double>()) {
      v = *d;
    } else {
      fail(key, "must be a number");
    }
    if (!std::isfinite(v) || v < lo || v > hi) {
      std::ostringstream m;
      m << "must be between " << lo << " and " << hi << " (got " << v << ")";
      fail(key, m.str());
    }
    return v;
  }

  int integer(const char* key, int lo, int hi) {
    const toml::node* n = get(key);
    auto i = n->value_exact<int64_t>();
    if (!i) fail(key, "must be an integer");
    if (*i < lo || *i > hi) fail(key, "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    return static_cast<int>(*i);
  }

  bool boolean(const char* key) {
    auto b = get(key)->value_exact<bool>();
    if (!b) fail(key, "must be true or false");
    return *b;
  }

  std::string string(const char* key) {
    auto s = get(key)->value_exact<std::string>();
    if (!s) fail(key, "must be a string");
    return *s;
  }

  template <class E>
  E choice(const char* key, std::initializer_list<std::pair<const char*, E>> options) {
    std::string s = string(key);
    std::string names;
    for (const auto& [text, value] : options) {
      if (s == text) return value;
      names += names.empty() ? "" : "|";
      names += text;
    }
    fail(key, "must be one of " + names + " (got '" + s + "')");
  }

  std::vector<int> int_array(const char* key, int lo, int hi) {
    const toml::array* a = get(key)->as_array();
    if (!a) fail(key, "must be an array of integers");
    std::vector<int> out;
    for (const auto& e : *a) {
      auto i = e.value_exact<int64_t>();
      if (!i || *i < lo || *i > hi)
        fail(key, "must hold integers between " + std::to_string(lo) + " and " + std::to_string(hi));
      out.push_back(static_cast<int>(*i));
    }
    return out;
  }

  void finish() const {
    if (!t_) return;
    for (const auto& [k, v] : *t_) {
      (void)v;
      std::string key(k.str());
      if (!used_.count(key)) {
        throw UserError("profile " + file_ + ": unknown key " + qualified(key) +
                        " (not used by this protocol or pen method, or misspelt)");
      }
    }
  }

  [[noreturn]] void fail(const char* key, const std::string& what) const {
    throw UserError("profile " + file_ + ": key " + qualified(key) + " " + what);
  }

 private:
  std::string qualified(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }

  const toml::node* get(const char* key) {
    used_.insert(key);
    const toml::node* n = t_ ? t_->get(key) : nullptr;
    if (!n) fail(key, "is missing");
    return n;
  }

  const toml::table* t_;
  std::string name_;
  const std::string& file_;
  std::set<std::string> used_;
};

const toml::table* subtable(const toml::table& root, const char* name, const std::string& file, bool required) {
  const toml::node* n = root.get(name);
  if (!n) {
    if (required) throw UserError("profile " + file + ": section [" + name + "] is missing");
    return nullptr;
  }
  const toml::table* t = n->as_table();
  if (!t) throw UserError("profile " + file + ": key " + name + " must be a section [" + name + "]");
  return t;
}

// `sheet = "A4 landscape"`: a page size as --page reads it, then portrait or landscape
// (named sizes are portrait without it, WxH sizes as written).
void read_sheet(Section& s, MachineGeometry& m) {
  if (!s.has("sheet")) {
    m.sheet_width_mm = m.travel_x_mm + std::fabs(m.origin_offset_x_mm);
    m.sheet_height_mm = m.travel_y_mm + std::fabs(m.origin_offset_y_mm);
    return;
  }
  std::string text = s.string("sheet");
  bool landscape = false, portrait = false;
  for (const char* word : {" landscape", " portrait"}) {
    const size_t n = std::strlen(word);
    if (text.size() > n && text.compare(text.size() - n, n, word) == 0) {
      (word[1] == 'l' ? landscape : portrait) = true;
      text.resize(text.size() - n);
    }
  }
  PageSpec page;
  try {
    page = parse_page(text);
  } catch (const UserError& e) {
    s.fail("sheet", "must be a page size such as \"A4 landscape\" or \"300x200mm\" (" + std::string(e.what()) + ")");
  }
  if ((landscape && page.width_mm < page.height_mm) || (portrait && page.width_mm > page.height_mm))
    std::swap(page.width_mm, page.height_mm);
  m.sheet_width_mm = page.width_mm;
  m.sheet_height_mm = page.height_mm;
}

MachineGeometry read_machine(Section s, bool hpgl) {
  MachineGeometry m;
  m.travel_x_mm = s.number("travel_x_mm", 1, 100000);
  m.travel_y_mm = s.number("travel_y_mm", 1, 100000);
  m.origin = s.choice<Origin>("origin", {{"top-left", Origin::top_left}, {"bottom-left", Origin::bottom_left}});
  auto sign = [&](const char* key) {
    int v = s.integer(key, -1, 1);
    if (v == 0) s.fail(key, "must be 1 or -1");
    return v;
  };
  m.x_sign = sign("x_sign");
  m.y_sign = sign("y_sign");
  m.origin_offset_x_mm = s.number("origin_offset_x_mm", -10000, 10000);
  m.origin_offset_y_mm = s.number("origin_offset_y_mm", -10000, 10000);
  if (hpgl) {
    m.units_per_mm = s.number("units_per_mm", 1, 10000);
    m.resolution_mm = 1.0 / m.units_per_mm;
  } else {
    m.units_per_mm = 1;
    m.resolution_mm = s.number("resolution_mm", 1e-4, 1);
  }
  read_sheet(s, m);
  s.finish();
  return m;
}

MotionParams read_motion(Section s, bool ebb) {
  MotionParams m;
  m.speed_down_mm_s = s.number("speed_down_mm_s", 0.1, 10000);
  m.speed_up_mm_s = s.number("speed_up_mm_s", 0.1, 10000);
  m.accel_mm_s2 = s.number("accel_mm_s2", 1, 1e6);
  m.junction_deviation_mm = s.number("junction_deviation_mm", 0, 10);
  if (!ebb) {  // an EBB's pen times follow from its servo settings ([pen], ebb_pen)
    m.pen_lift_s = s.number("pen_lift_s", 0, 10);
    m.pen_drop_s = s.number("pen_drop_s", 0, 10);
  }
  m.lookahead_blocks = s.integer("lookahead_blocks", 1, 10000);
  // Optional: older profiles without it change pens by hand (no machine time).
  m.pen_change_s = s.has("pen_change_s") ? s.number("pen_change_s", 0, 3600) : 0;
  s.finish();
  return m;
}

PenSetup read_pen(Section s, bool hpgl, bool ebb) {
  PenSetup p;
  if (hpgl) {
    p.method = s.choice<PenMethod>("method", {{"hpgl", PenMethod::hpgl}});
  } else if (ebb) {
    p.method = PenMethod::ebb;
    p.ebb_brushless = s.choice<bool>("method", {{"ebb-servo", false}, {"ebb-brushless", true}});
  } else {
    p.method = s.choice<PenMethod>(
        "method", {{"servo", PenMethod::servo}, {"z", PenMethod::z_axis}, {"laser", PenMethod::laser}});
  }
  p.count = s.integer("count", 1, 256);
  if (s.has("map")) {
    p.map = s.int_array("map", hpgl ? 1 : 0, p.count);
    if (p.map.empty()) s.fail("map", "must not be empty");
  }
  switch (p.method) {
    case PenMethod::servo:
      p.servo_down_s = s.number("servo_down_s", 0, 100000);
      p.servo_up_s = s.number("servo_up_s", 0, 100000);
      break;
    case PenMethod::z_axis:
      p.z_up_mm = s.number("z_up_mm", -1000, 1000);
      p.z_down_mm = s.number("z_down_mm", -1000, 1000);
      p.z_feed_mm_s = s.number("z_feed_mm_s", 0.1, 10000);
      if (p.z_up_mm == p.z_down_mm) s.fail("z_down_mm", "must differ from z_up_mm");
      break;
    case PenMethod::laser:
      p.laser_power_s = s.number("laser_power_s", 0, 100000);
      break;
    case PenMethod::hpgl:
      break;
    case PenMethod::ebb:
      p.pos_up_pct = s.number("pos_up_pct", 0, 100);
      p.pos_down_pct = s.number("pos_down_pct", 0, 100);
      p.rate_raise_pct = s.number("rate_raise_pct", 1, 200);
      p.rate_lower_pct = s.number("rate_lower_pct", 1, 200);
      p.delay_up_ms = s.number("delay_up_ms", 0, 10000);
      p.delay_down_ms = s.number("delay_down_ms", 0, 10000);
      break;
  }
  p.dot_dwell_s = s.number("dot_dwell_s", 0, 10);
  s.finish();
  return p;
}

void read_hpgl(Section s, HpglSettings& h) {
  h.velocity = s.boolean("velocity");
  h.max_velocity_cm_s = s.number("max_velocity_cm_s", 0.1, 1000);
  h.max_points_per_command = s.integer("max_points_per_command", 1, 10000);
  s.finish();
}

GrblSetup read_grbl(Section s, const MachineGeometry& m) {
  GrblSetup g;
  if (!s.present()) {  // steps follow the resolution; Z as X
    g.steps_per_mm_x = g.steps_per_mm_y = g.steps_per_mm_z = 1.0 / m.resolution_mm;
    return g;
  }
  g.given = true;
  g.steps_per_mm_x = s.number("steps_per_mm_x", 0.01, 100000);
  g.steps_per_mm_y = s.number("steps_per_mm_y", 0.01, 100000);
  g.steps_per_mm_z = s.number("steps_per_mm_z", 0.01, 100000);
  g.max_rate_z_mm_s = s.number("max_rate_z_mm_s", 0.01, 100000);
  g.accel_z_mm_s2 = s.number("accel_z_mm_s2", 0.01, 1e6);
  g.idle_lock_ms = s.number("idle_lock_ms", 0, 255);
  s.finish();
  return g;
}

EbbSetup read_ebb(Section s) {
  EbbSetup e;
  e.steps_per_mm = s.number("steps_per_mm", 1, 10000);
  e.servo_min = s.integer("servo_min", 1, 65535);
  e.servo_max = s.integer("servo_max", 1, 65535);
  e.servo_sweep_ms = s.number("servo_sweep_ms", 1, 10000);
  e.servo_move_min_ms = s.number("servo_move_min_ms", 0, 10000);
  e.servo_move_slope_ms = s.number("servo_move_slope_ms", 0, 1000);
  e.servo_pwm_period = s.number("servo_pwm_period", 0.001, 100);
  e.time_slice_ms = s.integer("time_slice_ms", 1, 1000);
  if (s.has("moves"))
    e.moves = s.choice<motion::EbbMoveKind>("moves", {{"lm", motion::EbbMoveKind::lm}, {"sm", motion::EbbMoveKind::sm}});
  e.fifo_commands = s.integer("fifo_commands", 1, 32);  // the firmware's COMMAND_FIFO_MAX_LENGTH
  s.finish();
  return e;
}

// [serial]; its handshake key belongs to the HPGL settings.
SerialSetup read_serial(Section s, bool hpgl, HpglSettings& h) {
  SerialSetup ser;
  ser.port.baud = s.integer("baud", 50, 10'000'000);
  ser.port.flow = s.choice<io::FlowControl>("flow_control", {{"none", io::FlowControl::None},
                                                             {"xonxoff", io::FlowControl::XonXoff},
                                                             {"rtscts", io::FlowControl::RtsCts}});
  ser.rx_buffer_bytes = s.integer("rx_buffer_bytes", 16, 1 << 24);
  if (hpgl) {
    h.handshake = s.choice<HpglHandshake>("handshake", {{"none", HpglHandshake::none},
                                                        {"xonxoff", HpglHandshake::xonxoff},
                                                        {"hardware", HpglHandshake::hardware},
                                                        {"buffer_query", HpglHandshake::buffer_query}});
  }
  ser.newline = s.boolean("newline");
  if (s.has("watchdog_s")) ser.watchdog_s = s.number("watchdog_s", 1, 86400);
  s.finish();
  return ser;
}

// An EBB's pen times from its servo (axicli's formula), and its speeds within the
// firmware's step rate: motor 1 steps at (|vx| + |vy|) * steps_per_mm at worst.
void finish_ebb(DeviceProfile& p, const std::string& file) {
  set_ebb_pen_heights(p, p.pen.pos_up_pct, p.pen.pos_down_pct);
  const double worst = std::max(p.motion.speed_up_mm_s, p.motion.speed_down_mm_s) * std::sqrt(2.0) * p.ebb.steps_per_mm;
  if (worst > p.ebb.max_step_rate_hz)
    throw UserError("profile " + file + ": speeds above " +
                    std::to_string(p.ebb.max_step_rate_hz / std::sqrt(2.0) / p.ebb.steps_per_mm) +
                    " mm/s would step a motor faster than the EBB's 25 kHz");
  if (p.pen.count != 1) throw UserError("profile " + file + ": key pen.count must be 1 on an EBB machine");
}

DeviceProfile parse_table(const toml::table& root, const std::string& file) {
  DeviceProfile p;
  static const std::set<std::string> kSections = {"machine", "motion", "pen", "hpgl", "grbl", "ebb", "serial"};

  Section top(&root, "", file);
  p.name = top.string("name");
  if (p.name.empty() || p.name.find_first_of(" \t/") != std::string::npos)
    top.fail("name", "must be a non-empty word without spaces or '/'");
  p.description = top.string("description");
  p.protocol = top.choice<Protocol>("protocol",
                                    {{"grbl", Protocol::grbl}, {"hpgl", Protocol::hpgl}, {"ebb", Protocol::ebb}});
  const bool hpgl = p.protocol == Protocol::hpgl;
  const bool ebb = p.protocol == Protocol::ebb;
  auto section = [&](const char* name) { return Section(subtable(root, name, file, true), name, file); };

  p.machine = read_machine(section("machine"), hpgl);
  p.motion = read_motion(section("motion"), ebb);
  p.pen = read_pen(section("pen"), hpgl, ebb);
  if (hpgl) {
    read_hpgl(section("hpgl"), p.hpgl);
  } else if (root.contains("hpgl")) {
    throw UserError("profile " + file + ": section [hpgl] is only for protocol = \"hpgl\"");
  }
  if (!hpgl && !ebb) {
    p.grbl = read_grbl(Section(subtable(root, "grbl", file, false), "grbl", file), p.machine);
  } else if (root.contains("grbl")) {
    throw UserError("profile " + file + ": section [grbl] is only for protocol = \"grbl\"");
  }
  if (ebb) {
    p.ebb = read_ebb(section("ebb"));
    finish_ebb(p, file);
  } else if (root.contains("ebb")) {
    throw UserError("profile " + file + ": section [ebb] is only for protocol = \"ebb\"");
  }
  p.serial = read_serial(section("serial"), hpgl, p.hpgl);
  // Top-level: everything else must be a known section.
  for (const auto& [k, v] : root) {
    (void)v;
    std::string key(k.str());
    if (key == "name" || key == "description" || key == "protocol" || kSections.count(key)) continue;
    throw UserError("profile " + file + ": unknown key " + key);
  }
  return p;
}

}  // namespace

DeviceProfile parse_profile(const std::string& text, const std::string& origin) {
  toml::table root;
  try {
    root = toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    std::ostringstream m;
    m << "profile " << origin << " line " << e.source().begin.line << ": " << e.description();
    throw UserError(m.str());
  }
  DeviceProfile p = parse_table(root, origin);
  p.source = origin;
  return p;
}

DeviceProfile load_profile_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError("profile " + path.string() + ": cannot read the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_profile(ss.str(), path.string());
}

std::vector<fs::path> profile_dirs() {
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("STIPPLOT_PROFILES"); env && *env) dirs.emplace_back(env);
  fs::path exe = executable_dir();
  if (!exe.empty()) {
    dirs.push_back(exe / "profiles");
    dirs.push_back(exe.parent_path() / "share" / "stipplot" / "profiles");
  }
#ifdef STIPPLOT_PROFILE_DIR
  dirs.emplace_back(STIPPLOT_PROFILE_DIR);
#endif
  return dirs;
}

std::vector<DeviceProfile> list_profiles() {
  std::map<std::string, DeviceProfile> by_name;
  for (const auto& dir : profile_dirs()) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) continue;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".toml") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      std::string stem = f.stem().string();
      if (by_name.count(stem)) continue;  // an earlier directory overrides
      by_name.emplace(stem, load_profile_file(f));
    }
  }
  std::vector<DeviceProfile> out;
  for (auto& [k, v] : by_name) out.push_back(std::move(v));
  return out;
}

DeviceProfile find_profile(const std::string& name_or_path) {
  if (name_or_path.empty()) throw UserError("--profile must name a profile (see `stipplot profiles`) or a .toml file");
  bool is_path = name_or_path.find('/') != std::string::npos ||
                 (name_or_path.size() > 5 && name_or_path.substr(name_or_path.size() - 5) == ".toml");
  if (is_path) return load_profile_file(name_or_path);
  std::string searched;
  for (const auto& dir : profile_dirs()) {
    fs::path f = dir / (name_or_path + ".toml");
    std::error_code ec;
    if (fs::is_regular_file(f, ec)) return load_profile_file(f);
    searched += searched.empty() ? "" : ", ";
    searched += dir.string();
  }
  std::string known;
  try {
    for (const auto& p : list_profiles()) known += (known.empty() ? "" : ", ") + p.name;
  } catch (const UserError&) {
  }
  throw UserError("--profile " + name_or_path + ": no such profile (known: " + (known.empty() ? "none" : known) +
                  "; searched " + searched + ")");
}

std::string to_string(Protocol p) {
  switch (p) {
    case Protocol::grbl: return "grbl";
    case Protocol::hpgl: return "hpgl";
    case Protocol::ebb: return "ebb";
  }
  return "?";
}

EbbPen ebb_pen(const PenSetup& pen, const EbbSetup& e) {
  EbbPen out;
  const double range = e.servo_max - e.servo_min;
  out.up = static_cast<int>(std::lround(e.servo_min + range / 100 * pen.pos_up_pct));
  out.down = static_cast<int>(std::lround(e.servo_min + range / 100 * pen.pos_down_pct));
  const double rate_scale = range * e.servo_pwm_period / e.servo_sweep_ms;
  out.rate_up = static_cast<int>(std::lround(rate_scale * pen.rate_raise_pct));
  out.rate_down = static_cast<int>(std::lround(rate_scale * pen.rate_lower_pct));
  const double dist = std::fabs(pen.pos_up_pct - pen.pos_down_pct);
  auto travel_ms = [&](double rate_pct) {
    if (dist < 0.9) return 0.0;  // axicli: equal heights need no wait
    const double fast = e.servo_move_slope_ms * dist + e.servo_move_min_ms;
    const double slow = e.servo_sweep_ms * dist / rate_pct;
    return std::floor(std::pow(std::pow(fast, 4) + std::pow(slow, 4), 0.25));
  };
  out.raise_ms = static_cast<int>(travel_ms(pen.rate_raise_pct) + pen.delay_up_ms);
  out.lower_ms = static_cast<int>(travel_ms(pen.rate_lower_pct) + pen.delay_down_ms);
  if (pen.ebb_brushless) {  // nextdraw/axidraw pen_handling.py: z_motor 1 on pin 2, SC,8,1
    out.pin = 2;
    out.channels = 1;
  }
  return out;
}

void set_ebb_pen_heights(DeviceProfile& p, double up_pct, double down_pct) {
  p.pen.pos_up_pct = up_pct;
  p.pen.pos_down_pct = down_pct;
  const EbbPen pen = ebb_pen(p.pen, p.ebb);
  p.motion.pen_lift_s = pen.raise_ms / 1000.0;
  p.motion.pen_drop_s = pen.lower_ms / 1000.0;
}

std::vector<std::string> ebb_servo_setup(const EbbPen& pen) {
  std::vector<std::string> out = {"SC,4," + std::to_string(pen.up), "SC,5," + std::to_string(pen.down),
                                  "SC,11," + std::to_string(pen.rate_up), "SC,12," + std::to_string(pen.rate_down)};
  // Before the first SP: the rates above count per PWM period, one channel of 3 ms.
  if (pen.channels > 0) out.push_back("SC,8," + std::to_string(pen.channels));
  return out;
}

std::string ebb_pen_command(const EbbPen& pen, bool down) {
  std::string c = down ? "SP,0," + std::to_string(pen.lower_ms) : "SP,1," + std::to_string(pen.raise_ms);
  if (pen.pin > 0) c += "," + std::to_string(pen.pin);
  return c;
}

std::string pen_method_name(const PenSetup& pen) {
  return pen.method == PenMethod::ebb && pen.ebb_brushless ? "ebb-brushless" : to_string(pen.method);
}

std::string to_string(PenMethod m) {
  switch (m) {
    case PenMethod::servo: return "servo";
    case PenMethod::z_axis: return "z";
    case PenMethod::laser: return "laser";
    case PenMethod::hpgl: return "hpgl";
    case PenMethod::ebb: return "ebb-servo";
  }
  return "?";
}

HpglHandshake parse_hpgl_handshake(const std::string& s) {
  if (s == "hardware" || s == "rtscts") return HpglHandshake::hardware;
  if (s == "xonxoff" || s == "software") return HpglHandshake::xonxoff;
  if (s == "escb" || s == "poll" || s == "esc.b") return HpglHandshake::buffer_query;
  throw UserError("HPGL handshake must be hardware, xonxoff or escb, got '" + s + "'");
}

}  // namespace stipplot
