#pragma once
// An in-process byte pipe: the driver's Transport at one end, the simulator at the
// other. Closing either end is a disconnect: the other end still reads what was
// already sent, then sees the hang-up.
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>

#include "drivers/transport/transport.hpp"

namespace stipplot::io {

class PipeEnd {
 public:
  // Returns false if the pipe is closed.
  bool write(std::string_view bytes);
  // Bytes read (waiting up to timeout); 0 on timeout; -1 when closed and drained.
  long read(char* buf, size_t n, std::chrono::microseconds timeout);
  void close();
  bool closed() const;
  // Bytes sent from this end that the other end has not read yet.
  size_t unread_by_peer() const;

 private:
  friend std::pair<std::shared_ptr<PipeEnd>, std::shared_ptr<PipeEnd>> make_pipe();
  struct Shared {
    std::mutex m;
    std::condition_variable cv;
    std::deque<char> q[2];  // q[i]: bytes travelling towards end i
    bool closed = false;
  };
  std::shared_ptr<Shared> s_;
  int side_ = 0;
};

std::pair<std::shared_ptr<PipeEnd>, std::shared_ptr<PipeEnd>> make_pipe();

class LoopbackTransport final : public Transport {
 public:
  explicit LoopbackTransport(std::shared_ptr<PipeEnd> end, std::string name = "sim")
      : end_(std::move(end)), name_(std::move(name)) {}
  ~LoopbackTransport() override { close(); }
  void write(std::string_view bytes, Millis timeout) override;
  size_t read(char* buf, size_t n, Millis timeout) override;
  bool is_connected() const override { return end_ && !end_->closed(); }
  void close() override {
    if (end_) end_->close();
  }
  std::string describe() const override { return "in-process " + name_; }

 private:
  std::shared_ptr<PipeEnd> end_;
  std::string name_;
};

}  // namespace stipplot::io
