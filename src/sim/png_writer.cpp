#include "quadric_slam/sim/png_writer.h"

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace quadric_slam {
namespace {

void putBigEndian32(std::vector<unsigned char>* out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out->push_back(static_cast<unsigned char>(value >> shift));
}

// One chunk: length, type, data, CRC of type and data (PNG specification, section 5.3).
void putChunk(std::vector<unsigned char>* out, const char* type, const unsigned char* data,
              std::size_t size) {
  putBigEndian32(out, static_cast<std::uint32_t>(size));
  const std::size_t start = out->size();
  out->insert(out->end(), type, type + 4);
  if (size > 0)
    out->insert(out->end(), data, data + size);
  putBigEndian32(
      out, static_cast<std::uint32_t>(crc32(0L, out->data() + start, static_cast<uInt>(size + 4))));
}

}  // namespace

std::vector<unsigned char> encodePng(const cv::Mat& image, int level) {
  if (level < 0 || level > 9)
    throw std::invalid_argument("encodePng: level must be in [0, 9]");
  const int type = image.type();
  if (type != CV_8UC3 && type != CV_8UC1 && type != CV_16UC1)
    throw std::invalid_argument("encodePng: image must be CV_8UC3, CV_8UC1 or CV_16UC1");
  const int width = image.cols, height = image.rows;
  const int bytes_per_pixel = static_cast<int>(image.elemSize());
  const std::size_t row_bytes = static_cast<std::size_t>(width) * bytes_per_pixel;
  // Filter "Up" suits the colour images, "Sub" the depth and label images; for 8-bit images
  // run-length matching compresses the residuals about as well as full deflate, faster.
  const unsigned char filter = type == CV_8UC3 ? 2 : 1;
  const int strategy = type == CV_16UC1 ? Z_DEFAULT_STRATEGY : Z_RLE;

  std::vector<unsigned char> filtered((row_bytes + 1) * height);
  std::vector<unsigned char> previous(row_bytes, 0), current(row_bytes);
  for (int v = 0; v < height; ++v) {
    const unsigned char* source = image.ptr<unsigned char>(v);
    if (type == CV_16UC1) {  // PNG stores 16-bit samples big-endian
      for (std::size_t i = 0; i < row_bytes; i += 2) {
        const std::uint16_t sample = reinterpret_cast<const std::uint16_t*>(source)[i / 2];
        current[i] = static_cast<unsigned char>(sample >> 8);
        current[i + 1] = static_cast<unsigned char>(sample & 0xff);
      }
    } else {
      std::memcpy(current.data(), source, row_bytes);
    }
    unsigned char* out = &filtered[v * (row_bytes + 1)];
    out[0] = filter;
    if (filter == 1) {
      for (std::size_t i = 0; i < row_bytes; ++i)
        out[1 + i] = static_cast<unsigned char>(
            current[i] -
            (i >= static_cast<std::size_t>(bytes_per_pixel) ? current[i - bytes_per_pixel] : 0));
    } else {
      for (std::size_t i = 0; i < row_bytes; ++i)
        out[1 + i] = static_cast<unsigned char>(current[i] - previous[i]);
    }
    std::swap(previous, current);
  }

  z_stream stream{};
  if (deflateInit2(&stream, level, Z_DEFLATED, 15, 8, strategy) != Z_OK)
    throw std::runtime_error("encodePng: deflateInit2 failed");
  std::vector<unsigned char> compressed(deflateBound(&stream, filtered.size()));
  stream.next_in = filtered.data();
  stream.avail_in = static_cast<uInt>(filtered.size());
  stream.next_out = compressed.data();
  stream.avail_out = static_cast<uInt>(compressed.size());
  const int status = deflate(&stream, Z_FINISH);
  compressed.resize(stream.total_out);
  deflateEnd(&stream);
  if (status != Z_STREAM_END)
    throw std::runtime_error("encodePng: deflate failed");

  std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> header;
  putBigEndian32(&header, static_cast<std::uint32_t>(width));
  putBigEndian32(&header, static_cast<std::uint32_t>(height));
  header.push_back(type == CV_16UC1 ? 16 : 8);  // bit depth
  header.push_back(type == CV_8UC3 ? 2 : 0);    // colour type: truecolour or greyscale
  header.push_back(0);                          // compression: deflate
  header.push_back(0);                          // filter method: adaptive (per-row byte)
  header.push_back(0);                          // no interlace
  png.reserve(compressed.size() + 64);
  putChunk(&png, "IHDR", header.data(), header.size());
  putChunk(&png, "IDAT", compressed.data(), compressed.size());
  putChunk(&png, "IEND", nullptr, 0);
  return png;
}

void writePng(const std::string& path, const cv::Mat& image, int level) {
  const std::vector<unsigned char> png = encodePng(image, level);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  if (!out)
    throw std::runtime_error("cannot write " + path);
}

}  // namespace quadric_slam
