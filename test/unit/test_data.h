// Where the tests find real data. Two places:
// - test/data (QUADRIC_SLAM_TEST_DATA_DIR): the TUM RGB-D frames and a ground-truth excerpt that
//   ship with the package (CC BY 4.0 / BSD, see test/data/README.md), so the tests reading them
//   never skip;
// - ../shared/data beside the checkout (QUADRIC_SLAM_SHARED_DATA_DIR): data that is not shipped
//   (research-use licences, or too large). Tests reading it skip, naming the missing path, with
//   QS_SKIP_WITHOUT_SHARED_DATA.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace quadric_slam {
namespace test {

// test/data/<relative>: always present in a checkout.
inline std::filesystem::path shippedData(const std::string& relative) {
  return std::filesystem::path(QUADRIC_SLAM_TEST_DATA_DIR) / relative;
}

// ../shared/data/<relative>: may be absent (a clone without ../shared). The environment variable
// QUADRIC_SLAM_SHARED_DATA_DIR, when set, replaces ../shared/data: e.g. a missing folder shows
// without a rebuild which tests a clone without ../shared runs and which it skips.
inline std::filesystem::path sharedData(const std::string& relative) {
  const char* from_environment = std::getenv("QUADRIC_SLAM_SHARED_DATA_DIR");
  const std::filesystem::path root = from_environment && *from_environment
                                         ? from_environment
                                         : QUADRIC_SLAM_SHARED_DATA_DIR;
  return root / relative;
}

// Why a piece of ../shared/data is not in test/data, for the skip message.
inline constexpr char kResearchUseOnly[] = "research-use licence";
inline constexpr char kFullGroundTruth[] =
    "full TUM ground-truth files, too large: test/data holds an excerpt only";

inline std::string notShippedMessage(const std::filesystem::path& path, const char* reason) {
  return path.string() + " not found: this data is not shipped with the package (" + reason +
         "; see test/data/README.md), so the test is skipped";
}

}  // namespace test
}  // namespace quadric_slam

// Skips the calling test when `path` (under ../shared/data) does not exist.
#define QS_SKIP_WITHOUT_SHARED_DATA(path, reason)                                    \
  do {                                                                               \
    if (!std::filesystem::exists(path))                                              \
      GTEST_SKIP() << ::quadric_slam::test::notShippedMessage((path), (reason));     \
  } while (false)
