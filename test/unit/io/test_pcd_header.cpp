// The PCD header check that runs before PCL reads a saved reconstruction (io/pcd_header.h): a
// consistent file passes; each inconsistency PCL 1.13 does not survive is refused naming the file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "quadric_slam/io/pcd_header.h"

namespace fs = std::filesystem;
using quadric_slam::checkPcdFile;
using quadric_slam::PcdHeader;

namespace {

const std::string kHeader =
    "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb label\n"
    "SIZE 4 4 4 4 4\nTYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\n"
    "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA binary\n";

class PcdHeaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("pcd_header_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Writes header + body_bytes zero bytes and checks the file.
  PcdHeader check(const std::string& header, std::size_t body_bytes) {
    const std::string path = (dir_ / "cloud.pcd").string();
    std::ofstream(path, std::ios::binary) << header << std::string(body_bytes, '\0');
    return checkPcdFile(path);
  }
  void expectRefused(const std::string& header, std::size_t body_bytes, const std::string& why) {
    try {
      check(header, body_bytes);
      ADD_FAILURE() << "accepted: " << why;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("cloud.pcd"), std::string::npos) << what;
      EXPECT_NE(what.find(why), std::string::npos) << what;
    }
  }
  fs::path dir_;
};

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

}  // namespace

TEST_F(PcdHeaderTest, AConsistentFilePasses) {
  const PcdHeader h = check(kHeader, 3 * 20);
  EXPECT_EQ(h.fields.size(), 5u);
  EXPECT_EQ(h.pointBytes(), 20u);
  EXPECT_EQ(h.points, 3u);
  EXPECT_EQ(h.data, "binary");
}

// The saved map that crashed PCL's reader (fuzzing, issue 14): a damaged FIELDS line and a body
// cut short.
TEST_F(PcdHeaderTest, TheFuzzedFileThatCrashedPclIsRefused) {
  expectRefused(replaced(kHeader, "FIELDS x y z rgb label", "FI0x10LDS x y z rgb4294967296label"),
                25, "unexpected header line");
}

TEST_F(PcdHeaderTest, InconsistentHeadersAreRefused) {
  expectRefused(kHeader, 3 * 20 - 1, "the binary body holds 59 bytes");
  expectRefused(replaced(kHeader, "SIZE 4 4 4 4 4", "SIZE 4 4 4 4"), 60, "one entry per field");
  expectRefused(replaced(kHeader, "POINTS 3", "POINTS 4"), 80, "not WIDTH x HEIGHT");
  expectRefused(replaced(kHeader, "WIDTH 3", "WIDTH 4294967297"), 60, "too large");
  expectRefused(replaced(kHeader, "TYPE F F F F U", "TYPE F F F F Q"), 60, "TYPE of label");
  expectRefused(replaced(kHeader, "SIZE 4 4 4 4 4", "SIZE 4 4 2 4 4"), 60, "float field (z)");
  expectRefused(replaced(kHeader, "COUNT 1 1 1 1 1", "COUNT 1 1 1 1 0"), 60, "COUNT of label");
  expectRefused(replaced(kHeader, "HEIGHT 1\n", "HEIGHT 1\nHEIGHT 1\n"), 60, "appears twice");
  expectRefused(replaced(kHeader, "DATA binary\n", ""), 0, "before its DATA line");
  expectRefused(replaced(kHeader, "x y z rgb label", "x y x rgb label"), 60,
                "field x appears twice");
}

TEST_F(PcdHeaderTest, CompressedBodiesAreCheckedAgainstTheirSizeWords) {
  const std::string compressed = replaced(kHeader, "DATA binary", "DATA binary_compressed");
  const auto with_words = [&](std::uint32_t packed, std::uint32_t unpacked, std::size_t body) {
    std::string bytes(8 + body, '\0');
    std::memcpy(&bytes[0], &packed, 4);
    std::memcpy(&bytes[4], &unpacked, 4);
    return compressed + bytes;
  };
  const std::string path = (dir_ / "cloud.pcd").string();
  std::ofstream(path, std::ios::binary) << with_words(10, 60, 10);
  EXPECT_NO_THROW(checkPcdFile(path));
  std::ofstream(path, std::ios::binary) << with_words(100, 60, 10);
  EXPECT_THROW(checkPcdFile(path), std::runtime_error);
  std::ofstream(path, std::ios::binary) << with_words(10, 61, 10);
  EXPECT_THROW(checkPcdFile(path), std::runtime_error);
}

TEST_F(PcdHeaderTest, AMissingFileIsRefused) {
  EXPECT_THROW(checkPcdFile((dir_ / "none.pcd").string()), std::runtime_error);
}
