#pragma once
// A write-only transport into a file (a job to copy to a plotter later, or a device
// node such as /dev/usb/lp0). Reads see silence.
#include <cstdio>
#include <string>

#include "drivers/transport/transport.hpp"

namespace stipplot::io {

class FileSink final : public Transport {
 public:
  explicit FileSink(std::string path);  // truncates; throws TransportError(NotFound)
  ~FileSink() override;
  void write(std::string_view bytes, Millis timeout) override;
  size_t read(char* buf, size_t n, Millis timeout) override;
  void flush() override;
  bool is_connected() const override { return f_ != nullptr; }
  void close() override;
  std::string describe() const override { return "file " + path_; }
  bool answers() const override { return false; }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
};

}  // namespace stipplot::io
