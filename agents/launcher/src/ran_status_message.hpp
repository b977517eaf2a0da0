#pragma once
// Makes drover/ran/status readable with the DDS layer here. (The RAN runner declares the
// same trait in its own sources, agents/ran_runner/src/ran_messages.hpp, which are not
// public; the two declarations are identical.)

#include "drover/dds/message_types.hpp"
#include "ranPubSubTypes.h"

namespace drover::dds {

DROVER_DDS_MESSAGE(RanStatus);

}  // namespace drover::dds
