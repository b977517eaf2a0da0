#pragma once
// Where logical agents meet their clients on DDS (docs/logical-agent.md, "On the wire").
// A logical agent's id is its vehicle's id; its RAN's id is ran::ran_agent_id(vehicle id).

#include <cstdint>

#include "drover/dds/qos.hpp"

namespace drover::logical_agent {

/// Service drover/logical/order/{request,reply}: OrderRequest / OrderReply, addressed to
/// one logical agent through header.responder.
inline constexpr const char* kServiceArea = "logical";
inline constexpr const char* kOrderService = "order";
/// Service drover/logical/withdraw/{request,reply}: OrderWithdrawRequest / OrderWithdrawReply,
/// addressed like an order.
inline constexpr const char* kWithdrawService = "withdraw";
/// Service drover/logical/pause/{request,reply}: VehiclePauseRequest / StatusReply,
/// addressed like an order.
inline constexpr const char* kPauseService = "pause";
/// State topic of OrderProgress, keyed on the order name.
inline constexpr const char* kOrderProgressTopic = "drover/logical/order_progress";
/// State topic of VehicleState, keyed on the vehicle id.
inline constexpr const char* kVehicleStateTopic = "drover/logical/vehicle";
/// Event log topic of OperatorAlarm: a reader that matches an agent late still gets its
/// recent alarms. Every writer and reader uses alarm_writer_qos() / alarm_reader_qos() (a
/// VOLATILE writer would not match the TRANSIENT_LOCAL readers).
inline constexpr const char* kAlarmTopic = "drover/operator/alarm";
/// How many of its latest alarms each writer keeps for readers that match later.
inline constexpr std::int32_t kAlarmsKept = 100;
inline dds::TopicQos alarm_writer_qos() { return dds::TopicQos::log_writer(kAlarmsKept); }
inline dds::TopicQos alarm_reader_qos() { return dds::TopicQos::log_reader(); }
/// Event topic of MakeWayRequest (RELIABLE + VOLATILE + KEEP_ALL), read filtered on `vehicle`.
inline constexpr const char* kMakeWayTopic = "drover/logical/make_way";

}  // namespace drover::logical_agent
