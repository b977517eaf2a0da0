#pragma once
// Typed publisher of one topic. With TopicQos::state() (the default) it publishes state:
// RELIABLE + TRANSIENT_LOCAL + KEEP_LAST per key, so late joiners get the last value of
// every instance.

#include <chrono>
#include <memory>
#include <string>
#include <utility>

#include "drover/common/result.hpp"
#include "drover/dds/detail/writer_core.hpp"
#include "drover/dds/message_types.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/qos.hpp"

namespace drover::dds {

/// Thread-safe. Must be destroyed before its Participant.
template <class T>
class Writer {
 public:
  /// \param topic  full topic name, e.g. "drover/topology/timeline".
  /// \return the writer, or conflict (the topic carries another type), or unavailable.
  static Result<std::unique_ptr<Writer>> create(Participant& participant, const std::string& topic,
                                                const TopicQos& qos = TopicQos::state()) {
    auto core = detail::WriterCore::create(participant, topic, type_support<T>(), qos);
    if (!core) return unexpected(core.error());
    return std::unique_ptr<Writer>(new Writer(std::move(*core)));
  }

  /// Publishes `sample` (for keyed types: the new value of its instance).
  /// \return success, or io when Fast DDS could not write it.
  Status write(const T& sample) { return core_->write(const_cast<T*>(&sample)); }

  /// Ends the instance whose key `key` carries (its other fields are not read): readers
  /// see it disposed, late joiners no longer get it, and the writer frees its last value
  /// once every reader acknowledged. A keyed state topic whose keys keep coming (orders,
  /// say) must retire the ones it is done with, or its history grows for ever.
  /// \return success, not_found when this writer never wrote the instance (or retired it
  ///         already), or io when Fast DDS could not.
  Status retire(const T& key) { return core_->retire(const_cast<T*>(&key)); }

  std::size_t matched_readers() const { return core_->matched_readers(); }
  /// Waits until at least `count` readers are matched. \return whether they are.
  bool wait_for_readers(std::size_t count, std::chrono::milliseconds timeout) const {
    return core_->wait_for_readers(count, timeout);
  }

 private:
  explicit Writer(std::unique_ptr<detail::WriterCore> core) : core_(std::move(core)) {}
  std::unique_ptr<detail::WriterCore> core_;
};

}  // namespace drover::dds
