#pragma once
// Makes the RAN messages of idl/ran.idl usable with the DDS layer's Writer, Reader and
// services (its MessageTraits), and registers their type objects, which content-filtered
// topics need, before the first use.

#include "drover/dds/message_types.hpp"
#include "ranPubSubTypes.h"

namespace drover::dds {

template <>
struct MessageTraits<msg::RanCommandRequest> {
  using PubSubType = msg::RanCommandRequestPubSubType;
};
template <>
struct MessageTraits<msg::RanCommandReply> {
  using PubSubType = msg::RanCommandReplyPubSubType;
};
template <>
struct MessageTraits<msg::RanStatus> {
  using PubSubType = msg::RanStatusPubSubType;
};
template <>
struct MessageTraits<msg::SimFaultRequest> {
  using PubSubType = msg::SimFaultRequestPubSubType;
};
template <>
struct MessageTraits<msg::SimFaultReply> {
  using PubSubType = msg::SimFaultReplyPubSubType;
};

}  // namespace drover::dds

namespace drover::ran {

/// Registers the type objects of idl/ran.idl once (thread-safe, idempotent).
void register_ran_type_objects();

}  // namespace drover::ran
