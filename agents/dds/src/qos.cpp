#include "drover/dds/qos.hpp"

namespace drover::dds {
namespace {

namespace fdds = eprosima::fastdds::dds;

eprosima::fastrtps::Duration_t to_duration(std::chrono::milliseconds ms) {
  return eprosima::fastrtps::Duration_t(static_cast<long double>(ms.count()) / 1000.0L);
}

template <class EndpointQos>
void apply(const TopicQos& qos, EndpointQos& out) {
  out.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  out.durability().kind =
      qos.transient_local ? fdds::TRANSIENT_LOCAL_DURABILITY_QOS : fdds::VOLATILE_DURABILITY_QOS;
  if (qos.history_depth > 0) {
    out.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    out.history().depth = qos.history_depth;
  } else {
    out.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  }
  if (qos.deadline.count() > 0) out.deadline().period = to_duration(qos.deadline);
  // Fast DDS limits keyed endpoints to 10 instances by default: a topology agent's
  // entities, the vehicles' statuses and the orders are many more. <= 0 means unlimited
  // (and Fast DDS then wants max_samples unlimited too; KEEP_LAST depth still bounds each
  // instance).
  out.resource_limits().max_instances = 0;
  out.resource_limits().max_samples = 0;
}

}  // namespace

fdds::DataWriterQos writer_qos(const TopicQos& qos) {
  fdds::DataWriterQos out = fdds::DATAWRITER_QOS_DEFAULT;
  apply(qos, out);
  // A blocked reliable writer (history full of unacknowledged samples) waits this long
  // before write() fails, instead of the default 100 ms.
  out.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(1, 0);
  // A sample lost on the wire (a UDP receive buffer overflowing on a loaded host) is sent
  // again once a reader's answer to the writer's heartbeat asks for it. Fast DDS's default
  // heartbeat period is 3 s, as long as a service call's timeout: a lost reply made a
  // reservation commit time out. Heartbeats go only while samples are unacknowledged.
  out.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 100'000'000);
  // No writer-side content filtering: content-filtered readers filter on their own side.
  // Fast DDS 2.9 removes a departed remote reader's filter (deleting the filter and its map
  // entry) on its receive thread without the writer's lock, while write() evaluates the
  // filters under that lock: a RAN publishing its status as its logical agent stopped
  // crashed with SIGSEGV in DDSFilterExpression::evaluate.
  out.writer_resource_limits().reader_filters_allocation =
      eprosima::fastrtps::ResourceLimitedContainerConfig::fixed_size_configuration(0);
  return out;
}

fdds::DataReaderQos reader_qos(const TopicQos& qos) {
  fdds::DataReaderQos out = fdds::DATAREADER_QOS_DEFAULT;
  apply(qos, out);
  return out;
}

}  // namespace drover::dds
