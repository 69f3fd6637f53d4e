#pragma once
// The simulator's end of the wire: a pseudo-terminal (what `stipplot sim` and the
// end-to-end tests use; the driver opens the pty path as a serial port) or an
// in-process pipe (io::LoopbackTransport at the other end).
#include <memory>
#include <string>
#include <string_view>

#include "drivers/transport/loopback.hpp"

namespace stipplot::sim {

class SimLink {
 public:
  virtual ~SimLink() = default;
  // Bytes read, waiting up to `timeout_s`; 0 on timeout; -1 once the client is gone.
  virtual long read(char* buf, size_t n, double timeout_s) = 0;
  virtual void write(std::string_view bytes) = 0;
  // Bytes written that the client has not read yet.
  virtual size_t unread_by_client() = 0;
  // Someone has the port open (what is written while nobody has is lost).
  virtual bool client_present() = 0;
  virtual void close() = 0;
  virtual std::string name() const = 0;
};

// openpty(): the slave path is what the driver opens. The simulator holds only the
// master, so it sees the client open and close the port (the master hangs up while no
// slave is open) and the client may close and reopen it; close() hangs the line up.
class PtyLink final : public SimLink {
 public:
  PtyLink();
  ~PtyLink() override;
  long read(char* buf, size_t n, double timeout_s) override;
  void write(std::string_view bytes) override;
  size_t unread_by_client() override;
  bool client_present() override;
  void close() override;
  std::string name() const override { return path_; }

 private:
  int master_ = -1;
  std::string path_;
};

class PipeLink final : public SimLink {
 public:
  explicit PipeLink(std::shared_ptr<io::PipeEnd> end) : end_(std::move(end)) {}
  ~PipeLink() override { close(); }
  long read(char* buf, size_t n, double timeout_s) override;
  void write(std::string_view bytes) override { end_->write(bytes); }
  size_t unread_by_client() override { return end_->unread_by_peer(); }
  bool client_present() override { return !end_->closed(); }
  void close() override { end_->close(); }
  std::string name() const override { return "pipe"; }

 private:
  std::shared_ptr<io::PipeEnd> end_;
};

}  // namespace stipplot::sim
