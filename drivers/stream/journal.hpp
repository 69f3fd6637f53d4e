#pragma once
// The resume journal kept next to a job file: which lines the device acknowledged, so
// `plot --resume` continues where a disconnect, power loss or abort left off.
#include <cstdint>
#include <string>

namespace stipplot::io {

// The job's fingerprint in the journal (FNV-1a): a job edited since it was started is refused.
uint64_t fnv1a64(const std::string& data);

struct JournalHeader {
  std::string job_path, job_hash, dialect, profile, port;
  size_t total_lines = 0;
};

// What the device proved it had done: it stood at (x, y, z) on the path of job line
// `line` (from where line - 1 leaves the pen to where `line` does), so everything the job
// draws before that point was drawn. From a status report's position on the acknowledged
// lines, or a sync line's answer (then the start of the line after it). Job units.
struct ProvenPoint {
  long line = -1;  // -1: nothing proved
  double x = 0, y = 0, z = 0;
  bool operator==(const ProvenPoint&) const = default;
};

struct JournalState {
  JournalHeader header;
  long last_acked = -1;  // index of the last line the device acknowledged
  ProvenPoint proven;    // the last point the device proved drawn up to
  bool complete = false;
  bool torn = false;     // the last record was cut short (a crash mid-write): ignored
  // The session ended with the device's buffers dropped (a reset, ESC.K): it runs no
  // line after last_acked, so last_acked + 1 is exactly where to resume.
  bool stopped = false;
};

// Append-only file JOB.journal: a JSON header line, then "ack N", "pos N X Y Z" (a
// ProvenPoint), "stopped" and "done" records, each line ending in " *" and the CRC-32 of
// what precedes it (8 hex digits). Journals without "pos" records (older ones) read as
// before: nothing proved.
// Every record is written as it happens (a killed host loses none); they are fsync'd at
// most every `sync_interval_ms` while streaming (a power loss may repeat that much),
// and always on sync() / close (device faults lose nothing).
// Reading it back, a last record cut short by a crash is detected and ignored; any
// other record that fails its CRC, and any ack outside the job, make the journal
// damaged: load() refuses it, naming the line.
class Journal {
 public:
  static std::string path_for(const std::string& job_path) { return job_path + ".journal"; }
  // Creates (or, with append, continues) the journal.
  Journal(std::string path, const JournalHeader& h, bool append = false, int sync_interval_ms = 100);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;
  void ack(size_t line);
  // The device proved it drew up to this point: written at once, made
  // durable with the acks (the sync interval), never fsync'd on its own.
  void proven(const ProvenPoint& p);
  // Moves the acknowledged point back (after an abort: acked lines the device
  // discarded from its buffer).
  void rollback_to(long line);
  // The device's buffers were dropped: it will run nothing past the last line acknowledged.
  void device_cleared();
  void done();
  void sync();
  long last_acked() const { return last_; }
  const std::string& path() const { return path_; }
  // Throws UserError if missing, malformed or damaged. O(file size).
  static JournalState load(const std::string& path);
  // A record as written, without its newline: "BODY *crc32".
  static std::string record(const std::string& body);
  // The journal belongs to this job (hash, dialect, line count) and profile (when both
  // name one); throws UserError naming what differs.
  static void check_belongs(const JournalState& st, const std::string& path, const std::string& job_hash,
                            const std::string& dialect, size_t lines, const std::string& profile);

 private:
  void append_record(const std::string& rec, bool force_sync);
  std::string path_;
  int fd_ = -1;
  long last_ = -1, last_written_ = -1;
  int sync_ms_;
  int64_t last_sync_ns_ = 0;
};

}  // namespace stipplot::io
