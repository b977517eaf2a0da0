#include "drover/launcher/trace_writer.hpp"

#include <cerrno>
#include <cstring>

namespace drover::launcher {

Result<std::unique_ptr<TraceWriter>> TraceWriter::open(const std::filesystem::path& path,
                                                       const std::vector<std::filesystem::path>& inputs) {
  for (const auto& input : inputs) {
    std::error_code error;
    if (std::filesystem::equivalent(path, input, error) && !error) {
      return fail(ErrorCode::invalid_argument,
                  "--trace: " + path.string() + " is an input of this launch; tracing would overwrite it");
    }
  }
  std::FILE* file = std::fopen(path.c_str(), "we");  // close-on-exec: the agents do not inherit it
  if (file == nullptr) {
    return fail(ErrorCode::io, "--trace: cannot create " + path.string() + ": " + std::strerror(errno));
  }
  return std::unique_ptr<TraceWriter>(new TraceWriter(file, path));
}

TraceWriter::~TraceWriter() { std::fclose(file_); }

void TraceWriter::write(TimeNs time, const std::string& type, const nlohmann::json& fields) {
  nlohmann::ordered_json line;
  line["t"] = time;
  line["type"] = type;
  for (const auto& [key, value] : fields.items()) line[key] = value;
  // Bytes that are not UTF-8 (ids or texts from a RAN, a path) are replaced: dump would
  // throw, and the line, with the figures counted after it, would be lost.
  const std::string text = line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::lock_guard lock(mutex_);
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() && write_error_ == 0) {
    write_error_ = errno != 0 ? errno : EIO;
  }
  ++lines_;
}

Status TraceWriter::flush() {
  std::lock_guard lock(mutex_);
  if (std::fflush(file_) != 0 && write_error_ == 0) write_error_ = errno != 0 ? errno : EIO;
  if (write_error_ == 0) return {};
  return fail(ErrorCode::io, "--trace: cannot write " + path_.string() + ": " + std::strerror(write_error_) +
                                 "; the trace is incomplete");
}

std::uint64_t TraceWriter::lines() const {
  std::lock_guard lock(mutex_);
  return lines_;
}

}  // namespace drover::launcher
