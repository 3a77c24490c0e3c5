#pragma once
// IO errors name the file, the record (line, message index, frame...) and what was wrong, so the CLI can
// print one clear line and exit with code 2.
#include <stdexcept>
#include <string>
#include <string_view>

namespace drover::io {

// `text` as one bounded line: control characters shown as '?' and, past `max` characters, cut with its length
// added. Every error message goes through it (IoError, and main() for any other exception), so no input -- a
// 200,000-digit token, a file name of a megabyte, a value with line breaks -- can make an error longer than a line.
inline std::string boundedText(std::string_view text, std::size_t max) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < max; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c);
  }
  if (text.size() > max) out += "... (" + std::to_string(text.size()) + " characters)";
  return out;
}

class IoError : public std::runtime_error {
 public:
  // [characters] of each part (under 2000 in all): a record can name a file, a bag's topic list fills hundreds.
  static constexpr std::size_t kMaxFile = 400, kMaxRecord = 400, kMaxWhat = 1100;

  IoError(std::string file, std::string record, const std::string& what)
      : std::runtime_error(boundedText(file, kMaxFile) +
                           (record.empty() ? "" : " (" + boundedText(record, kMaxRecord) + ")") + ": " +
                           boundedText(what, kMaxWhat)),
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
