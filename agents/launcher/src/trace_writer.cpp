#include "drover/launcher/trace_writer.hpp"

#include <cerrno>
#include <cstring>

namespace drover::launcher {

Result<std::unique_ptr<TraceWriter>> TraceWriter::open(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) {
    return fail(ErrorCode::io, "--trace: cannot create " + path.string() + ": " + std::strerror(errno));
  }
  return std::unique_ptr<TraceWriter>(new TraceWriter(file));
}

TraceWriter::~TraceWriter() { std::fclose(file_); }

void TraceWriter::write(TimeNs time, const std::string& type, const nlohmann::json& fields) {
  nlohmann::ordered_json line;
  line["t"] = time;
  line["type"] = type;
  for (const auto& [key, value] : fields.items()) line[key] = value;
  const std::string text = line.dump() + "\n";
  std::lock_guard lock(mutex_);
  std::fwrite(text.data(), 1, text.size(), file_);
  ++lines_;
}

void TraceWriter::flush() {
  std::lock_guard lock(mutex_);
  std::fflush(file_);
}

std::uint64_t TraceWriter::lines() const {
  std::lock_guard lock(mutex_);
  return lines_;
}

}  // namespace drover::launcher
