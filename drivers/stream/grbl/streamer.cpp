#include "drivers/stream/grbl/streamer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <thread>

#include "drivers/stream/grbl/codes.hpp"

namespace stipplot::io::grbl {

using clock = std::chrono::steady_clock;

Mode parse_mode(const std::string& s) {
  if (s == "counting" || s == "character-counting" || s == "cc") return Mode::CharacterCounting;
  if (s == "wait" || s == "send-and-wait" || s == "simple") return Mode::SendAndWait;
  throw UserError("--stream must be counting or wait, got '" + s + "'");
}

Options options_for(const DeviceProfile& p) {
  Options o;
  o.rx_buffer = p.serial.rx_buffer_bytes;
  o.planner_blocks = p.motion.lookahead_blocks;
  return o;
}

bool parse_status(const std::string& line, Status& s) {
  if (line.size() < 3 || line.front() != '<' || line.back() != '>') return false;
  std::string body = line.substr(1, line.size() - 2);
  size_t pos = 0;
  int field = 0;
  while (pos <= body.size()) {
    size_t bar = body.find('|', pos);
    std::string f = body.substr(pos, bar == std::string::npos ? std::string::npos : bar - pos);
    if (field == 0) s.state = f;
    else if (f.rfind("MPos:", 0) == 0 || f.rfind("WPos:", 0) == 0)
      std::sscanf(f.c_str() + 5, "%lf,%lf,%lf", &s.x, &s.y, &s.z);
    else if (f.rfind("Bf:", 0) == 0)
      std::sscanf(f.c_str() + 3, "%d,%d", &s.blocks_free, &s.bytes_free);
    else if (f.rfind("FS:", 0) == 0)
      std::sscanf(f.c_str() + 3, "%lf,%lf", &s.feed, &s.spindle);
    else if (f.rfind("F:", 0) == 0)
      std::sscanf(f.c_str() + 2, "%lf", &s.feed);
    ++field;
    if (bar == std::string::npos) break;
    pos = bar + 1;
  }
  return !s.state.empty();
}

Expectations expectations_for(const Job& job) {
  Expectations e;
  for (const auto& l : job.lines) {
    e.travel_x = std::max(e.travel_x, l.x);
    e.travel_y = std::max(e.travel_y, l.y);
    const std::string& t = l.text;
    for (size_t i = 0; i < t.size(); ++i) {
      if ((t[i] == 'F' || t[i] == 'S') && i + 1 < t.size()) {
        double v = std::strtod(t.c_str() + i + 1, nullptr);
        if (t[i] == 'F') e.speed_mm_s = std::max(e.speed_mm_s, v / 60);
        else e.max_s = std::max(e.max_s, v);
      }
      if (t[i] == 'M' && i + 1 < t.size() && t[i + 1] == '4') e.laser = true;
    }
  }
  return e;
}

Streamer::Streamer(Transport& t, Options o) : t_(t), o_(std::move(o)), reader_(t) {
  if (o_.rx_buffer < 16 || o_.rx_buffer > 1 << 20) throw UserError("rx buffer must be 16..1048576 bytes");
  if (!(o_.poll_hz > 0 && o_.poll_hz <= 50)) throw UserError("status poll rate must be in (0, 50] Hz");
}

void Streamer::note(const std::string& s) {
  if (o_.log) o_.log(s);
}

Status Streamer::query_status(Millis timeout) {
  t_.write("?");
  auto end = clock::now() + timeout;
  std::string line;
  while (clock::now() < end) {
    auto left = std::chrono::duration_cast<Millis>(end - clock::now());
    if (!reader_.read_line(line, std::max(left, Millis(1)))) break;
    Status s;
    if (parse_status(line, s)) {
      last_status_ = s;
      return s;
    }
  }
  throw TransportError(TransportError::Kind::Timeout, "no status report from grbl on " + t_.describe() + " within " +
                                                          std::to_string(timeout.count()) + " ms");
}

DevicePen Streamer::device_pen(const GcodePenRule& rule) {
  Status s = query_status(Millis(3000));
  DevicePen p;
  p.known = true;
  p.down = gcode_pen_down(s.spindle > 0, s.spindle, s.z, rule);
  p.x = s.x;
  p.y = s.y;
  return p;
}

void Streamer::soft_reset() {
  t_.write("\x18");
  auto end = clock::now() + o_.banner_timeout;
  std::string line;
  while (clock::now() < end) {
    if (reader_.read_line(line, Millis(100)) && line.rfind("Grbl ", 0) == 0) return;
  }
  throw TransportError(TransportError::Kind::Timeout, "grbl did not restart after a soft reset (Ctrl-X) within " +
                                                          std::to_string(o_.banner_timeout.count()) + " ms");
}

void Streamer::connect() {
  // An Arduino resets when the port opens and prints its banner; a board that did not
  // reset answers a status query instead; failing both, ask for a soft reset.
  std::string line;
  bool alive = false;
  auto end = clock::now() + Millis(400);
  while (clock::now() < end && !alive)
    if (reader_.read_line(line, Millis(50)) && line.rfind("Grbl ", 0) == 0) alive = true;
  Status st;
  if (!alive) {
    try {
      st = query_status(o_.probe_timeout);
      alive = true;
    } catch (const TransportError& e) {
      if (e.kind() != TransportError::Kind::Timeout) throw;
    }
  }
  if (!alive) {
    try {
      soft_reset();
    } catch (const TransportError& e) {
      if (e.kind() != TransportError::Kind::Timeout) throw;
      throw TransportError(TransportError::Kind::Timeout,
                           "no answer from grbl on " + t_.describe() + " within " +
                               std::to_string(o_.banner_timeout.count() / 1000) +
                               " s: is it a grbl device, powered, and set to the profile's baud rate?");
    }
  }
  st = query_status(Millis(3000));
  if (st.state.rfind("Alarm", 0) == 0) {
    if (!o_.unlock)
      throw UserError("grbl is in ALARM state: check the machine, then unlock it (pass --unlock to send $X)");
    t_.write("$X\n");
    std::string r;
    do r = reply_line(Millis(3000));
    while (r.rfind("ok", 0) != 0 && r.rfind("error", 0) != 0);
    note("grbl was in ALARM; unlocked with $X");
  }
  // Still finishing earlier work (after a reconnect): wait for it.
  auto wait_end = clock::now() + std::chrono::minutes(30);
  while ((st.state == "Run" || st.state.rfind("Hold", 0) == 0 || st.state == "Jog") && clock::now() < wait_end) {
    if (st.state.rfind("Hold", 0) == 0) t_.write("~");
    std::this_thread::sleep_for(Millis(100));
    st = query_status(Millis(3000));
  }
  reader_.clear();
}

std::string Streamer::reply_line(Millis timeout) {
  std::string line;
  auto end = clock::now() + timeout;
  while (clock::now() < end) {
    if (!reader_.read_line(line, Millis(50))) continue;
    if (line.front() == '<') continue;  // a stray status report
    return line;
  }
  throw TransportError(TransportError::Kind::Timeout, "no reply from grbl on " + t_.describe());
}

std::map<int, double> Streamer::read_settings() {
  t_.write("$$\n");
  std::map<int, double> s;
  for (;;) {
    std::string line = reply_line(Millis(5000));
    if (line == "ok") break;
    if (line.rfind("error:", 0) == 0)
      throw UserError("grbl refused $$ (" + line + "): " + error_meaning(std::atoi(line.c_str() + 6)));
    int k;
    double v;
    if (std::sscanf(line.c_str(), "$%d=%lf", &k, &v) == 2) s[k] = v;
  }
  return s;
}

std::vector<std::string> Streamer::check_settings(const std::map<int, double>& s, const Expectations& e) {
  std::vector<std::string> w;
  auto get = [&](int k) { auto it = s.find(k); return it == s.end() ? -1.0 : it->second; };
  char b[256];
  for (int axis = 0; axis < 2; ++axis) {
    double rate = get(110 + axis);
    if (rate > 0 && e.speed_mm_s * 60 > rate * 1.0001) {
      std::snprintf(b, sizeof b, "grbl's max rate $%d=%.0f mm/min is below the job's feed %.0f mm/min: it will move slower than planned",
                    110 + axis, rate, e.speed_mm_s * 60);
      w.push_back(b);
    }
  }
  if (get(20) > 0) {
    if ((get(130) >= 0 && e.travel_x > get(130) + 1e-6) || (get(131) >= 0 && e.travel_y > get(131) + 1e-6)) {
      std::snprintf(b, sizeof b,
                    "the job reaches %.1f x %.1f mm but grbl's soft limits ($130=%.1f, $131=%.1f) are smaller: it would stop with ALARM:2",
                    e.travel_x, e.travel_y, get(130), get(131));
      throw UserError(b);
    }
  }
  if (get(30) > 0 && e.max_s > get(30) + 1e-9) {
    std::snprintf(b, sizeof b, "the job uses S%.0f but grbl's max spindle speed is $30=%.0f: S values above it are clamped",
                  e.max_s, get(30));
    w.push_back(b);
  }
  if (e.laser && get(32) == 0) w.push_back("laser job but grbl's laser mode is off ($32=0): it will pause at every power change");
  if (!e.laser && get(32) == 1) w.push_back("grbl's laser mode is on ($32=1) but this is not a laser profile");
  if (get(10) >= 0 && !(static_cast<int>(get(10)) & 2))
    w.push_back("grbl's status reports omit buffer data ($10 lacks 2): progress uses acknowledged lines only");
  return w;
}

StreamResult Streamer::stream(const Job& job, size_t start, const std::vector<std::string>& preamble, Journal* journal,
                              const ProgressFn& progress, StreamControls* controls) {
  StreamResult res;
  res.last_acked = journal ? journal->last_acked() : static_cast<long>(start) - 1;
  const size_t n_pre = preamble.size();
  const size_t total = n_pre + (job.lines.size() > start ? job.lines.size() - start : 0);
  auto item_text = [&](size_t i) -> const std::string& { return i < n_pre ? preamble[i] : job.lines[start + i - n_pre].text; };
  auto item_index = [&](size_t i) -> long { return i < n_pre ? -1 : static_cast<long>(start + i - n_pre); };
  struct Inflight {
    size_t item;
    size_t bytes;
  };
  std::deque<Inflight> inflight;
  size_t inflight_bytes = 0, next = 0;
  // Acknowledged motion lines not yet known executed, for the journal after an abort.
  std::deque<long> acked_motion;
  auto t0 = clock::now();
  auto last_rx = t0, next_poll = t0;
  int idle_polls = 0;
  auto idle_first = t0;
  bool paused = false, finishing = false;
  long m0_released = -2;
  double est_done = 0;
  StreamProgress pg;
  pg.lines_total = job.lines.size();
  pg.lines_acked = start;
  auto report = [&] {
    if (!progress) return;
    pg.elapsed_s = std::chrono::duration<double>(clock::now() - t0).count();
    pg.lines_sent = start + (next > n_pre ? next - n_pre : 0);
    // ETA: the job's time model, corrected by how fast it has really gone.
    double est_left = std::max(0.0, job.est_total_s - est_done);
    double ratio = est_done > 0.5 && pg.elapsed_s > 1 ? pg.elapsed_s / est_done : 1.0;
    pg.eta_s = est_left * ratio;
    pg.state = last_status_.state;
    pg.x = last_status_.x;
    pg.y = last_status_.y;
    progress(pg);
  };
  // Lines grbl acknowledged that its planner may still hold (a reset discards them).
  auto executed_estimate = [&]() -> long {
    int in_planner = last_status_.blocks_free >= 0 ? o_.planner_blocks - last_status_.blocks_free : o_.planner_blocks;
    in_planner = std::clamp(in_planner, 0, static_cast<int>(acked_motion.size()));
    if (in_planner == 0) return res.last_acked;
    long first_unexecuted = acked_motion[acked_motion.size() - static_cast<size_t>(in_planner)];
    return first_unexecuted - 1;
  };
  auto acknowledge = [&](const Inflight& f) {
    long idx = item_index(f.item);
    if (idx < 0) return;
    res.last_acked = idx;
    ++res.lines_acked;
    pg.lines_acked = static_cast<size_t>(idx) + 1;
    est_done += job.lines[static_cast<size_t>(idx)].est_s;
    if (job.lines[static_cast<size_t>(idx)].motion) {
      acked_motion.push_back(idx);
      if (acked_motion.size() > 64) acked_motion.pop_front();
    }
    if (journal) journal->ack(static_cast<size_t>(idx));
  };
  auto sync_journal = [&] {
    if (journal) journal->sync();
  };
  try {
    for (;;) {
      auto now = clock::now();
      if (controls) {
        if (controls->abort.exchange(false)) {
          t_.write("!");
          std::this_thread::sleep_for(Millis(200));
          try {
            query_status(Millis(2000));
          } catch (const TransportError&) {
          }
          long done = executed_estimate();
          soft_reset();
          if (journal) journal->rollback_to(done);
          res.last_acked = done;
          res.seconds = std::chrono::duration<double>(clock::now() - t0).count();
          note("job aborted; the machine was reset. Resume continues after line " + std::to_string(done + 1));
          return res;
        }
        if (controls->pause.exchange(false) && !paused) {
          t_.write("!");
          paused = true;
          if (o_.lift_on_pause) {
            std::this_thread::sleep_for(Millis(100));
            t_.write("\x9e");  // spindle stop override: lifts a servo pen while held
          }
          note("paused (feed hold)");
        }
        if (controls->resume.exchange(false) && paused) {
          t_.write("~");
          paused = false;
          note("resumed");
        }
      }
      // Send while it fits.
      while (!paused && next < total) {
        const std::string& text = item_text(next);
        size_t bytes = text.size() + 1;
        bool fits = o_.mode == Mode::CharacterCounting ? inflight_bytes + bytes <= static_cast<size_t>(o_.rx_buffer)
                                                       : inflight.empty();
        if (o_.mode == Mode::CharacterCounting && inflight.empty() && bytes > static_cast<size_t>(o_.rx_buffer))
          fits = true;  // longer than the buffer: grbl will say error:11
        if (!fits) break;
        t_.write(text + "\n");
        inflight.push_back({next, bytes});
        inflight_bytes += bytes;
        ++next;
      }
      if (next == total && inflight.empty()) {
        if (!finishing) {
          finishing = true;
          next_poll = now;
        }
        if ((last_status_.state == "Idle" && idle_polls > 0) || last_status_.state == "Check") break;
      }
      if (now >= next_poll) {
        t_.write("?");
        next_poll = now + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1.0 / o_.poll_hz));
      }
      std::string line;
      auto wait = std::clamp(std::chrono::duration_cast<Millis>(next_poll - clock::now()), Millis(1), Millis(50));
      if (!reader_.read_line(line, wait)) {
        if (clock::now() - last_rx > o_.silence_timeout)
          throw TransportError(TransportError::Kind::Timeout,
                               "grbl on " + t_.describe() + " stopped answering (nothing for " +
                                   std::to_string(o_.silence_timeout.count() / 1000) + " s, not even status reports)");
        continue;
      }
      last_rx = clock::now();
      if (line == "ok") {
        if (inflight.empty()) {
          note("unexpected 'ok' from grbl (ignored)");
          continue;
        }
        Inflight f = inflight.front();
        inflight.pop_front();
        inflight_bytes -= f.bytes;
        acknowledge(f);
        report();
      } else if (line.rfind("error:", 0) == 0) {
        int code = std::atoi(line.c_str() + 6);
        if (inflight.empty()) {
          note("grbl reported " + line + " with no line outstanding: " + error_meaning(code));
          continue;
        }
        Inflight f = inflight.front();
        inflight.pop_front();
        inflight_bytes -= f.bytes;
        long idx = item_index(f.item);
        std::string where = idx >= 0 ? "line " + std::to_string(idx + 1) : "resume preamble";
        std::string msg = "grbl error:" + std::to_string(code) + " at " + where + " `" + item_text(f.item) +
                          "`: " + error_meaning(code);
        res.errors.push_back({idx, code});
        if (o_.skip_errors || idx < 0) {
          ++res.errors_skipped;
          note(msg + " (skipped)");
          if (idx >= 0) acknowledge(f);
          continue;
        }
        // Stop sending; the lines already in grbl's buffer still run: collect them.
        auto end = clock::now() + Millis(10000);
        while (!inflight.empty() && clock::now() < end) {
          std::string r;
          if (!reader_.read_line(r, Millis(100))) continue;
          if (r == "ok" || r.rfind("error:", 0) == 0) {
            Inflight g = inflight.front();
            inflight.pop_front();
            if (r == "ok") acknowledge(g);
          }
        }
        sync_journal();
        throw DeviceError(msg + " (the job stopped; that line was not executed)", idx, code, false);
      } else if (line.rfind("ALARM:", 0) == 0) {
        int code = std::atoi(line.c_str() + 6);
        long done = executed_estimate();
        long idx = inflight.empty() ? res.last_acked : item_index(inflight.front().item);
        // Leave the port sane: reset flushes grbl's buffers and restarts its parser.
        try {
          soft_reset();
        } catch (const TransportError&) {
        }
        if (journal) journal->rollback_to(done);
        res.last_acked = done;
        throw DeviceError("grbl ALARM:" + std::to_string(code) + " near line " + std::to_string(idx + 1) + ": " +
                              alarm_meaning(code) + " The machine is locked: check it, unlock ($X) or re-home, then resume.",
                          idx, code, true);
      } else if (line.front() == '<') {
        Status s;
        if (!parse_status(line, s)) continue;
        last_status_ = s;
        report();
        if (s.state.rfind("Alarm", 0) == 0) {
          long done = executed_estimate();
          if (journal) journal->rollback_to(done);
          res.last_acked = done;
          throw DeviceError("grbl entered ALARM state during the job (see the machine); resume after unlocking", -1, 0, true);
        }
        if (s.state.rfind("Hold", 0) == 0 && !paused && !inflight.empty()) {
          // A program pause (M0): the pen change or whatever the job asks for.
          const std::string& text = item_text(inflight.front().item);
          bool is_m0 = text.find("M0") != std::string::npos || text.find("M00") != std::string::npos;
          if (is_m0 && m0_released != static_cast<long>(inflight.front().item)) {
            bool go = o_.on_pause_m0 ? o_.on_pause_m0(text) : true;
            if (!go) {
              sync_journal();
              throw UserError("stopped at the pause on line " + std::to_string(item_index(inflight.front().item) + 1));
            }
            m0_released = static_cast<long>(inflight.front().item);
            t_.write("~");
          }
        }
        // Lost replies: grbl idle, its buffers empty, yet lines unacknowledged.
        bool empty = s.state == "Idle" && (s.blocks_free < 0 || s.blocks_free == o_.planner_blocks) &&
                     (s.bytes_free < 0 || s.bytes_free == o_.rx_buffer);
        if (empty) {
          if (idle_polls++ == 0) idle_first = clock::now();
          if (!inflight.empty() && idle_polls >= 3 && clock::now() - idle_first > o_.lost_reply_after) {
            res.warnings.push_back("grbl went idle without acknowledging " + std::to_string(inflight.size()) +
                                   " line(s): a reply was lost; counting them as done");
            note(res.warnings.back());
            while (!inflight.empty()) {
              acknowledge(inflight.front());
              inflight.pop_front();
            }
            inflight_bytes = 0;
            idle_polls = 0;
          }
        } else {
          idle_polls = 0;
        }
      } else if (line.rfind("Grbl ", 0) == 0) {
        long done = executed_estimate();
        if (journal) journal->rollback_to(done);
        res.last_acked = done;
        throw DeviceError("grbl restarted during the job (reset or power loss); its buffer was lost. Resume continues after line " +
                              std::to_string(done + 1),
                          done, 0, true);
      } else if (line.front() == '[') {
        note("grbl: " + line);
      } else {
        note("unrecognised reply from grbl: '" + line + "' (ignored)");
      }
    }
  } catch (const TransportError& e) {
    sync_journal();
    throw;
  }
  if (journal) journal->done();
  res.completed = true;
  res.seconds = std::chrono::duration<double>(clock::now() - t0).count();
  pg.lines_acked = job.lines.size();
  report();
  return res;
}

std::vector<std::pair<long, int>> Streamer::check_job(const Job& job) {
  t_.write("$C\n");
  for (;;) {
    std::string r = reply_line(Millis(5000));
    if (r == "ok") break;
    if (r.rfind("error:", 0) == 0) throw UserError("grbl refused check mode ($C): " + error_meaning(std::atoi(r.c_str() + 6)));
  }
  Options keep = o_;
  o_.skip_errors = true;
  o_.log = {};
  StreamResult res;
  try {
    res = stream(job, 0, {}, nullptr);
  } catch (...) {
    o_ = keep;
    throw;
  }
  o_ = keep;
  // Leaving check mode soft-resets grbl.
  t_.write("$C\n");
  auto end = clock::now() + o_.banner_timeout;
  std::string line;
  while (clock::now() < end)
    if (reader_.read_line(line, Millis(100)) && line.rfind("Grbl ", 0) == 0) break;
  reader_.clear();
  return res.errors;
}

}  // namespace stipplot::io::grbl
