#include "drover/dds/message_types.hpp"

#include <mutex>

#include "register_type_objects.h"

namespace drover::dds {

void register_type_objects() {
  static std::once_flag once;
  std::call_once(once, [] { msg::register_all_type_objects(); });
}

}  // namespace drover::dds
