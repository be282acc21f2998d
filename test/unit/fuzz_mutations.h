// Seeded mutations of valid files for the readers' fuzz tests (the seeded random mutator the
// reliability issue allows in place of libFuzzer): bit flips, bytes that mean something to the
// formats (YAML punctuation, digits, NUL, 0xFF), numbers replaced by extreme values, truncation,
// and spans deleted, repeated or inserted. Deterministic per seed, so a failure names the case.
#pragma once

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace quadric_slam {
namespace test {

// The number of fuzz cases a test runs: default_cases, or QUADRIC_SLAM_FUZZ_CASES from the
// environment for a longer campaign (e.g. 100000 before a release).
inline int fuzzCases(int default_cases) {
  const char* text = std::getenv("QUADRIC_SLAM_FUZZ_CASES");
  const int cases = text ? std::atoi(text) : 0;
  return cases > 0 ? cases : default_cases;
}

class FuzzMutator {
 public:
  explicit FuzzMutator(std::uint64_t seed) : rng_(seed) {}

  // 1 to max_mutations mutations of `bytes`.
  std::string mutate(std::string bytes, int max_mutations = 4) {
    const int n = 1 + static_cast<int>(below(static_cast<std::size_t>(max_mutations)));
    for (int i = 0; i < n; ++i)
      mutateOnce(bytes);
    return bytes;
  }

 private:
  std::size_t below(std::size_t n) {
    return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_);
  }

  void mutateOnce(std::string& b) {
    static const std::vector<std::string> kExtremeNumbers = {
        "nan",        "-inf",        "inf",
        "1e308",      "-1e308",      "0",
        "-1",         "1e-320",      "99999999999999999999",
        "4294967296", "-2147483649", ".",
        "--1",        "0x10"};
    static const std::string kSpecialBytes = std::string(":-[]{},#&*!|>'\"%@\n\t 0123456789") +
                                             std::string(1, '\0') + std::string(1, '\xff');
    if (b.empty()) {
      b.push_back(kSpecialBytes[below(kSpecialBytes.size())]);
      return;
    }
    const std::size_t at = below(b.size());
    switch (below(8)) {
      case 0:  // flip a bit
        b[at] = static_cast<char>(b[at] ^ (1 << below(8)));
        break;
      case 1:  // a byte that means something to a parser
        b[at] = kSpecialBytes[below(kSpecialBytes.size())];
        break;
      case 2: {  // the number at `at` becomes an extreme value
        std::size_t begin = at;
        while (begin > 0 && (std::isdigit(static_cast<unsigned char>(b[begin - 1])) ||
                             b[begin - 1] == '.' || b[begin - 1] == '-' || b[begin - 1] == 'e'))
          --begin;
        std::size_t end = at;
        while (end < b.size() && (std::isdigit(static_cast<unsigned char>(b[end])) ||
                                  b[end] == '.' || b[end] == '-' || b[end] == 'e'))
          ++end;
        b.replace(begin, std::max<std::size_t>(end - begin, 1),
                  kExtremeNumbers[below(kExtremeNumbers.size())]);
        break;
      }
      case 3:  // truncate
        b.resize(at);
        break;
      case 4:  // delete a span
        b.erase(at, 1 + below(std::min<std::size_t>(64, b.size() - at)));
        break;
      case 5: {  // repeat a span
        const std::string span = b.substr(at, 1 + below(std::min<std::size_t>(256, b.size() - at)));
        b.insert(at, span);
        break;
      }
      case 6: {  // insert random bytes
        std::string noise(1 + below(16), '\0');
        for (char& c : noise)
          c = static_cast<char>(below(256));
        b.insert(at, noise);
        break;
      }
      default: {  // overwrite a 4-byte word with an extreme integer (binary headers and sizes)
        static const std::uint32_t kWords[] = {0u, 0xffffffffu, 0x7fffffffu, 0x80000000u, 1u};
        const std::uint32_t word = kWords[below(5)];
        for (int k = 0; k < 4 && at + k < b.size(); ++k)
          b[at + k] = static_cast<char>((word >> (8 * k)) & 0xff);
        break;
      }
    }
  }

  std::mt19937_64 rng_;
};

}  // namespace test
}  // namespace quadric_slam
