#include "sim/device.hpp"

#include <algorithm>
#include <cmath>

namespace stipplot::sim {

SimDevice::SimDevice(const SimRun& run)
    : faults_(run.faults), linkm_(run.link), speedup_(run.speedup), t0_(std::chrono::steady_clock::now()) {
  if (!(speedup_ > 0) || !std::isfinite(speedup_)) throw UserError("--speedup must be a positive number");
  if (linkm_.baud < 0 || linkm_.latency_ms < 0) throw UserError("simulated link: baud and latency must be >= 0");
}

SimDevice::~SimDevice() { stop(); }

double SimDevice::device_time() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count() * speedup_;
}

void SimDevice::attach(std::unique_ptr<SimLink> link) {
  {
    // Parked until the serve thread takes it: that thread may still be in the old link's
    // hang-up (a power loss or a dropped line), and must not close or read the new one.
    std::lock_guard lk(link_m_);
    next_link_ = std::move(link);
    new_link_ = true;
    connected_ = true;
  }
  link_cv_.notify_all();
  if (!thread_.joinable()) thread_ = std::thread([this] { serve(); });
}

std::unique_ptr<io::Transport> SimDevice::connect_loopback() {
  auto [a, b] = io::make_pipe();
  attach(std::make_unique<PipeLink>(b));
  return std::make_unique<io::LoopbackTransport>(a, "simulator");
}

std::string SimDevice::open_pty() {
  auto link = std::make_unique<PtyLink>();
  std::string name = link->name();
  attach(std::move(link));
  return name;
}

std::string SimDevice::link_name() const {
  std::lock_guard lk(const_cast<std::mutex&>(link_m_));
  if (next_link_) return next_link_->name();
  return link_ ? link_->name() : "";
}

void SimDevice::stop() {
  stop_ = true;
  link_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (link_) link_->close();
  if (next_link_) next_link_->close();
}

std::vector<Segment> SimDevice::record() const {
  std::lock_guard lk(m_);
  return rec_.segments();
}

SimStats SimDevice::stats() const {
  std::lock_guard lk(m_);
  return stats_;
}

bool SimDevice::wait_idle(double seconds) {
  auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (idle_flag_) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return idle_flag_;
}

void SimDevice::send(const std::string& s, double t) {
  double byte_t = linkm_.baud > 0 ? 10.0 / linkm_.baud : 0;
  double at = std::max(t + linkm_.latency_ms / 2000.0, last_out_) + byte_t * static_cast<double>(s.size());
  last_out_ = at;
  wire_out_.emplace_back(at, s);
}

void SimDevice::mark_busy(double t) {
  std::lock_guard lk(m_);
  if (stats_.busy_start < 0) stats_.busy_start = t;
  if (idle_since_ >= 0 && ever_busy_) stats_.starved_s += t - idle_since_;
  idle_since_ = -1;
  ever_busy_ = true;
}

void SimDevice::mark_idle(double t) {
  std::lock_guard lk(m_);
  stats_.busy_end = t;
  if (idle_since_ < 0) idle_since_ = t;
}

void SimDevice::mark_paused() {
  std::lock_guard lk(m_);
  idle_since_ = -1;
}

void SimDevice::disconnect(double t) {
  // The line goes down: what already left the device still reaches the host (so a
  // line is acknowledged exactly when the device has it), then the hang-up; the
  // machine finishes what it had accepted.
  faults_.disconnect_after_bytes = -1;  // once; a reconnection then works
  on_disconnect(t);
  wire_in_.clear();
  for (auto& [at, s] : wire_out_)
    if (client_present_) link_->write(s);
  wire_out_.clear();
  auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (link_->unread_by_client() > 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  link_->close();
  connected_ = false;
}

void SimDevice::serve() {
  std::vector<char> buf(4096);
  bool linked = false;
  while (!stop_) {
    {
      std::lock_guard lk(link_m_);
      if (new_link_) {
        new_link_ = false;
        link_ = std::move(next_link_);
        connected_ = true;  // again: the old link's hang-up may have cleared it after attach
        linked = true;
        client_present_ = false;
        wire_in_.clear();
        wire_out_.clear();
        on_connect(device_time());
      }
    }
    double t = device_time();
    if (linked) {
      const bool present = link_->client_present();
      if (present && !client_present_) {
        wire_in_.clear();
        on_client_open(t);
      }
      client_present_ = present;
    }
    double byte_t = linkm_.baud > 0 ? 10.0 / linkm_.baud : 0;
    // Deliver input bytes whose time has come, running the machine up to each.
    while (!wire_in_.empty() && wire_in_.front().t <= t) {
      Timed b = wire_in_.front();
      wire_in_.pop_front();
      advance(b.t);
      on_byte(b.c, b.t);
    }
    advance(t);
    idle_flag_ = idle() && wire_in_.empty();
    // Replies whose time has come.
    // Replies whose time has come; with nobody on the port they are lost, as on a wire.
    while (linked && !wire_out_.empty() && wire_out_.front().first <= t) {
      if (client_present_) link_->write(wire_out_.front().second);
      wire_out_.pop_front();
    }
    // Sleep until the next thing to do, or input.
    double next = next_event();
    if (!wire_in_.empty()) next = std::min(next, wire_in_.front().t);
    if (!wire_out_.empty()) next = std::min(next, wire_out_.front().first);
    double wait = std::clamp((next - t) / speedup_, 0.0, 0.002);
    if (!linked) {
      std::this_thread::sleep_for(std::chrono::duration<double>(std::max(wait, 1e-4)));
      continue;
    }
    long n = link_->read(buf.data(), buf.size(), wait);
    if (n < 0) {  // the client closed an in-process pipe: wait for a new link
      linked = false;
      connected_ = false;
      continue;
    }
    double now = device_time();
    if (n > 0 && first_in_ < 0) first_in_ = now;
    const bool timed_out = faults_.power_loss_after_s >= 0 && first_in_ >= 0 && now - first_in_ >= faults_.power_loss_after_s;
    for (long i = 0; i <= n; ++i) {
      if (timed_out || (faults_.power_loss_after_bytes >= 0 && static_cast<long>(stats_.bytes_in) >= faults_.power_loss_after_bytes)) {
        faults_.power_loss_after_bytes = -1;  // once
        faults_.power_loss_after_s = -1;
        advance(now);
        on_power_loss(now);
        disconnect(now);
        linked = false;
        break;
      }
      if (i == n) break;
      if (faults_.disconnect_after_bytes >= 0 &&
          static_cast<long>(stats_.bytes_in) >= faults_.disconnect_after_bytes) {
        disconnect(now);
        linked = false;
        break;
      }
      {
        std::lock_guard lk(m_);
        ++stats_.bytes_in;
      }
      double at = std::max(now + linkm_.latency_ms / 2000.0, last_in_) + byte_t;
      last_in_ = at;
      wire_in_.push_back({buf[static_cast<size_t>(i)], at});
    }
  }
}

}  // namespace stipplot::sim
