// A small RAII C++ wrapper over the Cyclone DDS C API: participant (optionally in its own
// configured domain), topic, writer, reader and the QoS sss-slam uses for navigation feedback:
// reliable, keep-last, transient-local, so a navigation computer that starts late still gets the
// newest correction. Samples must be plain structs (no strings or sequences): they are copied.
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>

namespace sss::transport::dds {

struct QosSettings {
  bool reliable = true;
  int32_t history_depth = 1;     // keep-last depth
  bool transient_local = true;   // late joiners get the last history_depth samples
  double max_blocking_s = 0.1;   // reliable writes block at most this long when readers lag
};

// Owns a dds_qos_t.
class Qos {
 public:
  explicit Qos(const QosSettings& settings);
  ~Qos() { dds_delete_qos(qos_); }
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  const dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

// Owns one dds_entity_t; deleting an entity deletes its children too.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  ~Entity() { reset(); }
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;

  bool good() const { return handle_ > 0; }
  dds_entity_t handle() const { return handle_; }
  // The DDS error of a failed creation, as text.
  std::string error() const { return good() ? "" : dds_strretcode(handle_); }

 private:
  void reset() {
    if (handle_ > 0) dds_delete(handle_);
    handle_ = 0;
  }
  dds_entity_t handle_ = 0;
};

// Cyclone configuration for loopback-only traffic: unicast discovery on 127.0.0.1, no
// multicast. For tests and single-host chains.
std::string loopbackConfigXml();

class Participant {
 public:
  // config_xml: a Cyclone configuration for this domain (empty: CYCLONEDDS_URI or defaults).
  explicit Participant(uint32_t domain_id, const std::string& config_xml = "");
  bool good() const { return participant_.good(); }
  std::string error() const { return participant_.error(); }
  dds_entity_t handle() const { return participant_.handle(); }

 private:
  Entity domain_;  // declared first: destroyed last
  Entity participant_;
};

template <typename Sample>
class Topic {
 public:
  Topic(const Participant& participant, const dds_topic_descriptor_t* descriptor, const std::string& name)
      : topic_(dds_create_topic(participant.handle(), descriptor, name.c_str(), nullptr, nullptr)) {}
  bool good() const { return topic_.good(); }
  std::string error() const { return topic_.error(); }
  dds_entity_t handle() const { return topic_.handle(); }

 private:
  Entity topic_;
};

template <typename Sample>
class Writer {
  static_assert(std::is_trivially_copyable_v<Sample>, "DDS samples handled here must be plain structs");

 public:
  Writer(const Participant& participant, const Topic<Sample>& topic, const QosSettings& settings = {})
      : writer_(dds_create_writer(participant.handle(), topic.handle(), Qos(settings).get(), nullptr)) {}
  bool good() const { return writer_.good(); }
  std::string error() const { return writer_.error(); }

  bool write(const Sample& sample) { return dds_write(writer_.handle(), &sample) == DDS_RETCODE_OK; }

  // Readers currently matched (discovered, compatible QoS).
  int32_t matchedReaders() const {
    dds_publication_matched_status_t status{};
    if (dds_get_publication_matched_status(writer_.handle(), &status) != DDS_RETCODE_OK) return 0;
    return static_cast<int32_t>(status.current_count);
  }

 private:
  Entity writer_;
};

template <typename Sample>
class Reader {
  static_assert(std::is_trivially_copyable_v<Sample>, "DDS samples handled here must be plain structs");

 public:
  Reader(const Participant& participant, const Topic<Sample>& topic, const QosSettings& settings = {})
      : reader_(dds_create_reader(participant.handle(), topic.handle(), Qos(settings).get(), nullptr)) {}
  bool good() const { return reader_.good(); }
  std::string error() const { return reader_.error(); }

  // Takes one sample if one is waiting. Returns false when none.
  bool take(Sample& sample) {
    void* samples[1] = {nullptr};
    dds_sample_info_t info{};
    const dds_return_t n = dds_take(reader_.handle(), samples, &info, 1, 1);
    if (n <= 0) return false;
    const bool valid = info.valid_data;
    if (valid) sample = *static_cast<const Sample*>(samples[0]);
    dds_return_loan(reader_.handle(), samples, n);
    return valid;
  }

  // Waits up to timeout_s for a sample and takes it.
  bool waitAndTake(Sample& sample, double timeout_s);

 private:
  Entity reader_;
};

// Waits until the reader has data or the timeout passes; true when data is there.
bool waitForData(dds_entity_t reader, double timeout_s);

template <typename Sample>
bool Reader<Sample>::waitAndTake(Sample& sample, double timeout_s) {
  if (take(sample)) return true;
  return waitForData(reader_.handle(), timeout_s) && take(sample);
}

}  // namespace sss::transport::dds
