#pragma once
// IO errors name the file, the record (line, message index, frame...) and what was wrong, so the CLI can
// print one clear line and exit with code 2.
#include <stdexcept>
#include <string>

namespace drover::io {

class IoError : public std::runtime_error {
 public:
  IoError(std::string file, std::string record, const std::string& what)
      : std::runtime_error(file + (record.empty() ? "" : " (" + record + ")") + ": " + what),
        file_(std::move(file)),
        record_(std::move(record)) {}
  const std::string& file() const { return file_; }
  const std::string& record() const { return record_; }

 private:
  std::string file_;
  std::string record_;
};

// Throws IoError. `record` is e.g. "line 12", "message 40", "" when the whole file is at fault.
[[noreturn]] inline void fail(const std::string& file, const std::string& record, const std::string& what) {
  throw IoError(file, record, what);
}

}  // namespace drover::io
