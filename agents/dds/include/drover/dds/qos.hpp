#pragma once
// The QoS of Drover's topics (docs/dds.md "QoS"). Every topic is RELIABLE; readers are set
// explicitly because Fast DDS 2.9 defaults readers to BEST_EFFORT + VOLATILE.

#include <chrono>
#include <cstdint>

#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

namespace drover::dds {

/// What a writer keeps and what a late-joining reader gets.
struct TopicQos {
  /// TRANSIENT_LOCAL (late joiners get the kept samples) or VOLATILE.
  bool transient_local = true;
  /// KEEP_LAST depth, counted per instance for keyed types; 0 means KEEP_ALL.
  std::int32_t history_depth = 1;
  /// Deadline: a writer promises a sample per instance at least this often and a reader
  /// reports instances that miss it; zero means no deadline. A reader's deadline must not
  /// be shorter than its writers' or they do not match.
  std::chrono::milliseconds deadline{0};

  /// State topics: RELIABLE + TRANSIENT_LOCAL + KEEP_LAST(depth) per key, so a late
  /// joiner gets the last `depth` values of every instance.
  static TopicQos state(std::int32_t depth = 1) { return TopicQos{true, depth, {}}; }
  /// Event topics (notices): RELIABLE + VOLATILE + KEEP_ALL, nothing dropped in bursts.
  static TopicQos events() { return TopicQos{false, 0, {}}; }
  /// Request and reply topics of services: as events; a reply is only written once the
  /// requester's reply reader has matched, so nothing needs to be kept for late joiners.
  static TopicQos service() { return events(); }
  /// Event logs (operator alarms), writer side: RELIABLE + TRANSIENT_LOCAL + KEEP_LAST(depth),
  /// so that a reader that matches later still gets the writer's last `depth` samples: an
  /// operator's console started after the agent, or an agent's first events written before
  /// discovery matched its readers (a VOLATILE writer loses those).
  static TopicQos log_writer(std::int32_t depth) { return TopicQos{true, depth, {}}; }
  /// Event logs, reader side: RELIABLE + TRANSIENT_LOCAL + KEEP_ALL, so that a burst (the
  /// kept samples of every writer at once) is taken whole.
  static TopicQos log_reader() { return TopicQos{true, 0, {}}; }
};

/// The DataWriterQos for `qos` (RELIABLE; write() blocks at most 1 s on a full history;
/// content filters are left to the readers).
eprosima::fastdds::dds::DataWriterQos writer_qos(const TopicQos& qos);

/// The DataReaderQos for `qos` (RELIABLE, set explicitly).
eprosima::fastdds::dds::DataReaderQos reader_qos(const TopicQos& qos);

}  // namespace drover::dds
