#pragma once
// IO errors name the file, the record (line, message index, frame...) and what was wrong, so the CLI can
// print one clear line and exit with code 2.
#include <stdexcept>
#include <string>
#include <string_view>

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

// A user-given text (a value, a key, a name) as messages echo it: quoted, control characters shown as '?' so the
// message stays one line, and past kEchoChars cut with its length added, so a 10 MB config value prints as
// 'abc...' (10485760 characters).
constexpr std::size_t kEchoChars = 40;
inline std::string echo(std::string_view text) {
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kEchoChars; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  if (text.size() <= kEchoChars) return out + "'";
  return out + "...' (" + std::to_string(text.size()) + " characters)";
}

}  // namespace drover::io
