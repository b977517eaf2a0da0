#pragma once
// Typed subscriber of one topic with a callback. With TopicQos::state() (the default) it
// reads state: RELIABLE + TRANSIENT_LOCAL + KEEP_LAST per key, so on joining it gets the
// last value of every instance, then every change.

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "drover/common/result.hpp"
#include "drover/dds/detail/reader_core.hpp"
#include "drover/dds/message_types.hpp"
#include "drover/dds/participant.hpp"
#include "drover/dds/qos.hpp"
#include "drover/dds/sample_source.hpp"

namespace drover::dds {

struct ReaderOptions {
  TopicQos qos = TopicQos::state();
  /// Optional content filter (Fast DDS's default SQL-like filter), e.g. "agent = %0" with
  /// parameters {"'vehicle7'"}; strings are single-quoted. Empty: every sample.
  std::string filter_expression;
  std::vector<std::string> filter_parameters;
};

/// Must be destroyed before its Participant, and not from inside its own callback.
template <class T>
class Reader {
 public:
  /// Runs on the reader's own thread, one sample at a time, in arrival order; it may
  /// block and may call services.
  using Callback = std::function<void(const T&)>;
  /// The same, told which writer each sample came from.
  using SourcedCallback = std::function<void(const T&, const SampleSource&)>;

  /// \return the reader, or invalid_argument (filter rejected), or conflict (the topic
  ///         carries another type), or unavailable.
  static Result<std::unique_ptr<Reader>> create(Participant& participant, const std::string& topic,
                                                Callback callback, ReaderOptions options = {}) {
    return create(
        participant, topic,
        SourcedCallback([callback = std::move(callback)](const T& sample, const SampleSource&) { callback(sample); }),
        std::move(options));
  }
  static Result<std::unique_ptr<Reader>> create(Participant& participant, const std::string& topic,
                                                SourcedCallback callback, ReaderOptions options = {}) {
    detail::ReaderSpec spec{topic,
                            type_support<T>(),
                            options.qos,
                            std::move(options.filter_expression),
                            std::move(options.filter_parameters),
                            {},
                            detail::Dispatch::own_thread};
    auto core = detail::ReaderCore::create(
        participant, std::move(spec),
        [callback = std::move(callback)](std::shared_ptr<void>& sample,
                                         const eprosima::fastdds::dds::SampleInfo& info) {
          callback(*static_cast<const T*>(sample.get()), SampleSource(info.publication_handle));
        });
    if (!core) return unexpected(core.error());
    return std::unique_ptr<Reader>(new Reader(std::move(*core)));
  }

  std::size_t matched_writers() const { return core_->matched_writers(); }
  /// Waits until at least `count` writers are matched. An events() topic is VOLATILE:
  /// what a writer sends before the match never reaches this reader, so a reader that must
  /// not miss an event waits for its writer first. \return whether they are matched.
  bool wait_for_writers(std::size_t count, std::chrono::milliseconds timeout) const {
    return core_->wait_for_writers(count, timeout);
  }

 private:
  explicit Reader(std::unique_ptr<detail::ReaderCore> core) : core_(std::move(core)) {}
  std::unique_ptr<detail::ReaderCore> core_;
};

}  // namespace drover::dds
