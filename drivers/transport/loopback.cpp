#include "drivers/transport/loopback.hpp"

namespace stipplot::io {

std::pair<std::shared_ptr<PipeEnd>, std::shared_ptr<PipeEnd>> make_pipe() {
  auto shared = std::make_shared<PipeEnd::Shared>();
  auto a = std::shared_ptr<PipeEnd>(new PipeEnd());
  auto b = std::shared_ptr<PipeEnd>(new PipeEnd());
  a->s_ = shared;
  a->side_ = 0;
  b->s_ = shared;
  b->side_ = 1;
  return {a, b};
}

bool PipeEnd::write(std::string_view bytes) {
  std::lock_guard lk(s_->m);
  if (s_->closed) return false;
  auto& q = s_->q[1 - side_];
  q.insert(q.end(), bytes.begin(), bytes.end());
  s_->cv.notify_all();
  return true;
}

long PipeEnd::read(char* buf, size_t n, std::chrono::microseconds timeout) {
  std::unique_lock lk(s_->m);
  auto& q = s_->q[side_];
  s_->cv.wait_for(lk, timeout, [&] { return !q.empty() || s_->closed; });
  if (q.empty()) return s_->closed ? -1 : 0;
  size_t k = std::min(n, q.size());
  std::copy(q.begin(), q.begin() + static_cast<long>(k), buf);
  q.erase(q.begin(), q.begin() + static_cast<long>(k));
  s_->cv.notify_all();
  return static_cast<long>(k);
}

void PipeEnd::close() {
  std::lock_guard lk(s_->m);
  s_->closed = true;
  s_->cv.notify_all();
}

bool PipeEnd::closed() const {
  std::lock_guard lk(s_->m);
  return s_->closed;
}

size_t PipeEnd::unread_by_peer() const {
  std::lock_guard lk(s_->m);
  return s_->q[1 - side_].size();
}

void LoopbackTransport::write(std::string_view bytes, Millis) {
  if (!end_->write(bytes))
    throw TransportError(TransportError::Kind::Disconnected, describe() + " disconnected (write)");
}

size_t LoopbackTransport::read(char* buf, size_t n, Millis timeout) {
  long r = end_->read(buf, n, timeout);
  if (r < 0) throw TransportError(TransportError::Kind::Disconnected, describe() + " disconnected");
  return static_cast<size_t>(r);
}

}  // namespace stipplot::io
