#pragma once
// Conversions between drover::Error (inside the libraries) and msg::Error (in every reply).

#include "common.h"
#include "drover/common/result.hpp"

namespace drover::dds {

/// The wire code of an error code (never ERROR_NONE).
msg::ErrorCode to_wire(ErrorCode code) noexcept;

/// The wire form of an error.
msg::Error to_wire(const Error& error);

/// The wire form of success: ERROR_NONE and an empty message.
msg::Error wire_ok();

/// Success for ERROR_NONE, otherwise the error; an unknown wire code becomes `internal`
/// with a message that says so (a peer built from newer IDL).
Status from_wire(const msg::Error& error);

}  // namespace drover::dds
