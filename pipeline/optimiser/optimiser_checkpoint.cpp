// Checkpoint of the optimiser engine (see OptimiserEngine::saveCheckpoint). Two files:
//   PATH          text, rewritten atomically on each save: engine state, waiting closures, the graph
//                 (SlidingWindowPoseGraph::checkpointText) and which journal bytes belong to it.
//   PATH.journal  binary, append-only: a 24-byte header (magic, version, id), then records of
//                 {u32 type, u32 payload bytes, u64 FNV-1a of the payload, payload}, little-endian:
//                 the ping times and DR poses of a subframe, or a closure pair's correspondences
//                 (a later record of a pair replaces the earlier one, as a newer association round does).
// A save appends the new records and fsyncs the journal, then rewrites PATH; a load reads the journal
// only up to the length PATH names, so bytes appended by a save that crashed before PATH was
// renamed into place are ignored (and cut off by the next save).
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <type_traits>

#include "pipeline/core/state_file.hpp"
#include "pipeline/optimiser/checkpoint_io.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/optimiser/pose_manifold.hpp"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the checkpoint journal is written in host byte order");

namespace sss::optimiser {

using sss::core::Pose;
using checkpoint::TextReader;
using checkpoint::TextWriter;

namespace {

constexpr const char* kMagic = "sss-optimiser-checkpoint";
// 1 was the pose graph's checkpoint alone ("sss-pose-graph-checkpoint 1"), without ping poses and
// correspondences; 2 adds them (journal), the waiting closures, the odometer and the engine counters;
// 3 adds the INS's drift rate (InsDriftEstimator) and the odometry drift fraction the graph took from
// it. A version 2 file restores with the configured fraction (the rate is learnt again).
constexpr int kVersion = 3;
constexpr const char* kGraphOnlyMagic = "sss-pose-graph-checkpoint";
constexpr size_t kMaxFileBytes = size_t{1} << 31;  // 2 GiB: far above any mission

constexpr char kJournalMagic[8] = {'s', 's', 's', '-', 'j', 'r', 'n', 'l'};
constexpr uint32_t kJournalVersion = 2;
constexpr size_t kJournalHeaderBytes = 24;
constexpr size_t kRecordHeaderBytes = 16;
constexpr uint32_t kMaxRecordBytes = 64u << 20;  // 1 M pings or 1.8 M correspondences: corrupt beyond
constexpr uint32_t kSubframeRecord = 1;
constexpr uint32_t kCorrespondenceRecord = 2;
constexpr size_t kPingBytes = 8 + 7 * 8;
constexpr size_t kCorrespondenceBytes = 4 * 4 + 5 * 4;

class ByteWriter {
 public:
  template <typename T>
  void put(T v) {
    static_assert(std::is_arithmetic_v<T>);
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(&bytes_[at], &v, sizeof(T));
  }
  void pose(const Pose& p) {
    for (double v : toParameters(p)) put(v);
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(const std::string& bytes) : bytes_(bytes) {}
  template <typename T>
  bool get(T& v) {
    static_assert(std::is_arithmetic_v<T>);
    if (remaining() < sizeof(T)) return false;
    std::memcpy(&v, &bytes_[pos_], sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  // As stored, not validated: the record's checksum guards it, and the engine stores ping poses
  // as they came.
  bool pose(Pose& p) {
    double x[kPoseAmbientSize];
    for (double& v : x)
      if (!get(v)) return false;
    p = fromParameters(x);
    return true;
  }
  size_t remaining() const { return bytes_.size() - pos_; }

 private:
  const std::string& bytes_;
  size_t pos_ = 0;
};

void appendRecord(std::string& out, uint32_t type, const std::string& payload) {
  ByteWriter header;
  header.put(type);
  header.put(static_cast<uint32_t>(payload.size()));
  header.put(checkpoint::fnv1a(payload.data(), payload.size()));
  out += header.bytes();
  out += payload;
}

std::string journalHeader(uint64_t id) {
  ByteWriter w;
  for (char c : kJournalMagic) w.put(c);
  w.put(kJournalVersion);
  w.put(uint32_t{0});
  w.put(id);
  return w.bytes();
}

// The id of the journal at path when its header is sound and it holds at least min_bytes.
bool journalId(const std::string& path, uint64_t min_bytes, uint64_t& id) {
  std::ifstream in(path, std::ios::binary);
  std::string header(kJournalHeaderBytes, '\0');
  if (!in || !in.read(header.data(), static_cast<std::streamsize>(header.size()))) return false;
  if (std::memcmp(header.data(), kJournalMagic, sizeof(kJournalMagic)) != 0) return false;
  uint32_t version = 0;
  std::memcpy(&version, &header[8], sizeof(version));
  std::memcpy(&id, &header[16], sizeof(id));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  return version == kJournalVersion && size >= 0 && static_cast<uint64_t>(size) >= min_bytes;
}

// Appends bytes at offset `at` of an existing file (cutting off anything after `at` first), fsyncs.
Status appendAt(const std::string& path, uint64_t at, const std::string& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return Status::error(path + ": cannot open for appending: " + std::strerror(errno));
  bool ok = ::ftruncate(fd, static_cast<off_t>(at)) == 0;
  size_t done = 0;
  while (ok && done < bytes.size()) {
    const ssize_t n = ::pwrite(fd, bytes.data() + done, bytes.size() - done, static_cast<off_t>(at + done));
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<size_t>(n);
  }
  ok = ok && ::fsync(fd) == 0;
  const int write_errno = errno;
  ::close(fd);
  if (!ok) {
    return Status::error(path + ": append failed: " + std::strerror(write_errno) + "; the previous checkpoint is kept");
  }
  return Status::success();
}

uint64_t newJournalId() {
  std::random_device device;
  return (static_cast<uint64_t>(device()) << 32) ^ device() ^ 0x9e3779b97f4a7c15ull;
}

}  // namespace

// ---- save ----------------------------------------------------------------------------------------

Status OptimiserEngine::saveCheckpoint(const std::string& path) {
  auto fail = [&](const std::string& why) { return Status::error("checkpoint " + why); };

  // 1. The journal: a new one with everything, or the records since the previous save appended.
  const std::string journal_path = path + ".journal";
  uint64_t on_disk_id = 0;
  const bool fresh = journal_.path != journal_path || !journalId(journal_path, journal_.bytes, on_disk_id) ||
                     on_disk_id != journal_.id;
  Journal journal = fresh ? Journal{journal_path, newJournalId(), kJournalHeaderBytes, 0, 0} : journal_;
  std::string records;
  auto appendSubframe = [&](int64_t id, const StoredSubframe& s) {
    ByteWriter w;
    w.put(id);
    w.pose(s.T_body_sonar);
    w.put(static_cast<int32_t>(s.centre_index));
    w.put(static_cast<uint32_t>(s.dr.size()));
    for (size_t i = 0; i < s.dr.size(); ++i) {
      w.put(s.utime_us[i]);
      w.pose(s.dr[i]);
    }
    appendRecord(records, kSubframeRecord, w.bytes());
    ++journal.subframe_records;
  };
  auto appendCorrespondences = [&](const std::pair<int64_t, int64_t>& key, const StoredCorrespondences& c) {
    ByteWriter w;
    w.put(key.first);
    w.put(key.second);
    w.put(static_cast<int32_t>(c.association_round));
    w.put(c.mean_zncc);
    w.put(static_cast<uint32_t>(c.correspondences.size()));
    for (const sss::core::ClosureCorrespondence& k : c.correspondences) {
      for (int32_t v : {k.ping_index_a, k.column_a, k.ping_index_b, k.column_b}) w.put(v);
      for (float v : {k.slant_range_a_m, k.slant_range_b_m, k.landmark_a_m.x(), k.landmark_a_m.y(), k.landmark_a_m.z()})
        w.put(v);
    }
    appendRecord(records, kCorrespondenceRecord, w.bytes());
    ++journal.correspondence_records;
  };
  if (fresh) {
    for (const auto& [id, stored] : stored_) appendSubframe(id, stored);
    for (const auto& [key, stored] : correspondences_) appendCorrespondences(key, stored);
  } else {
    for (int64_t id : unjournaled_subframes_) {
      const auto found = stored_.find(id);
      if (found != stored_.end()) appendSubframe(id, found->second);  // else already forgotten
    }
    for (const auto& key : unjournaled_pairs_) appendCorrespondences(key, correspondences_.at(key));
  }
  const Status journal_written = fresh ? sss::core::writeFileAtomically(journal_path, journalHeader(journal.id) + records)
                                 : records.empty() ? Status::success()
                                                   : appendAt(journal_path, journal.bytes, records);
  if (!journal_written) return fail(journal_written.message);
  journal.bytes += records.size();

  // 2. The rewritten file: engine state, waiting closures, the graph.
  TextWriter w;
  w.word(kMagic);
  w.integer(kVersion);
  w.endLine();
  const OptimiserEngineCounters& k = counters_;
  w.word("engine");
  w.integer(newest_subframe_id_);
  w.integer(new_input_ ? 1 : 0);
  for (uint64_t v : {k.subframes_in, k.subframes_refused, k.closures_in, k.closures_refused, k.subframes_forgotten,
                     k.odometer_resets})
    w.unsignedInteger(v);
  w.endLine();
  w.word("odometer");
  w.real(odometer_offset_m_);
  w.real(last_input_distance_m_);
  w.endLine();
  const InsDriftState& drift = ins_drift_.state();
  w.word("ins_drift");
  w.integer(drift.started ? 1 : 0);
  w.real(drift.min_distance_m);
  w.real(drift.min_sigma_m);
  w.real(drift.last_distance_m);
  w.real(drift.estimate.value_or(std::numeric_limits<double>::quiet_NaN()));
  w.integer(drift.reports);
  w.unsignedInteger(k.odometry_drift_updates);
  w.real(graph_.odometryDriftFraction());
  w.endLine();
  w.word("journal");
  w.unsignedInteger(journal.id);
  w.unsignedInteger(journal.bytes);
  w.unsignedInteger(journal.subframe_records);
  w.unsignedInteger(journal.correspondence_records);
  w.endLine();
  w.word("waiting");
  w.integer(static_cast<int64_t>(waiting_.size()));
  w.endLine();
  for (const sss::core::LoopClosure& c : waiting_) {
    // Raw values (a waiting closure has not been validated yet: the graph does that on arrival).
    w.word("closure");
    for (int64_t v : {c.subframe_id_a, c.subframe_id_b, c.centre_utime_a_us, c.centre_utime_b_us}) w.integer(v);
    for (int v : {c.association_round, c.num_matches, c.num_inliers}) w.integer(v);
    for (double v : {c.range_cost, c.plane_cost, c.total_cost}) w.real(v);
    w.single(c.mean_zncc);
    for (double v : toParameters(c.T_a_b)) w.real(v);
    for (int i = 0; i < 36; ++i) w.real(c.covariance(i / 6, i % 6));
    w.integer(static_cast<int64_t>(c.correspondences.size()));
    w.endLine();
    for (const sss::core::ClosureCorrespondence& m : c.correspondences) {
      w.word("c");
      for (int v : {m.ping_index_a, m.column_a, m.ping_index_b, m.column_b}) w.integer(v);
      for (float v : {m.slant_range_a_m, m.slant_range_b_m, m.landmark_a_m.x(), m.landmark_a_m.y(), m.landmark_a_m.z()})
        w.single(v);
      w.endLine();
    }
  }
  const std::string graph = graph_.checkpointText();
  w.word("graph");
  w.integer(static_cast<int64_t>(graph.size()));
  w.endLine();
  w.raw(graph);
  std::string& text = w.text();
  checkpoint::appendChecksum(text);
  if (const Status written = sss::core::writeFileAtomically(path, text); !written) return fail(written.message);

  journal_ = journal;
  unjournaled_subframes_.clear();
  unjournaled_pairs_.clear();
  return Status::success();
}

// ---- load ----------------------------------------------------------------------------------------

Status OptimiserEngine::loadCheckpoint(const std::string& path) {
  auto fail = [&](const std::string& why) {
    return Status::error("checkpoint " + path + ": " + why + "; the optimiser state is left unchanged");
  };
  const sss::core::Result<std::string> read = checkpoint::readChecked(path, kMaxFileBytes);
  if (!read) return fail(read.message());
  const std::string& text = read.value();
  TextReader r(text);
  std::string magic;
  int64_t version = 0;
  if (!r.token(magic)) return fail("empty");
  if (magic == kGraphOnlyMagic)
    return fail("format version 1 (the pose graph alone, written by an older sss-optimiser) is not supported: "
                "version " + std::to_string(kVersion) + " is needed to restore the ping poses and correspondences");
  if (magic != kMagic) return fail("not an sss-optimiser checkpoint");
  if (!r.integer(version)) return fail("bad version field");
  if (version < 2 || version > kVersion)
    return fail("format version " + std::to_string(version) + " not supported (expected 2 to " +
                std::to_string(kVersion) + ")");

  // Everything goes into locals first: *this changes only when all of it is sound.
  OptimiserEngineCounters counters;
  int64_t newest_subframe_id = -1;
  int new_input = 0;
  if (!r.expect("engine") || !r.integer(newest_subframe_id) || !r.boundedInt(new_input, 0, 1))
    return fail("bad engine record");
  for (uint64_t* v : {&counters.subframes_in, &counters.subframes_refused, &counters.closures_in,
                      &counters.closures_refused, &counters.subframes_forgotten, &counters.odometer_resets})
    if (!r.unsignedInteger(*v)) return fail("bad engine record");
  double odometer_offset_m = 0.0, last_input_distance_m = 0.0;
  if (!r.expect("odometer") || !r.finite(odometer_offset_m) || !r.finite(last_input_distance_m))
    return fail("bad odometer record");
  InsDriftState drift;
  double drift_estimate = std::numeric_limits<double>::quiet_NaN();
  double graph_drift_fraction = options_.graph.odometry_drift_fraction;
  int drift_started = 0;
  if (version >= 3) {
    if (!r.expect("ins_drift") || !r.boundedInt(drift_started, 0, 1) || !r.finite(drift.min_distance_m) ||
        !r.finite(drift.min_sigma_m) || !r.finite(drift.last_distance_m) || !r.real(drift_estimate) ||
        !r.boundedInt(drift.reports, 0, std::numeric_limits<int>::max()) ||
        !r.unsignedInteger(counters.odometry_drift_updates) || !r.finite(graph_drift_fraction) ||
        graph_drift_fraction < 0.0)
      return fail("bad ins_drift record");
    drift.started = drift_started == 1;
    if (std::isfinite(drift_estimate)) drift.estimate = drift_estimate;
  }
  InsDriftEstimator ins_drift(options_.graph.ins_drift);
  if (!ins_drift.restore(drift)) return fail("bad ins_drift record (negative or NaN values)");
  Journal journal;
  journal.path = path + ".journal";
  if (!r.expect("journal") || !r.unsignedInteger(journal.id) || !r.unsignedInteger(journal.bytes) ||
      !r.unsignedInteger(journal.subframe_records) || !r.unsignedInteger(journal.correspondence_records) ||
      journal.bytes < kJournalHeaderBytes)
    return fail("bad journal record");

  int64_t num_waiting = 0;
  if (!r.expect("waiting") || !r.integer(num_waiting) || num_waiting < 0 ||
      static_cast<uint64_t>(num_waiting) > r.remainingRecords(60))
    return fail("bad waiting record");
  std::deque<sss::core::LoopClosure> waiting;
  for (int64_t i = 0; i < num_waiting; ++i) {
    sss::core::LoopClosure c;
    const std::string bad = "bad waiting closure " + std::to_string(i);
    constexpr int64_t kIntMin = std::numeric_limits<int>::min(), kIntMax = std::numeric_limits<int>::max();
    if (!r.expect("closure") || !r.integer(c.subframe_id_a) || !r.integer(c.subframe_id_b) ||
        !r.integer(c.centre_utime_a_us) || !r.integer(c.centre_utime_b_us) ||
        !r.boundedInt(c.association_round, kIntMin, kIntMax) || !r.boundedInt(c.num_matches, kIntMin, kIntMax) ||
        !r.boundedInt(c.num_inliers, kIntMin, kIntMax) || !r.real(c.range_cost) || !r.real(c.plane_cost) ||
        !r.real(c.total_cost) || !r.single(c.mean_zncc))
      return fail(bad);
    double x[kPoseAmbientSize];
    for (double& v : x)
      if (!r.real(v)) return fail(bad);
    c.T_a_b = fromParameters(x);
    for (int k = 0; k < 36; ++k)
      if (!r.real(c.covariance(k / 6, k % 6))) return fail(bad);
    int64_t count = 0;
    if (!r.integer(count) || count < 0 || static_cast<uint64_t>(count) > r.remainingRecords(10)) return fail(bad);
    c.correspondences.resize(static_cast<size_t>(count));
    for (sss::core::ClosureCorrespondence& m : c.correspondences) {
      if (!r.expect("c") || !r.boundedInt(m.ping_index_a, kIntMin, kIntMax) || !r.boundedInt(m.column_a, kIntMin, kIntMax) ||
          !r.boundedInt(m.ping_index_b, kIntMin, kIntMax) || !r.boundedInt(m.column_b, kIntMin, kIntMax) ||
          !r.single(m.slant_range_a_m) || !r.single(m.slant_range_b_m) || !r.single(m.landmark_a_m.x()) ||
          !r.single(m.landmark_a_m.y()) || !r.single(m.landmark_a_m.z()))
        return fail(bad + " (correspondences)");
    }
    waiting.push_back(std::move(c));
  }

  int64_t graph_bytes = 0;
  std::string graph_text;
  if (!r.expect("graph") || !r.integer(graph_bytes) || graph_bytes < 0 ||
      !r.raw(static_cast<size_t>(graph_bytes), graph_text))
    return fail("bad graph section (truncated?)");
  std::string extra;
  if (r.token(extra)) return fail("unexpected data after the graph section");
  SlidingWindowPoseGraph graph(options_.graph);
  const Status restored = graph.restoreCheckpointText(graph_text);
  if (!restored.ok) return fail("graph section: " + restored.message);
  // The odometry drifted as the INS reported when the checkpoint was written: its edges again so.
  // (Configured off since: the configured fraction, and no update to report.)
  if (!options_.graph.odometry_drift_from_ins) {
    counters.odometry_drift_updates = 0;
  } else if (counters.odometry_drift_updates > 0) {
    const Status drift_set = graph.setOdometryDriftFraction(graph_drift_fraction);
    if (!drift_set.ok) return fail("ins_drift record: " + drift_set.message);
  }

  // The journal, record by record up to the committed length.
  auto journalFail = [&](const std::string& why) { return fail("journal " + journal.path + ": " + why); };
  uint64_t on_disk_id = 0;
  if (!journalId(journal.path, journal.bytes, on_disk_id))
    return journalFail("missing, not a journal, or shorter than the " + std::to_string(journal.bytes) +
                       " bytes the checkpoint names (truncated?)");
  if (on_disk_id != journal.id) return journalFail("belongs to another checkpoint (journal id differs)");
  std::ifstream in(journal.path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(kJournalHeaderBytes));
  std::map<int64_t, StoredSubframe> stored;
  std::map<std::pair<int64_t, int64_t>, StoredCorrespondences> correspondences;
  uint64_t subframe_records = 0, correspondence_records = 0;
  std::string header(kRecordHeaderBytes, '\0'), payload;
  for (uint64_t at = kJournalHeaderBytes; at < journal.bytes;) {
    const std::string where = "record at byte " + std::to_string(at);
    if (journal.bytes - at < kRecordHeaderBytes || !in.read(header.data(), kRecordHeaderBytes))
      return journalFail(where + ": truncated header");
    uint32_t type = 0, size = 0;
    uint64_t hash = 0;
    std::memcpy(&type, &header[0], 4);
    std::memcpy(&size, &header[4], 4);
    std::memcpy(&hash, &header[8], 8);
    if (size > kMaxRecordBytes || size > journal.bytes - at - kRecordHeaderBytes)
      return journalFail(where + ": payload of " + std::to_string(size) + " bytes runs past the committed end");
    payload.resize(size);
    if (!in.read(payload.data(), size)) return journalFail(where + ": read failed");
    if (checkpoint::fnv1a(payload.data(), payload.size()) != hash) return journalFail(where + ": checksum mismatch");
    ByteReader b(payload);
    if (type == kSubframeRecord) {
      int64_t id = 0;
      int32_t centre = 0;
      uint32_t count = 0;
      StoredSubframe s;
      if (!b.get(id) || !b.pose(s.T_body_sonar) || !b.get(centre) || !b.get(count) || count == 0 ||
          b.remaining() != static_cast<size_t>(count) * kPingBytes || centre < 0 || centre >= static_cast<int32_t>(count))
        return journalFail(where + ": malformed subframe record");
      s.centre_index = centre;
      s.utime_us.resize(count);
      s.dr.resize(count);
      for (uint32_t i = 0; i < count; ++i) {
        b.get(s.utime_us[i]);
        b.pose(s.dr[i]);
      }
      stored[id] = std::move(s);
      // Forget as addSubframe does: the same ones remain.
      while (static_cast<int>(stored.size()) > options_.max_stored_subframes) stored.erase(stored.begin());
      ++subframe_records;
    } else if (type == kCorrespondenceRecord) {
      std::pair<int64_t, int64_t> key;
      int32_t round = 0;
      uint32_t count = 0;
      StoredCorrespondences c;
      if (!b.get(key.first) || !b.get(key.second) || !b.get(round) || !b.get(c.mean_zncc) || !b.get(count) ||
          b.remaining() != static_cast<size_t>(count) * kCorrespondenceBytes)
        return journalFail(where + ": malformed correspondence record");
      c.association_round = round;
      c.correspondences.resize(count);
      for (sss::core::ClosureCorrespondence& m : c.correspondences) {
        b.get(m.ping_index_a);
        b.get(m.column_a);
        b.get(m.ping_index_b);
        b.get(m.column_b);
        b.get(m.slant_range_a_m);
        b.get(m.slant_range_b_m);
        b.get(m.landmark_a_m.x());
        b.get(m.landmark_a_m.y());
        b.get(m.landmark_a_m.z());
      }
      correspondences[key] = std::move(c);  // the newest record of a pair wins
      ++correspondence_records;
    } else {
      return journalFail(where + ": unknown record type " + std::to_string(type));
    }
    at += kRecordHeaderBytes + size;
  }
  if (subframe_records != journal.subframe_records || correspondence_records != journal.correspondence_records)
    return journalFail(std::to_string(subframe_records) + " subframe and " + std::to_string(correspondence_records) +
                       " correspondence records, the checkpoint names " + std::to_string(journal.subframe_records) +
                       " and " + std::to_string(journal.correspondence_records));

  graph_ = std::move(graph);
  // The anchor was decided with the first node (the graph's checkpoint keeps its sigma).
  anchor_decided_ = graph_.numNodes() > 0;
  start_accuracy_.clear();
  stored_ = std::move(stored);
  correspondences_ = std::move(correspondences);
  waiting_ = std::move(waiting);
  newest_subframe_id_ = newest_subframe_id;
  new_input_ = new_input == 1;
  counters_ = counters;
  ins_drift_ = ins_drift;
  odometer_offset_m_ = odometer_offset_m;
  last_input_distance_m_ = last_input_distance_m;
  journal_ = journal;
  unjournaled_subframes_.clear();
  unjournaled_pairs_.clear();
  return Status::success();
}

}  // namespace sss::optimiser
