// A strict check of a PCD file's header against its size, made before PCL reads it: PCL 1.13's
// PCDReader trusts the header and crashes (reads out of bounds) on files whose FIELDS, SIZE, TYPE
// and COUNT lines disagree, whose POINTS is not WIDTH x HEIGHT, or whose binary body is shorter
// than the header promises (found by fuzzing saved maps). A file that passes is consistent enough
// for PCL to parse safely.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace quadric_slam {

struct PcdHeader {
  std::vector<std::string> fields;
  std::vector<int> sizes, counts;
  std::vector<char> types;
  std::size_t width = 0, height = 0, points = 0;
  std::string data;                // ascii | binary | binary_compressed
  std::size_t header_bytes = 0;    // the body starts here
  std::size_t pointBytes() const;  // bytes of one point in a binary body
};

// Parses and checks the header of the PCD file at path. Throws std::runtime_error naming the file
// and the first problem found (unreadable, a missing or repeated line, entries that do not agree,
// sizes that overflow or do not fit the file).
PcdHeader checkPcdFile(const std::string& path);

}  // namespace quadric_slam
