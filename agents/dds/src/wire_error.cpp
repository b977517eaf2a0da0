#include "drover/dds/wire_error.hpp"

#include <string>

namespace drover::dds {

msg::ErrorCode to_wire(ErrorCode code) noexcept {
  switch (code) {
    case ErrorCode::invalid_argument: return msg::ERROR_INVALID_ARGUMENT;
    case ErrorCode::not_found: return msg::ERROR_NOT_FOUND;
    case ErrorCode::conflict: return msg::ERROR_CONFLICT;
    case ErrorCode::not_permitted: return msg::ERROR_NOT_PERMITTED;
    case ErrorCode::unavailable: return msg::ERROR_UNAVAILABLE;
    case ErrorCode::io: return msg::ERROR_IO;
    case ErrorCode::parse: return msg::ERROR_PARSE;
    case ErrorCode::timeout: return msg::ERROR_TIMEOUT;
    case ErrorCode::internal: return msg::ERROR_INTERNAL;
  }
  return msg::ERROR_INTERNAL;
}

msg::Error to_wire(const Error& error) {
  msg::Error out;
  out.code(to_wire(error.code));
  out.message(error.message);
  return out;
}

msg::Error wire_ok() {
  msg::Error out;
  out.code(msg::ERROR_NONE);
  return out;
}

Status from_wire(const msg::Error& error) {
  switch (error.code()) {
    case msg::ERROR_NONE: return {};
    case msg::ERROR_INVALID_ARGUMENT: return fail(ErrorCode::invalid_argument, error.message());
    case msg::ERROR_NOT_FOUND: return fail(ErrorCode::not_found, error.message());
    case msg::ERROR_CONFLICT: return fail(ErrorCode::conflict, error.message());
    case msg::ERROR_NOT_PERMITTED: return fail(ErrorCode::not_permitted, error.message());
    case msg::ERROR_UNAVAILABLE: return fail(ErrorCode::unavailable, error.message());
    case msg::ERROR_IO: return fail(ErrorCode::io, error.message());
    case msg::ERROR_PARSE: return fail(ErrorCode::parse, error.message());
    case msg::ERROR_TIMEOUT: return fail(ErrorCode::timeout, error.message());
    case msg::ERROR_INTERNAL: return fail(ErrorCode::internal, error.message());
  }
  return fail(ErrorCode::internal, "unknown wire error code " +
                                       std::to_string(static_cast<int>(error.code())) + ": " +
                                       error.message());
}

}  // namespace drover::dds
