// Based on: ITU-R BT.601-7 (the luma weights Kr = 0.299, Kb = 0.114; the 8-bit studio range
// Y 16–235, Cb/Cr 16–240); the YUV4MPEG2 format as mjpegtools defines it (yuv4mpeg(5)) and
// ffmpeg reads it (its XCOLORRANGE extension).
#include "present/y4m.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <memory>

#include "present/async_writer.h"
#include "present/outputs.h"
#include "synthvis/files.h"

namespace sv::present {
namespace {

// 16.16 fixed point: a coefficient c ≤ 1 times an 8-bit value times 3 terms stays below 2^26,
// far inside int32. Rounded to nearest at compile time.
constexpr int32_t fix16(double v) { return int32_t(v >= 0 ? v * 65536.0 + 0.5 : v * 65536.0 - 0.5); }

// The BT.601 matrix, in the standard's symbols: E'Y = Kr·R + Kg·G + Kb·B, and the colour
// differences E'Cb = (B − E'Y) / (2(1 − Kb)), E'Cr = (R − E'Y) / (2(1 − Kr)); then scaled to the
// studio range, 219/255 for Y and 224/255 for Cb, Cr. Each row's middle term is derived from the
// others so that rounding cannot break the sums: Y's row sums to exactly 219/255 (white is 235),
// Cb's and Cr's to exactly 0 (every grey has Cb = Cr = 128).
constexpr double kKr = 0.299, kKb = 0.114, kKg = 1.0 - kKr - kKb;
constexpr double kYs = 219.0 / 255.0, kCs = 224.0 / 255.0;
constexpr int32_t kYr = fix16(kYs * kKr), kYb = fix16(kYs * kKb), kYg = fix16(kYs) - kYr - kYb;
constexpr int32_t kUr = fix16(-kCs * kKr / (2 * (1 - kKb))), kUb = fix16(kCs * 0.5),
                  kUg = -kUr - kUb;
constexpr int32_t kVr = fix16(kCs * 0.5), kVb = fix16(-kCs * kKb / (2 * (1 - kKr))),
                  kVg = -kVr - kVb;
static_assert(kYr + kYg + kYb == fix16(kYs) && kUr + kUg + kUb == 0 && kVr + kVg + kVb == 0);

constexpr int32_t kHalf = 1 << 15;  // rounds to nearest in the final shift

uint8_t toByte(int32_t v16) { return uint8_t(std::clamp((v16 + kHalf) >> 16, 0, 255)); }

}  // namespace

Yuv rgbToYuv601(uint8_t r, uint8_t g, uint8_t b) {
  // The offsets are added before the shift, so the sums are positive and >> rounds as intended.
  return {toByte((16 << 16) + kYr * r + kYg * g + kYb * b),
          toByte((128 << 16) + kUr * r + kUg * g + kUb * b),
          toByte((128 << 16) + kVr * r + kVg * g + kVb * b)};
}

std::string y4mHeader(int width, int height, int rate) {
  // Ip: progressive; A1:1: square pixels; C444: no chroma subsampling.
  return fmt::format("YUV4MPEG2 W{} H{} F{}:1 Ip A1:1 C444 XCOLORRANGE=LIMITED\n", width, height,
                     rate);
}

Status Y4mWriter::write(const Image& image) {
  if (image.width <= 0 || image.height <= 0) return Error{name_, "", "y4m: empty frame"};
  std::string out;
  if (width_ == 0) {
    width_ = image.width;
    height_ = image.height;
    out = y4mHeader(width_, height_, rate_);
  } else if (image.width != width_ || image.height != height_) {
    return Error{name_, "", fmt::format("y4m: frame size changed from {}x{} to {}x{}", width_, height_,
                                        image.width, image.height)};
  }
  const size_t n = size_t(width_) * size_t(height_);
  out += "FRAME\n";
  const size_t planes = out.size();
  out.resize(planes + 3 * n);
  uint8_t* y = reinterpret_cast<uint8_t*>(out.data()) + planes;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = &image.rgb[i * 3];
    const Yuv c = rgbToYuv601(p[0], p[1], p[2]);
    y[i] = c.y;
    y[n + i] = c.u;
    y[2 * n + i] = c.v;
  }
  errno = 0;
  // Flushed every frame: a player at the other end of a pipe shows it now, not a buffer later.
  if (std::fwrite(out.data(), 1, out.size(), file_) != out.size() || std::fflush(file_) != 0) {
    if (errno == EPIPE) brokenPipe_ = true;
    return Error{name_, "", std::string("y4m: write failed: ") + core::writeFailure(errno)};
  }
  return {};
}

namespace detail {
namespace {

class Y4mStream final : public Presenter {
 public:
  Y4mStream(std::FILE* file, bool owned, const std::string& name, int rate)
      : file_(file), owned_(owned), y4m_(file, name, rate),
        writer_(std::make_unique<AsyncWriter>([this](const OwnedFrame& f) { return write(f); },
                                              kQueueDepth)) {}
  ~Y4mStream() override {
    writer_.reset();  // writes what is queued before the file closes
    if (owned_) std::fclose(file_);
  }

  Status present(const Frame& frame) override {
    if (closed_.load()) return {};
    return writer_->submit(frame);
  }
  bool closed() const override { return closed_.load(); }
  Status flush() override { return writer_->flush(); }
  uint64_t dropped() const override { return writer_->dropped(); }

 private:
  Status write(const OwnedFrame& frame) {
    if (closed_.load()) return {};
    Status s = y4m_.write(frame.channels.size() == 1 ? frame.channels[0] : mosaic(frame.channels));
    if (y4m_.brokenPipe()) closed_.store(true);
    return s;
  }

  std::FILE* file_;
  bool owned_;
  Y4mWriter y4m_;  // used on the writer thread only
  std::atomic<bool> closed_{false};
  std::unique_ptr<AsyncWriter> writer_;  // last: its thread uses the members above
};

}  // namespace

Result<std::unique_ptr<Presenter>> makeY4mStream(const std::string& path, int rate) {
  if (rate <= 0) return Error{path, "", fmt::format("y4m: frame rate must be positive, not {}", rate)};
  if (path == "-") return std::unique_ptr<Presenter>(new Y4mStream(stdout, false, "-", rate));
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return Error{path, "", std::string("cannot open for writing: ") + std::strerror(errno)};
  return std::unique_ptr<Presenter>(new Y4mStream(f, true, path, rate));
}

}  // namespace detail
}  // namespace sv::present
