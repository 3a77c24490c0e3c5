#pragma once
// Deterministic mutations of valid input files for the fuzz suite: truncations, byte flips, hostile numbers
// (NaN, inf, huge, 2^70, empty), duplicated, removed and reordered lines, empty files. The random source is a
// splitmix64 generator used with plain modulo arithmetic (no std:: distributions, whose output differs between
// standard libraries), so a case number names the same mutation on every machine.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace drover::test::fuzz {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(next() % n); }

 private:
  std::uint64_t s_;
};

// Text that number parsers and range checks must survive: non-finite, overflowing (double and int64/uint64),
// denormal, negative, empty, not a number at all.
inline const std::vector<std::string>& hostileTokens() {
  static const std::vector<std::string> t = {"nan",
                                             "NaN",
                                             "-nan",
                                             "inf",
                                             "-inf",
                                             "Infinity",
                                             "1e308",
                                             "1e309",
                                             "-1e309",
                                             "4.9e-324",
                                             "0",
                                             "-0",
                                             "-1",
                                             "2147483648",
                                             "-2147483649",
                                             "9223372036854775808",
                                             "18446744073709551616",
                                             "1180591620717411303424" /* 2^70 */,
                                             "1e10",
                                             "-1e10",
                                             "",
                                             "x",
                                             "0x1p3",
                                             "1,5",
                                             "+",
                                             ".",
                                             "1e",
                                             "--1"};
  return t;
}

struct Mutation {
  std::string description;  // what was done, for the failure report
  std::string bytes;        // the mutated file content
};

namespace detail {
inline std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) {
      lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, end - start + 1));  // keeps its '\n'
    start = end + 1;
  }
  return lines;
}
inline std::string joinLines(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l;
  return s;
}
inline bool isSeparator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\n' || c == '\r' || c == '['; }
}  // namespace detail

// One text mutation chosen by rng. Field replacement targets a token that looks numeric when there is one.
inline Mutation mutateText(const std::string& text, Rng& rng) {
  using namespace detail;
  std::vector<std::string> lines = splitLines(text);
  const std::size_t n = lines.size();
  const std::size_t op = rng.below(12);
  switch (op) {
    case 0: {
      const std::size_t cut = rng.below(text.size() + 1);
      return {"truncated to " + std::to_string(cut) + " bytes", text.substr(0, cut)};
    }
    case 1: {
      std::string b = text;
      if (b.empty()) return {"empty (flip)", b};
      const std::size_t at = rng.below(b.size());
      b[at] = static_cast<char>(b[at] ^ static_cast<char>(1 + rng.below(255)));
      return {"byte " + std::to_string(at) + " flipped", b};
    }
    case 2:
    case 3:
    case 4: {  // the most useful: one number replaced by a hostile token
      std::vector<std::pair<std::size_t, std::size_t>> numeric;  // [begin, end) of number-looking tokens
      for (std::size_t i = 0; i < text.size();) {
        if (isSeparator(text[i]) || text[i] == ':') {
          ++i;
          continue;
        }
        std::size_t j = i;
        while (j < text.size() && !isSeparator(text[j])) ++j;
        const char c = text[i];
        if ((c >= '0' && c <= '9') || c == '-' || c == '.') numeric.emplace_back(i, j);
        i = j;
      }
      if (numeric.empty()) return {"unchanged (no number)", text};
      const auto [b, e] = numeric[rng.below(numeric.size())];
      const std::string& token = hostileTokens()[rng.below(hostileTokens().size())];
      std::string out = text;
      out.replace(b, e - b, token);
      return {"number '" + text.substr(b, e - b) + "' at byte " + std::to_string(b) + " -> '" + token + "'", out};
    }
    case 5: {
      if (n == 0) return {"empty (dup)", text};
      const std::size_t i = rng.below(n);
      std::string l = lines[i];
      if (l.empty() || l.back() != '\n') l += '\n';
      lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), l);
      return {"line " + std::to_string(i + 1) + " duplicated", joinLines(lines)};
    }
    case 6: {
      if (n == 0) return {"empty (remove)", text};
      const std::size_t i = rng.below(n);
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
      return {"line " + std::to_string(i + 1) + " removed", joinLines(lines)};
    }
    case 7: {
      if (n < 2) return {"single line (swap)", text};
      const std::size_t i = rng.below(n - 1);
      if (lines.back().empty() || lines.back().back() != '\n') lines.back() += '\n';
      std::swap(lines[i], lines[i + 1]);
      return {"lines " + std::to_string(i + 1) + " and " + std::to_string(i + 2) + " swapped", joinLines(lines)};
    }
    case 8:
      return {"emptied", ""};
    case 9: {
      const std::size_t i = rng.below(n + 1);
      const std::string& token = hostileTokens()[rng.below(hostileTokens().size())];
      lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), token + " " + token + "\n");
      return {"line '" + token + " " + token + "' inserted before line " + std::to_string(i + 1), joinLines(lines)};
    }
    case 10: {  // a whole file twice: every stamp duplicated, every key repeated
      return {"content repeated", text + (text.empty() || text.back() == '\n' ? "" : "\n") + text};
    }
    default: {  // one very long number (the "10 MB value echoed whole" class, kept at 200 kB for speed)
      if (n == 0) return {"empty (long)", text};
      std::string out = text;
      const std::size_t at = rng.below(text.size());
      out.insert(at, std::string(200'000, '7'));
      return {"200000 digits inserted at byte " + std::to_string(at), out};
    }
  }
}

