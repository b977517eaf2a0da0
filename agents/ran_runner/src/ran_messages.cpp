#include "ran_messages.hpp"

#include <mutex>

#include "ranTypeObject.h"

namespace drover::ran {

void register_ran_type_objects() {
  static std::once_flag once;
  std::call_once(once, [] { registerranTypes(); });
}

}  // namespace drover::ran
