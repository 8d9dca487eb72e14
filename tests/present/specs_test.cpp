// Output specs: the good ones make presenters, the bad ones one clear error line.
#include <gtest/gtest.h>

#include <cstdlib>

#include "present/present.h"

namespace sv::present {
namespace {

std::string specError(const std::string& spec) {
  auto p = makePresenter(spec, 60);
  EXPECT_FALSE(p.ok()) << spec;
  return p.ok() ? std::string() : p.error().str();
}

TEST(PresentSpecs, BadSpecsAreErrorsNamingTheProblem) {
  const std::string choices = " (use png:DIR, y4m:PATH, y4m:-, window, window:channels or null)";
  EXPECT_EQ(specError("png:"), "output 'png:': png needs a directory, as png:DIR" + choices);
  EXPECT_EQ(specError("png"), "output 'png': png needs a directory, as png:DIR" + choices);
  EXPECT_EQ(specError("y4m:"), "output 'y4m:': y4m needs a file, as y4m:PATH (y4m:- for stdout)" + choices);
  EXPECT_EQ(specError("tiff:out"), "output 'tiff:out': unknown kind" + choices);
  EXPECT_EQ(specError(""), "output '': unknown kind" + choices);
  EXPECT_EQ(specError("null:x"), "output 'null:x': unknown kind" + choices);
  EXPECT_EQ(specError("window:big"), "output 'window:big': the window's only option is 'channels'" + choices);
}

TEST(PresentSpecs, UnwritablePlacesNameTheFile) {
  EXPECT_EQ(specError("png:/proc/sv-no-such/dir").rfind("/proc/sv-no-such/dir: cannot create", 0), 0u);
  EXPECT_EQ(specError("y4m:/proc/sv-no-such/out.y4m").rfind("/proc/sv-no-such/out.y4m: cannot open", 0), 0u);
  EXPECT_EQ(makePresenter("y4m:/tmp/sv_rate.y4m", 0).error().str(), "/tmp/sv_rate.y4m: y4m: frame rate must be positive, not 0");
}

TEST(PresentSpecs, NullPresentsNothing) {
  auto p = makePresenter("null", 60);
  ASSERT_TRUE(p.ok());
  const Image im{2, 2, std::vector<uint8_t>(12, 9)};
  const std::string name = "c";
  EXPECT_TRUE(p.value()->present({1, {&im, 1}, {&name, 1}}).ok());
  EXPECT_FALSE(p.value()->closed());
}

TEST(PresentSpecs, WindowWithoutADisplayIsAClearErrorNotACrash) {
  // No X display, no Wayland, and SDL held to X11 so that no other video driver answers.
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  setenv("SDL_VIDEODRIVER", "x11", 1);
  const std::string e = specError("window");
#ifdef SV_HAVE_SDL2
  EXPECT_EQ(e.rfind("output 'window': no display (is DISPLAY set?): SDL_Init failed: ", 0), 0u) << e;
#else
  EXPECT_EQ(e, "output 'window': synthvis was built without SDL2 (install libsdl2-dev)");
#endif
  unsetenv("SDL_VIDEODRIVER");
}

}  // namespace
}  // namespace sv::present
