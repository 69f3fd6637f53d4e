#include "cli/job_estimate.hpp"

#include "drivers/device/motion_setup.hpp"
#include "drivers/job/ebb_reader.hpp"

namespace stipplot::cli {

JobEstimate::JobEstimate(const DeviceProfile& p) {
  if (p.protocol == Protocol::grbl) {
    io::GcodeLink link;
    link.baud = p.serial.port.baud;
    link.rx_buffer = p.serial.rx_buffer_bytes;
    gcode_ = std::make_unique<io::GcodeTimer>(grbl_settings_for(p), link);
  } else if (p.protocol == Protocol::ebb) {
    ebb_ = std::make_unique<io::EbbTimer>();
  } else {
    hpgl_ = std::make_unique<io::HpglTimer>(hpgl_motion_for(p));
  }
}

size_t JobEstimate::lines() const { return gcode_ ? gcode_->lines() : ebb_ ? ebb_->lines() : hpgl_->lines(); }

EbbOptions JobEstimate::ebb_options() {
  EbbOptions o;
  o.also = [this](std::string_view l) { ebb_->feed(l, !l.empty() && l[0] == '#', io::ebb_pause_note(l).has_value()); };
  o.on_layer = [this](size_t) { layer_first_.push_back(lines()); };
  return o;
}

GcodeOptions JobEstimate::gcode_options() {
  GcodeOptions o;
  o.also = [this](std::string_view l) { gcode_->feed(l); };
  o.on_layer = [this](size_t) { layer_first_.push_back(lines()); };
  return o;
}

HpglOptions JobEstimate::hpgl_options() {
  HpglOptions o;
  o.also = [this](std::string_view l) { hpgl_->feed(l); };
  o.on_layer = [this](size_t) { layer_first_.push_back(lines()); };
  return o;
}

void JobEstimate::apply(nlohmann::json& plan) {
  const io::JobTiming t = gcode_ ? gcode_->finish() : ebb_ ? ebb_->finish() : hpgl_->finish();
  plan["total"]["seconds"] = t.total_s;
  plan["total"]["stops"] = t.stops;
  auto done_before = [&](size_t line) { return line == 0 || t.done_s.empty() ? 0.0 : t.done_s[std::min(line, t.done_s.size()) - 1]; };
  nlohmann::json& layers = plan["layers"];
  for (size_t i = 0; i < layers.size() && i < layer_first_.size(); ++i) {
    const size_t end = i + 1 < layer_first_.size() ? layer_first_[i + 1] : t.done_s.size();
    layers[i]["seconds"] = done_before(end) - done_before(layer_first_[i]);
  }
}

}  // namespace stipplot::cli
