#include "drivers/transport/file_sink.hpp"

#include <cerrno>
#include <cstring>
#include <thread>

namespace stipplot::io {

FileSink::FileSink(std::string path) : path_(std::move(path)) {
  f_ = std::fopen(path_.c_str(), "wb");
  if (!f_) throw TransportError(TransportError::Kind::NotFound, "cannot open " + path_ + " for writing: " + std::strerror(errno));
}

FileSink::~FileSink() { close(); }

void FileSink::write(std::string_view bytes, Millis) {
  if (!f_) throw TransportError(TransportError::Kind::Disconnected, "file " + path_ + " is closed");
  if (std::fwrite(bytes.data(), 1, bytes.size(), f_) != bytes.size())
    throw TransportError(TransportError::Kind::Io, "cannot write " + path_ + ": " + std::strerror(errno));
}

size_t FileSink::read(char*, size_t, Millis timeout) {
  if (!f_) throw TransportError(TransportError::Kind::Disconnected, "file " + path_ + " is closed");
  std::this_thread::sleep_for(std::min(timeout, Millis(1)));
  return 0;
}

void FileSink::flush() {
  if (f_) std::fflush(f_);
}

void FileSink::close() {
  if (!f_) return;
  std::FILE* f = f_;
  f_ = nullptr;
  if (std::fclose(f) != 0) throw TransportError(TransportError::Kind::Io, "cannot finish writing " + path_);
}

}  // namespace stipplot::io
