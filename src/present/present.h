// Presentation: where the running image generator's frames go. One Presenter per output, made
// from an output spec (the CLI's --output); the frame loop calls present() once a frame.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "synthvis/image.h"
#include "synthvis/result.h"

namespace sv::present {

// One presented frame. The spans are only borrowed for the call: a presenter that works after
// returning copies what it needs.
struct Frame {
  uint64_t number = 0;                 // the IG's frame counter
  std::span<const Image> channels;     // in channel order
  std::span<const std::string> names;  // channel names (same length)
};

class Presenter {
 public:
  virtual ~Presenter() = default;
  // Shows or queues one frame. Must not block for long: the loop has a deadline. File outputs
  // encode and write on their own thread; when it falls behind, frames are dropped (counted by
  // dropped()) rather than the loop held up. An error from the writer thread is returned by the
  // next present() (and by flush()).
  virtual Status present(const Frame& frame) = 0;
  // A window the user closed, or a y4m reader that went away (broken pipe): the loop may stop.
  virtual bool closed() const { return false; }
  // Waits until every queued frame is written; the first write error since the last call, if any.
  virtual Status flush() { return {}; }
  // Frames dropped because the writer thread was still busy with earlier ones.
  virtual uint64_t dropped() const { return 0; }
};

// Parses an output spec and makes the presenter (`rate` is the frame rate, frames per second,
// written into the y4m header):
//   "png:DIR"          PNG sequence DIR/frame-000123-<channel>.png (DIR created; a channel name's
//                      characters other than [A-Za-z0-9._-] become '_', an empty one "channelN")
//   "y4m:PATH"         YUV4MPEG2 stream of the channels' mosaic: C444, BT.601 limited range
//                      (XCOLORRANGE=LIMITED), 'F<rate>:1'; PATH '-' is standard output
//   "window"           an SDL2 window showing the mosaic (resizable, scaled keeping its aspect)
//   "window:channels"  one window per channel, titled with its name
//   "null"             nothing (benchmarks)
// Errors: an unknown kind, a missing DIR or PATH, a directory or file that cannot be made, no
// display (SDL's own text), or "built without SDL2".
Result<std::unique_ptr<Presenter>> makePresenter(const std::string& spec, int rate);

// The PNG sequence's file name for one channel of a frame: "frame-000123-left.png".
std::string pngFrameName(uint64_t number, const std::string& channelName, size_t channelIndex);

}  // namespace sv::present
