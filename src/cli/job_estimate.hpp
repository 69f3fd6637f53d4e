#pragma once
// The time a written job will take, from its own lines: the writers tell what they write,
// the job timer (drivers/job/timed_job.hpp) runs it through the device's motion, and the
// plan's summary gets those seconds, in total and per layer.
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "drivers/device/profile.hpp"
#include "drivers/job/timed_job.hpp"
#include "drivers/writers/gcode_writer.hpp"
#include "drivers/writers/ebb_writer.hpp"
#include "drivers/writers/hpgl_writer.hpp"

namespace stipplot::cli {

class JobEstimate {
 public:
  explicit JobEstimate(const DeviceProfile& profile);
  GcodeOptions gcode_options();  // writer options that feed the timer
  HpglOptions hpgl_options();
  EbbOptions ebb_options();
  // Sets plan.total.seconds and plan.layers[i].seconds from the timed lines, and adds
  // total.stops (times the machine comes to rest). O(lines).
  void apply(nlohmann::json& plan_summary);

 private:
  std::unique_ptr<io::GcodeTimer> gcode_;
  std::unique_ptr<io::HpglTimer> hpgl_;
  std::unique_ptr<io::EbbTimer> ebb_;
  std::vector<size_t> layer_first_;  // timed line index where each layer starts
  size_t lines() const;
};

}  // namespace stipplot::cli
