#pragma once
// The time a written job will take, from its own lines: the writers tell what they write,
// the job timer (drivers/job/timed_job.hpp) runs it through the device's motion, and the
// plan's summary gets those seconds, in total and per layer. The timer runs on a thread of
// its own beside the writer (lines handed over in batches): the same seconds, sooner.
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "drivers/device/profile.hpp"
#include "drivers/job/timed_job.hpp"
#include "drivers/writers/gcode_writer.hpp"
#include "drivers/writers/ebb_writer.hpp"
#include "drivers/writers/hpgl_writer.hpp"

namespace stipplot::cli {

class JobEstimate {
 public:
  // `expected_lines`: about how many lines the writer will write (room reserved for their
  // times; more is harmless, fewer only grows as it goes).
  explicit JobEstimate(const DeviceProfile& profile, size_t expected_lines = 0);
  ~JobEstimate();
  JobEstimate(const JobEstimate&) = delete;
  JobEstimate& operator=(const JobEstimate&) = delete;
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

  // Written lines on their way to the timer; a layer starts before line layer_at[i].
  struct Batch {
    std::string text;
    std::vector<size_t> ends;
    std::vector<size_t> layer_at;
  };
  void add_line(std::string_view line);
  void start_layer();
  void hand_over();      // the batch being filled to the timer's thread (which it starts)
  void time_batch(const Batch& b);
  void drain();          // waits until every line is timed; rethrows the timer's error
  std::function<void(std::string_view)> feed_;
  Batch filling_;
  std::deque<Batch> queue_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool closed_ = false;
  std::exception_ptr error_;
  std::thread worker_;
};

}  // namespace stipplot::cli
