// YUV4MPEG2 (y4m), the uncompressed stream ffmpeg and mpv read from a pipe: one text header, then
// per frame "FRAME\n" and the planes. synthvis writes 4:4:4 (C444, no chroma subsampling, so no
// channel edge is smeared) in BT.601 limited ("studio") range, converted in 16.16 fixed point.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "synthvis/image.h"
#include "synthvis/result.h"

namespace sv::present {

struct Yuv {
  uint8_t y, u, v;  // u = Cb, v = Cr
};

// BT.601 (Kr = 0.299, Kb = 0.114) from 8-bit R'G'B' (full range 0–255) to limited range:
// Y in 16–235, Cb and Cr in 16–240, 128 meaning no colour. Integer arithmetic only, so every
// machine writes the same bytes; greys get Cb = Cr = 128 exactly.
Yuv rgbToYuv601(uint8_t r, uint8_t g, uint8_t b);

// "YUV4MPEG2 W640 H480 F60:1 Ip A1:1 C444 XCOLORRANGE=LIMITED\n".
std::string y4mHeader(int width, int height, int rate);

// Writes a y4m stream to a FILE: the header before the first frame, then "FRAME\n" and the Y, U,
// V planes of each image. Every frame must have the first one's size. `name` is used in errors
// ("-" for standard output).
class Y4mWriter {
 public:
  Y4mWriter(std::FILE* file, std::string name, int rate) : file_(file), name_(std::move(name)), rate_(rate) {}
  Status write(const Image& image);
  // The reader of a pipe went away (EPIPE).
  bool brokenPipe() const { return brokenPipe_; }

 private:
  std::FILE* file_;
  std::string name_;
  int rate_;
  int width_ = 0, height_ = 0;  // of the first frame, once written
  std::string planes_;          // the frame's bytes, reused
  bool brokenPipe_ = false;
};

}  // namespace sv::present
