#include "drover/dds/sample_source.hpp"

#include <sstream>

#include <fastdds/rtps/common/Guid.h>

namespace drover::dds {

std::string SampleSource::text() const {
  std::ostringstream out;
  out << eprosima::fastrtps::rtps::iHandle2GUID(writer_);
  return out.str();
}

}  // namespace drover::dds
