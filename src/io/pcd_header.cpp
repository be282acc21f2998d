#include "quadric_slam/io/pcd_header.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace quadric_slam {

namespace {

// Point counts and sizes above this are refused (a saved reconstruction holds far fewer points;
// it also keeps every product below in range).
constexpr std::size_t kMaxPoints = std::size_t(1) << 32;
constexpr std::size_t kMaxPointBytes = 1 << 16;

std::size_t parseCount(const std::string& text, const std::string& what) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || text.size() > 12)
    throw std::invalid_argument(what + " is not a whole number: '" + text + "'");
  const std::size_t value = std::stoull(text);
  if (value > kMaxPoints)
    throw std::invalid_argument(what + " " + text + " is too large");
  return value;
}

// The header of the file at path; throws std::invalid_argument naming the first problem.
PcdHeader parseHeader(const std::string& path) {
  const auto fail = [](const std::string& why) { throw std::invalid_argument(why); };
  std::ifstream in(path, std::ios::binary);
  if (!in)
    fail("cannot open it");
  std::error_code error;
  const std::uintmax_t file_size = std::filesystem::file_size(path, error);
  if (error)
    fail("cannot read its size");

  PcdHeader header;
  std::set<std::string> seen;
  std::string line;
  std::vector<std::string> size_entries, type_entries, count_entries;
  while (header.data.empty()) {
    if (!std::getline(in, line))
      fail("the header ends before its DATA line");
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream words(line);
    std::string key, word;
    words >> key;
    std::vector<std::string> values;
    while (words >> word)
      values.push_back(word);
    if (!seen.insert(key).second)
      fail("the line " + key + " appears twice");
    if (key == "VERSION") {
      continue;
    } else if (key == "FIELDS") {
      header.fields = values;
    } else if (key == "SIZE") {
      size_entries = values;
    } else if (key == "TYPE") {
      type_entries = values;
    } else if (key == "COUNT") {
      count_entries = values;
    } else if (key == "WIDTH" && values.size() == 1) {
      header.width = parseCount(values[0], "WIDTH");
    } else if (key == "HEIGHT" && values.size() == 1) {
      header.height = parseCount(values[0], "HEIGHT");
    } else if (key == "POINTS" && values.size() == 1) {
      header.points = parseCount(values[0], "POINTS");
    } else if (key == "VIEWPOINT" && values.size() == 7) {
      continue;
    } else if (key == "DATA" && values.size() == 1 &&
               (values[0] == "ascii" || values[0] == "binary" ||
                values[0] == "binary_compressed")) {
      header.data = values[0];
    } else {
      fail("unexpected header line '" + line.substr(0, 60) + "'");
    }
  }
  header.header_bytes = static_cast<std::size_t>(in.tellg());
  for (const char* required : {"FIELDS", "SIZE", "TYPE", "WIDTH", "HEIGHT", "POINTS"})
    if (!seen.count(required))
      fail(std::string("no ") + required + " line");
  const std::size_t n = header.fields.size();
  if (n == 0 || size_entries.size() != n || type_entries.size() != n ||
      (!count_entries.empty() && count_entries.size() != n))
    fail("FIELDS, SIZE, TYPE and COUNT do not have one entry per field");
  std::set<std::string> names;
  for (std::size_t i = 0; i < n; ++i) {
    if (!names.insert(header.fields[i]).second)
      fail("the field " + header.fields[i] + " appears twice");
    const std::string& size = size_entries[i];
    if (size != "1" && size != "2" && size != "4" && size != "8")
      fail("SIZE of " + header.fields[i] + " is not 1, 2, 4 or 8");
    header.sizes.push_back(size[0] - '0');
    const std::string& type = type_entries[i];
    if (type != "F" && type != "I" && type != "U")
      fail("TYPE of " + header.fields[i] + " is not F, I or U");
    if (type == "F" && size != "4" && size != "8")
      fail("a float field (" + header.fields[i] + ") must be 4 or 8 bytes");
    header.types.push_back(type[0]);
    const std::size_t count =
        count_entries.empty() ? 1 : parseCount(count_entries[i], "COUNT of " + header.fields[i]);
    if (count < 1 || count > 1024)
      fail("COUNT of " + header.fields[i] + " is outside [1, 1024]");
    header.counts.push_back(static_cast<int>(count));
  }
  if (header.pointBytes() > kMaxPointBytes)
    fail("a point is larger than " + std::to_string(kMaxPointBytes) + " bytes");
  if (header.width > 0 && header.height > kMaxPoints / header.width)
    fail("WIDTH x HEIGHT is too large");
  if (header.points != header.width * header.height)
    fail("POINTS " + std::to_string(header.points) + " is not WIDTH x HEIGHT");

  const std::size_t body = file_size - std::min<std::uintmax_t>(file_size, header.header_bytes);
  if (header.data == "binary") {
    if (header.points * header.pointBytes() > body)
      fail("the binary body holds " + std::to_string(body) + " bytes, the header promises " +
           std::to_string(header.points * header.pointBytes()));
  } else if (header.data == "binary_compressed") {
    std::uint32_t sizes[2] = {0, 0};  // compressed, uncompressed
    if (body < sizeof(sizes) || !in.read(reinterpret_cast<char*>(sizes), sizeof(sizes)))
      fail("the compressed body has no size words");
    if (sizes[0] > body - sizeof(sizes))
      fail("the compressed body is shorter than its size word says");
    if (sizes[1] != header.points * header.pointBytes())
      fail("the uncompressed size does not match POINTS x the point size");
  }
  return header;
}

}  // namespace

std::size_t PcdHeader::pointBytes() const {
  std::size_t bytes = 0;
  for (std::size_t i = 0; i < sizes.size(); ++i)
    bytes += static_cast<std::size_t>(sizes[i]) * static_cast<std::size_t>(counts[i]);
  return bytes;
}

PcdHeader checkPcdFile(const std::string& path) {
  try {
    return parseHeader(path);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": not a valid PCD file: " + e.what());
  }
}

}  // namespace quadric_slam
