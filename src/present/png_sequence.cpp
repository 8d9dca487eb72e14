// "png:DIR": every channel of every frame as its own PNG file, written on the writer thread.
#include <fmt/format.h>

#include <filesystem>
#include <system_error>

#include "present/async_writer.h"
#include "present/outputs.h"

namespace sv::present {

std::string pngFrameName(uint64_t number, const std::string& channelName, size_t channelIndex) {
  // A channel name becomes part of a file name: keep it to characters every file system takes.
  std::string name = channelName.empty() ? fmt::format("channel{}", channelIndex) : channelName;
  for (char& c : name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
    if (!keep) c = '_';
  }
  return fmt::format("frame-{:06}-{}.png", number, name);
}

namespace detail {
namespace {

class PngSequence final : public Presenter {
 public:
  explicit PngSequence(std::filesystem::path dir)
      : dir_(std::move(dir)), writer_([this](const OwnedFrame& f) { return write(f); }, kQueueDepth) {}

  Status present(const Frame& frame) override { return writer_.submit(frame); }
  Status flush() override { return writer_.flush(); }
  uint64_t dropped() const override { return writer_.dropped(); }

 private:
  Status write(const OwnedFrame& frame) const {
    for (size_t i = 0; i < frame.channels.size(); ++i) {
      const std::string& name = i < frame.names.size() ? frame.names[i] : std::string();
      const std::filesystem::path path = dir_ / pngFrameName(frame.number, name, i);
      if (Status s = writePng(frame.channels[i], path.string()); !s) return s;
    }
    return {};
  }

  std::filesystem::path dir_;
  AsyncWriter writer_;  // last: its thread calls write(), so it must stop before dir_ goes
};

}  // namespace

Result<std::unique_ptr<Presenter>> makePngSequence(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Error{dir, "", "cannot create the output directory: " + ec.message()};
  if (!std::filesystem::is_directory(dir, ec)) return Error{dir, "", "not a directory"};
  return std::unique_ptr<Presenter>(new PngSequence(dir));
}

}  // namespace detail
}  // namespace sv::present
