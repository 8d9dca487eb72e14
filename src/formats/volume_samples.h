// What the volume readers share (volume_files.cpp, nifti_reader.cpp, nrrd_reader.cpp, the OpenVDB
// adapter): a problem thrown to the reader's entry point, a source of bytes (plain or gzip) read
// a piece at a time, the sample types, and turning samples into a grid's 16-bit codes — every
// size checked against the limits before anything is allocated.
#pragma once

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

#include "formats/reader.h"
#include "synthvis/volumes.h"

namespace sv::formats::volumes {

// A problem in a volume file, thrown and caught in parseVolume, which returns it as an Error.
struct VolumeProblem {
  std::string message;
};
[[noreturn]] inline void fail(std::string message) { throw VolumeProblem{std::move(message)}; }

// A gzip stream (or plain bytes) read from the start, a piece at a time: the caller learns the
// sizes from the header before asking for the data.
class Source {
 public:
  Source(const std::string& bytes, size_t start, bool gzip)
      : bytes_(bytes), at_(start), gzip_(gzip) {
    if (!gzip_) return;
    z_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + start));
    z_.avail_in = uInt(std::min<size_t>(bytes.size() - start, 1u << 30));
    if (inflateInit2(&z_, 16 + MAX_WBITS) != Z_OK) fail("cannot start gzip decompression");
    open_ = true;
  }
  ~Source() {
    if (open_) inflateEnd(&z_);
  }
  Source(const Source&) = delete;
  Source& operator=(const Source&) = delete;

  // Fills out[0, n), or fails naming what was being read.
  void read(void* out, size_t n, const char* what) {
    if (!gzip_) {
      if (bytes_.size() - at_ < n)
        fail(fmt::format("truncated: {} needs {} bytes, {} remain", what, n, bytes_.size() - at_));
      std::memcpy(out, bytes_.data() + at_, n);
      at_ += n;
      return;
    }
    z_.next_out = static_cast<Bytef*>(out);
    while (n > 0) {
      const size_t piece = std::min<size_t>(n, 1u << 30);
      z_.avail_out = uInt(piece);
      const int r = inflate(&z_, Z_NO_FLUSH);
      const size_t got = piece - z_.avail_out;
      n -= got;
      if (n == 0) break;
      if (r == Z_STREAM_END) fail(fmt::format("truncated: the gzip data ends inside {}", what));
      if (r != Z_OK) fail(fmt::format("gzip data is damaged ({})", z_.msg ? z_.msg : "zlib error"));
      if (got == 0 && z_.avail_in == 0)
        fail(fmt::format("truncated: the gzip data ends inside {}", what));
    }
  }
  // The most bytes the rest of the input can hold: what remains, or for gzip what remains times
  // deflate's largest ratio (1032:1) — so that a short file claiming a huge grid is refused before
  // the grid is allocated.
  uint64_t most() const {
    return gzip_ ? uint64_t(z_.avail_in) * 1032 + 4096 : uint64_t(bytes_.size() - at_);
  }
  // Skips n bytes.
  void skip(size_t n, const char* what) {
    char buffer[4096];
    while (n > 0) {
      const size_t k = std::min(n, sizeof buffer);
      read(buffer, k, what);
      n -= k;
    }
  }

 private:
  const std::string& bytes_;
  size_t at_;
  bool gzip_;
  bool open_ = false;
  z_stream z_{};
};

enum class Type { u8, i8, u16, i16, u32, i32, f32, f64 };
size_t sizeOf(Type t);

// The grid of nx × ny × nz samples, checked against the limits (before any allocation).
VolumeGrid sizedGrid(int64_t nx, int64_t ny, int64_t nz, size_t maxSamples);
// The samples of `g` read from `in` as `type` in the given byte order, turned into codes: 8- and
// 16-bit integers exactly (signed ones offset), wider ones and floats quantized over their range.
void readSamples(VolumeGrid& g, Source& in, Type type, bool bigEndian);
// value' = slope·value + intercept, kept as codes with a positive scale.
void rescale(VolumeGrid& g, double slope, double intercept);
// A header's spacing as a positive float (1 where it is 0, not finite or absurd).
float spacingOf(double v);
// Whether `bytes` start as a gzip stream.
bool gzipped(const std::string& bytes);

// The readers proper: NIfTI-1 (nifti_reader.cpp), NRRD (nrrd_reader.cpp).
VolumeGrid nifti(const std::string& bytes, size_t maxSamples);
VolumeGrid nrrd(const std::string& bytes, const std::string& path, bool followReferences,
                size_t maxSamples);

}  // namespace sv::formats::volumes
