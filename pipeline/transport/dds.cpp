// Cyclone DDS wrapper, see dds.hpp.
#include "pipeline/transport/dds.hpp"

namespace sss::transport::dds {

Qos::Qos(const QosSettings& settings) : qos_(dds_create_qos()) {
  dds_qset_reliability(qos_, settings.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       static_cast<dds_duration_t>(settings.max_blocking_s * 1e9));
  dds_qset_history(qos_, DDS_HISTORY_KEEP_LAST, settings.history_depth);
  dds_qset_durability(qos_, settings.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
}

std::string loopbackConfigXml() {
  return "<CycloneDDS><Domain id=\"any\">"
         "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
         "<AllowMulticast>false</AllowMulticast></General>"
         "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex>"
         "<Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>"
         "</Domain></CycloneDDS>";
}

Participant::Participant(uint32_t domain_id, const std::string& config_xml) {
  if (!config_xml.empty()) {
    domain_ = Entity(dds_create_domain(domain_id, config_xml.c_str()));
    if (!domain_.good()) {
      participant_ = Entity(domain_.handle() < 0 ? domain_.handle() : DDS_RETCODE_ERROR);
      return;
    }
  }
  participant_ = Entity(dds_create_participant(domain_id, nullptr, nullptr));
}

bool waitForData(dds_entity_t reader, double timeout_s) {
  const dds_entity_t participant = dds_get_participant(reader);
  const dds_entity_t waitset = dds_create_waitset(participant);
  if (waitset < 0) return false;
  const dds_entity_t condition = dds_create_readcondition(reader, DDS_ANY_STATE);
  dds_waitset_attach(waitset, condition, 0);
  const dds_return_t triggered = dds_waitset_wait(waitset, nullptr, 0, static_cast<dds_duration_t>(timeout_s * 1e9));
  dds_delete(condition);
  dds_delete(waitset);
  return triggered > 0;
}

}  // namespace sss::transport::dds
