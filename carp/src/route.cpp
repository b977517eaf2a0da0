#include "drover/carp/route.hpp"

namespace drover::carp {

const char* to_string(PlanFailure failure) noexcept {
  switch (failure) {
    case PlanFailure::invalid_request: return "invalid_request";
    case PlanFailure::unreachable: return "unreachable";
    case PlanFailure::restricted: return "restricted";
    case PlanFailure::locked: return "locked";
    case PlanFailure::no_window: return "no_window";
    case PlanFailure::conflict: return "conflict";
  }
  return "invalid_request";
}

Error to_error(const PlanError& error) {
  ErrorCode code = ErrorCode::unavailable;
  switch (error.reason) {
    case PlanFailure::invalid_request: code = ErrorCode::invalid_argument; break;
    case PlanFailure::restricted: code = ErrorCode::not_permitted; break;
    case PlanFailure::conflict: code = ErrorCode::conflict; break;
    case PlanFailure::unreachable:
    case PlanFailure::locked:
    case PlanFailure::no_window: code = ErrorCode::unavailable; break;
  }
  return Error{code, std::string(to_string(error.reason)) + ": " + error.message};
}

}  // namespace drover::carp
