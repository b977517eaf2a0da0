#pragma once
// Makes the messages of idl/logical.idl usable with the DDS layer's Writer, Reader and
// services. (Their type objects, which content filters need, are registered with every
// IDL's by Participant::create.)

#include "drover/dds/message_types.hpp"
#include "logicalPubSubTypes.h"

namespace drover::dds {

DROVER_DDS_MESSAGE(OrderRequest);
DROVER_DDS_MESSAGE(OrderReply);
DROVER_DDS_MESSAGE(OrderWithdrawRequest);
DROVER_DDS_MESSAGE(OrderWithdrawReply);
DROVER_DDS_MESSAGE(VehiclePauseRequest);
DROVER_DDS_MESSAGE(OrderProgress);
DROVER_DDS_MESSAGE(VehicleState);
DROVER_DDS_MESSAGE(OperatorAlarm);
DROVER_DDS_MESSAGE(MakeWayRequest);

}  // namespace drover::dds
