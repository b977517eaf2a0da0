#pragma once
// Makes the RAN messages of idl/ran.idl usable with the DDS layer's Writer, Reader and
// services. (Their type objects, which content filters need, are registered with every
// IDL's by Participant::create.)

#include "drover/dds/message_types.hpp"
#include "ranPubSubTypes.h"

namespace drover::dds {

DROVER_DDS_MESSAGE(RanCommandRequest);
DROVER_DDS_MESSAGE(RanCommandReply);
DROVER_DDS_MESSAGE(RanStatus);
DROVER_DDS_MESSAGE(SimFaultRequest);
DROVER_DDS_MESSAGE(SimFaultReply);

}  // namespace drover::dds
