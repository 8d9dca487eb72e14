// Issue 31's acceptance: a screenshot of the SDL2 window under Xvfb matches the headless frame.
// The test starts its own Xvfb (a free display number chosen by the server, -displayfd), presents
// a known mosaic in a window exactly its size on a screen exactly its size, grabs the root window
// with `xwd -root`, reads the XWD file and compares every pixel with the image.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "present/present.h"
#include "present/test_patterns.h"

extern char** environ;

namespace sv::present {
namespace {

bool onPath(const char* program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  for (size_t at = 0; at <= dirs.size();) {
    const size_t colon = std::min(dirs.find(':', at), dirs.size());
    if (access((dirs.substr(at, colon - at) + "/" + program).c_str(), X_OK) == 0) return true;
    at = colon + 1;
  }
  return false;
}

// An Xvfb server for the test's lifetime, with one screen of the given size at 24-bit depth.
class Xvfb {
 public:
  ~Xvfb() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }

  Status start(int width, int height) {
    int fds[2];
    if (pipe(fds) != 0) return Error{"", "", "pipe failed"};
    fcntl(fds[0], F_SETFD, FD_CLOEXEC);  // the server gets only the write end
    const std::string fd = std::to_string(fds[1]);
    const std::string screen = std::to_string(width) + "x" + std::to_string(height) + "x24";
    const char* argv[] = {"Xvfb", "-displayfd", fd.c_str(), "-screen", "0", screen.c_str(),
                          "-nolisten", "tcp", "-noreset", nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);  // its warnings
    const int rc = posix_spawnp(&pid_, "Xvfb", &actions, nullptr, const_cast<char**>(argv), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    if (rc != 0) {
      close(fds[0]);
      pid_ = -1;
      return Error{"", "", "cannot start Xvfb"};
    }
    // The server writes its display number once it accepts connections.
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    char c = 0;
    while (poll(&p, 1, 20000) == 1 && read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    close(fds[0]);
    if (number.empty()) return Error{"", "", "Xvfb did not report a display number"};
    display_ = ":" + number;
    return {};
  }
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

uint32_t bigEndian32(const std::string& b, size_t at) {
  return uint32_t(uint8_t(b[at])) << 24 | uint32_t(uint8_t(b[at + 1])) << 16 |
         uint32_t(uint8_t(b[at + 2])) << 8 | uint32_t(uint8_t(b[at + 3]));
}

// An XWD file (X11's XWDFileHeader, version 7): 25 big-endian CARD32 fields, the window name, the
// colormap (12 bytes an entry), then the image rows. Only what Xvfb's 24-bit screens give is
// read: ZPixmap at 32 bits per pixel, or 24 (what xwd makes of a root holding windows of more
// than one visual, as SDL's may be), channels found by their masks.
Result<Image> parseXwd(const std::string& b) {
  if (b.size() < 100) return Error{"xwd", "", "shorter than its header"};
  uint32_t h[25];
  for (int i = 0; i < 25; ++i) h[i] = bigEndian32(b, size_t(i) * 4);
  const uint32_t headerSize = h[0], version = h[1], format = h[2], width = h[4], height = h[5];
  const uint32_t byteOrder = h[7], bitsPerPixel = h[11], bytesPerLine = h[12];
  const uint32_t masks[3] = {h[14], h[15], h[16]}, colours = h[19];
  if (version != 7 || format != 2 || (bitsPerPixel != 32 && bitsPerPixel != 24))
    return Error{"xwd", "", "not a version-7 24- or 32-bpp ZPixmap (version " + std::to_string(version) +
                                ", format " + std::to_string(format) + ", " +
                                std::to_string(bitsPerPixel) + " bpp)"};
  const int bytesPerPixel = int(bitsPerPixel / 8);
  const size_t data = size_t(headerSize) + size_t(colours) * 12;
  if (b.size() < data + size_t(bytesPerLine) * height) return Error{"xwd", "", "truncated"};
  Image im{int(width), int(height), std::vector<uint8_t>(size_t(width) * height * 3)};
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const size_t at = data + size_t(y) * bytesPerLine + size_t(x) * bytesPerPixel;
      uint32_t v = 0;
      for (int k = 0; k < bytesPerPixel; ++k) {
        const uint32_t byte = uint8_t(b[at + k]);
        v |= byteOrder == 0 ? byte << (8 * k) : byte << (8 * (bytesPerPixel - 1 - k));  // 0: LSBFirst
      }
      for (int c = 0; c < 3; ++c)
        im.pixel(int(x), int(y))[c] = uint8_t((v & masks[c]) >> std::countr_zero(masks[c]));
    }
  return im;
}

Result<Image> screenshot(const std::string& display) {
  const std::string command = "xwd -root -silent -display " + display;
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return Error{"", "", "cannot run xwd"};
  std::string bytes;
  char buffer[65536];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) bytes.append(buffer, n);
  if (pclose(pipe) != 0) return Error{"", "", "xwd failed"};
  return parseXwd(bytes);
}

size_t differingPixels(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) return size_t(-1);
  size_t n = 0;
  for (size_t i = 0; i < a.rgb.size(); i += 3)
    n += a.rgb[i] != b.rgb[i] || a.rgb[i + 1] != b.rgb[i + 1] || a.rgb[i + 2] != b.rgb[i + 2];
  return n;
}

// Presents two channels (colour bars and wedges, 160×240 each) through `spec` on a 320×240 Xvfb
// screen and compares the screen with their mosaic, retrying for a few seconds while the server
// catches up.
void expectScreenIsTheMosaic(const std::string& spec) {
  ASSERT_TRUE(onPath("Xvfb")) << "Xvfb not found: scripts/lib.sh installs it (package xvfb)";
  ASSERT_TRUE(onPath("xwd")) << "xwd not found: scripts/lib.sh installs it (package x11-apps)";
  const Image channels[2] = {testPattern(TestPattern::colorBars, 160, 240, "left"),
                             testPattern(TestPattern::wedges, 160, 240, "right")};
  const std::string names[2] = {"left", "right"};
  const Image expected = mosaic({channels[0], channels[1]});
  Xvfb server;
  const Status started = server.start(expected.width, expected.height);
  ASSERT_TRUE(started.ok()) << started.error().str();
  setenv("DISPLAY", server.display().c_str(), 1);
  auto presenter = makePresenter(spec, 60);
#ifndef SV_HAVE_SDL2
  FAIL() << "built without SDL2: scripts/lib.sh installs libsdl2-dev";
#endif
  ASSERT_TRUE(presenter.ok()) << presenter.error().str();
  size_t differ = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    const Status s = presenter.value()->present({uint64_t(attempt), channels, names});
    ASSERT_TRUE(s.ok()) << s.error().str();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    auto shot = screenshot(server.display());
    ASSERT_TRUE(shot.ok()) << shot.error().str();
    differ = differingPixels(shot.value(), expected);
    if (differ == 0) break;
  }
  EXPECT_EQ(differ, 0u) << "pixels of the screenshot differing from the headless frame";
  EXPECT_FALSE(presenter.value()->closed());
  presenter.value().reset();
  unsetenv("DISPLAY");
}

TEST(PresentWindow, ScreenshotUnderXvfbMatchesTheHeadlessFrame) { expectScreenIsTheMosaic("window"); }

// One window per channel, placed side by side from the desktop's left: the same screen.
TEST(PresentWindow, ChannelWindowsSideBySideMatchTheMosaic) { expectScreenIsTheMosaic("window:channels"); }

TEST(PresentXwd, ReaderRejectsWhatIsNotAnXwdFile) {
  EXPECT_FALSE(parseXwd("short").ok());
  EXPECT_FALSE(parseXwd(std::string(100, '\0')).ok());
}

}  // namespace
}  // namespace sv::present
