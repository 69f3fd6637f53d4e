#include "cli/job_estimate.hpp"

#include "drivers/device/motion_setup.hpp"
#include "drivers/job/ebb_reader.hpp"

namespace stipplot::cli {

JobEstimate::JobEstimate(const DeviceProfile& p, size_t expected_lines) {
  if (p.protocol == Protocol::grbl) {
    io::GcodeLink link;
    link.baud = p.serial.port.baud;
    link.rx_buffer = p.serial.rx_buffer_bytes;
    gcode_ = std::make_unique<io::GcodeTimer>(grbl_settings_for(p), link);
    feed_ = [this](std::string_view l) { gcode_->feed(l); };
  } else if (p.protocol == Protocol::ebb) {
    ebb_ = std::make_unique<io::EbbTimer>();
    feed_ = [this](std::string_view l) { ebb_->feed(l, !l.empty() && l[0] == '#', io::ebb_pause_note(l).has_value()); };
  } else {
    hpgl_ = std::make_unique<io::HpglTimer>(hpgl_motion_for(p));
    feed_ = [this](std::string_view l) { hpgl_->feed(l); };
  }
  if (gcode_) gcode_->reserve(expected_lines);
  if (ebb_) ebb_->reserve(expected_lines);
  if (hpgl_) hpgl_->reserve(expected_lines);
}

JobEstimate::~JobEstimate() {
  if (!worker_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

void JobEstimate::add_line(std::string_view line) {
  filling_.text.append(line);
  filling_.ends.push_back(filling_.text.size());
  if (filling_.text.size() >= (size_t{1} << 18)) hand_over();
}

void JobEstimate::start_layer() { filling_.layer_at.push_back(filling_.ends.size()); }

void JobEstimate::time_batch(const Batch& b) {
  size_t next_layer = 0, begin = 0;
  for (size_t i = 0; i <= b.ends.size(); ++i) {
    // The timer's own count: a G-code timer does not count comments and blank lines.
    for (; next_layer < b.layer_at.size() && b.layer_at[next_layer] == i; ++next_layer) layer_first_.push_back(lines());
    if (i == b.ends.size()) break;
    feed_(std::string_view(b.text).substr(begin, b.ends[i] - begin));
    begin = b.ends[i];
  }
}

void JobEstimate::hand_over() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!worker_.joinable()) {
    worker_ = std::thread([this] {
      std::unique_lock<std::mutex> lk(mutex_);
      for (;;) {
        changed_.wait(lk, [this] { return closed_ || !queue_.empty(); });
        if (queue_.empty()) return;  // closed, all timed
        Batch b = std::move(queue_.front());
        queue_.pop_front();
        changed_.notify_all();
        lk.unlock();
        try {
          if (!error_) time_batch(b);
        } catch (...) {
          error_ = std::current_exception();
        }
        lk.lock();
      }
    });
  }
  // A few batches ahead at most: the writer waits for a slower timer.
  changed_.wait(lock, [this] { return queue_.size() < 8; });
  queue_.push_back(std::move(filling_));
  filling_ = Batch{};
  changed_.notify_all();
}

void JobEstimate::drain() {
  if (worker_.joinable()) {
    hand_over();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    changed_.notify_all();
    worker_.join();
  } else {
    time_batch(filling_);
    filling_ = Batch{};
  }
  if (error_) std::rethrow_exception(error_);
}

size_t JobEstimate::lines() const { return gcode_ ? gcode_->lines() : ebb_ ? ebb_->lines() : hpgl_->lines(); }

EbbOptions JobEstimate::ebb_options() {
  EbbOptions o;
  o.also = [this](std::string_view l) { add_line(l); };
  o.on_layer = [this](size_t) { start_layer(); };
  return o;
}

GcodeOptions JobEstimate::gcode_options() {
  GcodeOptions o;
  o.also = [this](std::string_view l) { add_line(l); };
  o.on_layer = [this](size_t) { start_layer(); };
  return o;
}

HpglOptions JobEstimate::hpgl_options() {
  HpglOptions o;
  o.also = [this](std::string_view l) { add_line(l); };
  o.on_layer = [this](size_t) { start_layer(); };
  return o;
}

void JobEstimate::apply(nlohmann::json& plan) {
  drain();
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
