#pragma once
// Which generated TopicDataType (fastddsgen's <Type>PubSubType) serialises each message
// type that travels as a topic sample. A message type is usable with Writer, Reader,
// ServiceClient and ServiceServer once it has a MessageTraits specialisation: listed
// below, or declared next to its users with DROVER_DDS_MESSAGE(Type) at namespace
// drover::dds scope (Type in drover::msg).

#include <fastdds/dds/topic/TypeSupport.hpp>

#include "diagnosticsPubSubTypes.h"
#include "heartbeatPubSubTypes.h"
#include "routingPubSubTypes.h"
#include "topologyPubSubTypes.h"

namespace drover::dds {

/// Primary template left undefined: using an unlisted type fails to compile.
template <class T>
struct MessageTraits;

#define DROVER_DDS_MESSAGE(Type)              \
  template <>                                 \
  struct MessageTraits<msg::Type> {           \
    using PubSubType = msg::Type##PubSubType; \
  }

DROVER_DDS_MESSAGE(Heartbeat);
DROVER_DDS_MESSAGE(PingRequest);
DROVER_DDS_MESSAGE(PingReply);
DROVER_DDS_MESSAGE(EntityDescription);
DROVER_DDS_MESSAGE(TimelineState);
DROVER_DDS_MESSAGE(StatusReply);
DROVER_DDS_MESSAGE(ReservePrepareRequest);
DROVER_DDS_MESSAGE(ReservePrepareReply);
DROVER_DDS_MESSAGE(ReserveCommitRequest);
DROVER_DDS_MESSAGE(ReserveAbortRequest);
DROVER_DDS_MESSAGE(AllocateRequest);
DROVER_DDS_MESSAGE(AllocateReply);
DROVER_DDS_MESSAGE(ReleaseRequest);
DROVER_DDS_MESSAGE(LockRequest);
DROVER_DDS_MESSAGE(LockReply);
DROVER_DDS_MESSAGE(UnlockRequest);
DROVER_DDS_MESSAGE(DelayRequest);
DROVER_DDS_MESSAGE(DelayReply);
DROVER_DDS_MESSAGE(CancelRouteRequest);
DROVER_DDS_MESSAGE(HoldingsRequest);
DROVER_DDS_MESSAGE(HoldingsReply);
DROVER_DDS_MESSAGE(ReservationNotice);
DROVER_DDS_MESSAGE(RouteRequest);
DROVER_DDS_MESSAGE(RouteReply);

/// A TypeSupport that serialises T.
template <class T>
eprosima::fastdds::dds::TypeSupport type_support() {
  return eprosima::fastdds::dds::TypeSupport(new typename MessageTraits<T>::PubSubType());
}

/// Registers the type objects of every IDL file of idl/ with Fast DDS's TypeObjectFactory,
/// which content-filtered topics need. Idempotent and thread-safe; Participant::create
/// calls it.
void register_type_objects();

}  // namespace drover::dds