// One binary mutation; `record` is the size of the file's records (16 for KITTI .bin, 24 for sim .bin, 1 for
// unstructured files) so that float overwrites land on fields.
inline Mutation mutateBinary(const std::string& bytes, Rng& rng, std::size_t record) {
  std::string b = bytes;
  const std::size_t op = rng.below(9);
  auto putFloat = [&](float v, const char* name) -> Mutation {
    if (b.size() < 4) return {"too short for a float", b};
    const std::size_t at = (rng.below(b.size() / 4)) * 4;
    std::memcpy(b.data() + at, &v, 4);
    return {std::string("float at byte ") + std::to_string(at) + " -> " + name, b};
  };
  switch (op) {
    case 0: {
      const std::size_t cut = rng.below(b.size() + 1);
      return {"truncated to " + std::to_string(cut) + " bytes", b.substr(0, cut)};
    }
    case 1:
      return {"last byte cut", b.empty() ? b : b.substr(0, b.size() - 1)};
    case 2: {
      std::string what;
      const std::size_t flips = 1 + rng.below(8);
      for (std::size_t k = 0; k < flips && !b.empty(); ++k) {
        const std::size_t at = rng.below(b.size());
        b[at] = static_cast<char>(b[at] ^ static_cast<char>(1 + rng.below(255)));
        what += std::to_string(at) + " ";
      }
      return {"bytes flipped at " + what, b};
    }
    case 3:
      return putFloat(std::numeric_limits<float>::quiet_NaN(), "NaN");
    case 4:
      return putFloat(rng.below(2) ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity(),
                      "inf");
    case 5:
      return putFloat(rng.below(2) ? 3.0e38f : -1.0e30f, "huge");
    case 6:
      return {"emptied", ""};
    case 7: {
      if (b.size() < record) return {"short (dup)", b};
      const std::size_t r = rng.below(b.size() / record) * record;
      b.insert(r, b.substr(r, record));
      b += std::string(rng.below(record) + 1, '\x7f');  // and a partial record at the end
      return {"record at byte " + std::to_string(r) + " duplicated, partial record appended", b};
    }
    default:
      std::fill(b.begin(), b.end(), '\0');
      return {"all bytes zero", b};
  }
}

}  // namespace drover::test::fuzz
