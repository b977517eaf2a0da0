#include "drover/dds/message_types.hpp"

#include <mutex>

#include "commonTypeObject.h"
#include "diagnosticsTypeObject.h"
#include "heartbeatTypeObject.h"
#include "topologyTypeObject.h"

namespace drover::dds {

void register_type_objects() {
  static std::once_flag once;
  std::call_once(once, [] {
    registercommonTypes();
    registerdiagnosticsTypes();
    registerheartbeatTypes();
    registertopologyTypes();
  });
}

}  // namespace drover::dds
