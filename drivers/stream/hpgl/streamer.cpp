#include "drivers/stream/hpgl/streamer.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <thread>

#include "drivers/stream/device_error.hpp"

namespace stipplot::io::hpgl {

using clock = std::chrono::steady_clock;

Options options_for(const DeviceProfile& p) {
  Options o;
  o.handshake = p.hpgl.handshake;
  o.newline = p.serial.newline;
  return o;
}

std::string error_meaning(int code) {
  switch (code) {
    case 0: return "no error";
    case 1: return "instruction not recognized";
    case 2: return "wrong number of parameters";
    case 3: return "out-of-range parameters";
    case 5: return "unknown character set";
    case 6: return "position overflow";
    case 7: return "buffer overflow (data was lost)";
    default: return "HP-GL error " + std::to_string(code);
  }
}

Streamer::Streamer(Transport& t, Options o) : t_(t), o_(std::move(o)) {
  if (o_.reserve < 0 || o_.buffer_bytes < 0) throw UserError("HPGL buffer size and reserve must be >= 0");
  if (o_.retries < 0) throw UserError("HPGL retries must be >= 0");
}

void Streamer::pump(Millis timeout) {
  char buf[512];
  size_t n = t_.read(buf, sizeof buf, timeout);
  for (size_t i = 0; i < n; ++i) {
    if (buf[i] == 0x13) {
      if (!xoff_) xoff_since_ = clock::now();
      xoff_ = true;
    } else if (buf[i] == 0x11) {
      xoff_ = false;
    } else {
      incoming_.push_back(buf[i]);
    }
  }
}

bool Streamer::read_reply(std::string& out, Millis timeout) {
  auto end = clock::now() + timeout;
  for (;;) {
    auto eol = incoming_.find_first_of("\r\n");
    while (eol == 0) {
      incoming_.erase(0, 1);
      eol = incoming_.find_first_of("\r\n");
    }
    if (eol != std::string::npos) {
      out = incoming_.substr(0, eol);
      incoming_.erase(0, eol + 1);
      return true;
    }
    auto left = std::chrono::duration_cast<Millis>(end - clock::now());
    if (left.count() <= 0) return false;
    pump(std::min(left, Millis(50)));
  }
}

int Streamer::query(char c) {
  for (int attempt = 0; attempt <= o_.retries; ++attempt) {
    incoming_.clear();
    t_.write(std::string("\x1b.") + c);
    std::string r;
    if (!read_reply(r, o_.reply_timeout)) {
      note(std::string("no answer to ESC.") + c + ", asking again");
      continue;
    }
    char* end = nullptr;
    long v = std::strtol(r.c_str(), &end, 10);
    if (end != r.c_str() && (*end == '\0' || *end == ',') && v >= 0) return static_cast<int>(v);
    note(std::string("garbled answer to ESC.") + c + ": '" + r + "', asking again");
    std::this_thread::sleep_for(Millis(20));
    pump(Millis(20));
  }
  throw TransportError(TransportError::Kind::Timeout, std::string("the plotter on ") + t_.describe() +
                                                          " does not answer ESC." + c + " (tried " +
                                                          std::to_string(o_.retries + 1) + " times)");
}

void Streamer::connect() {
  if (o_.handshake != HpglHandshake::buffer_query && !o_.status_queries) {
    buffer_ = o_.buffer_bytes;
    return;
  }
  buffer_ = o_.buffer_bytes > 0 ? o_.buffer_bytes : query('L');
  if (buffer_ <= o_.reserve) throw UserError("the plotter reports a buffer of " + std::to_string(buffer_) + " bytes: too small");
  // Wait for earlier work to finish (after a reconnect), so free space means empty.
  auto end = clock::now() + std::chrono::minutes(30);
  while (query('B') < buffer_ && clock::now() < end) std::this_thread::sleep_for(Millis(50));
}

StreamResult Streamer::stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                              const ProgressFn& progress, StreamControls* controls) {
  StreamResult res;
  res.last_acked = journal ? journal->last_acked() : static_cast<long>(start) - 1;
  // The whole byte stream, and where each job line ends in it.
  std::string data;
  std::vector<std::pair<size_t, long>> ends;  // (end offset, job index)
  auto add = [&](const std::string& text, long idx) {
    data += text;
    if (o_.newline) data += '\n';
    ends.push_back({data.size(), idx});
  };
  for (const auto& p : preamble) add(p, -1);
  for (size_t i = start; i < job.lines.size(); ++i) add(job.lines[i].text, static_cast<long>(i));
  size_t sent = 0, acked_upto = 0;  // acked_upto: entries of `ends` done
  auto t0 = clock::now();
  StreamProgress pg;
  pg.lines_total = job.lines.size();
  double est_done = 0;
  auto ack_bytes = [&](size_t executed) {
    while (acked_upto < ends.size() && ends[acked_upto].first <= executed) {
      long idx = ends[acked_upto].second;
      if (idx >= 0) {
        res.last_acked = idx;
        ++res.lines_acked;
        est_done += job.lines[static_cast<size_t>(idx)].est_s;
        if (journal) journal->ack(static_cast<size_t>(idx));
      }
      ++acked_upto;
    }
    if (progress) {
      pg.elapsed_s = std::chrono::duration<double>(clock::now() - t0).count();
      pg.lines_acked = res.last_acked + 1 > 0 ? static_cast<size_t>(res.last_acked + 1) : 0;
      size_t k = static_cast<size_t>(std::upper_bound(ends.begin(), ends.end(), std::make_pair(sent, LONG_MAX)) - ends.begin());
      pg.lines_sent = start + (k > preamble.size() ? k - preamble.size() : 0);
      double ratio = est_done > 0.5 && pg.elapsed_s > 1 ? pg.elapsed_s / est_done : 1.0;
      pg.eta_s = std::max(0.0, job.est_total_s - est_done) * ratio;
      progress(pg);
    }
  };
  auto check_status = [&](bool final) {
    if (!o_.status_queries) return;
    int st = query('O');
    if (st & 16) {
      auto since = clock::now();
      while (st & 16) {
        if (clock::now() - since > o_.not_ready_timeout)
          throw DeviceError("the plotter is not ready (paper lever raised or view mode?) and stayed so for " +
                                      std::to_string(o_.not_ready_timeout.count() / 1000) + " s; resume when it is ready",
                                  res.last_acked, 16, true);
        std::this_thread::sleep_for(Millis(100));
        st = query('O');
      }
    }
    if (st & 32 || final) {
      // OE goes through the plotter's buffer: if that is stuck (lost bytes left an
      // unfinished instruction), OE would never be answered.
      if ((st & 32) && !(st & 8) && query('B') < buffer_ && final)
        throw DeviceError("the plotter reports an error and its buffer holds an unfinished instruction "
                                "(bytes lost to a late XOFF or no handshake?); the job is incomplete",
                                res.last_acked, 7, false);
      t_.write(o_.newline ? "OE;\n" : "OE;");
      std::string r;
      if (!read_reply(r, Millis(30000)))
        throw TransportError(TransportError::Kind::Timeout, "the plotter on " + t_.describe() + " does not answer OE");
      int code = std::atoi(r.c_str());
      if (code != 0)
        throw DeviceError("the plotter reports HP-GL error " + std::to_string(code) + " (" + error_meaning(code) +
                                    ") after line " + std::to_string(res.last_acked + 1),
                                res.last_acked, code, false);
    }
  };
  try {
    auto last_status = clock::now();
    if (o_.handshake == HpglHandshake::buffer_query) {
      for (;;) {
        if (controls && controls->abort.exchange(false)) {
          t_.write("\x1b.K");  // abort graphics: drop the plotter's buffer
          if (journal) journal->sync();
          return res;
        }
        int free = query('B');
        size_t in_buffer = static_cast<size_t>(std::max(0, buffer_ - free));
        ack_bytes(sent > in_buffer ? sent - in_buffer : 0);
        if (sent == data.size() && free >= buffer_) break;
        if (clock::now() - last_status > Millis(500)) {
          check_status(false);
          last_status = clock::now();
        }
        bool paused = controls && controls->pause.load();
        size_t room = free > o_.reserve ? static_cast<size_t>(free - o_.reserve) : 0;
        size_t chunk = paused ? 0 : std::min(room, data.size() - sent);
        if (chunk > 0) {
          t_.write(std::string_view(data).substr(sent, chunk));
          sent += chunk;
        } else {
          std::this_thread::sleep_for(o_.poll_interval);
        }
      }
    } else {
      // XON/XOFF or hardware: write in small pieces, watching for XOFF between them.
      while (sent < data.size()) {
        if (controls && controls->abort.exchange(false)) {
          if (journal) journal->sync();
          return res;
        }
        pump(Millis(0));
        if (o_.handshake == HpglHandshake::xonxoff && xoff_) {
          if (clock::now() - xoff_since_ > o_.not_ready_timeout)
            throw TransportError(TransportError::Kind::Timeout, "the plotter held XOFF for " +
                                                                    std::to_string(o_.not_ready_timeout.count() / 1000) + " s");
          pump(Millis(20));
          continue;
        }
        size_t chunk = std::min<size_t>(64, data.size() - sent);
        t_.write(std::string_view(data).substr(sent, chunk), Millis(60000));
        sent += chunk;
        // Without per-line acknowledgement, a line counts as done once written.
        ack_bytes(sent);
      }
      if (o_.status_queries) {
        // Wait until the plotter has drawn everything, or reports an error (then OE
        // below names it), or stops consuming data (an incomplete instruction left
        // after lost bytes would hold its buffer forever).
        int last_free = -1;
        auto since = clock::now();
        for (;;) {
          int st = query('O');
          if (st & (8 | 32)) break;
          int free = query('B');
          if (free != last_free) {
            last_free = free;
            since = clock::now();
          } else if (clock::now() - since > o_.not_ready_timeout) {
            throw DeviceError("the plotter stopped taking data with " + std::to_string(buffer_ - free) +
                                        " bytes in its buffer (bytes lost to a late XOFF?)",
                                    res.last_acked, 0, false);
          }
          std::this_thread::sleep_for(Millis(50));
        }
      }
    }
    check_status(true);
  } catch (const TransportError&) {
    if (journal) journal->sync();
    throw;
  } catch (const DeviceError&) {
    if (journal) journal->sync();
    throw;
  }
  if (journal) journal->done();
  res.completed = true;
  res.seconds = std::chrono::duration<double>(clock::now() - t0).count();
  return res;
}

}  // namespace stipplot::io::hpgl
