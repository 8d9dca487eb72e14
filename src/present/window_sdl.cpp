// "window" and "window:channels": SDL2 windows. Built only with SDL2 (SV_HAVE_SDL2); SDL is
// called from the thread that calls present(), the frame loop's, as SDL wants its video calls
// and events on one thread.
#include <SDL.h>
#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "present/outputs.h"

namespace sv::present::detail {
namespace {

// One window with its renderer and a streaming texture the image's size.
struct View {
  SDL_Window* window = nullptr;
  SDL_Renderer* renderer = nullptr;
  SDL_Texture* texture = nullptr;
  int width = 0, height = 0;  // the texture's
};

Error sdlError(const char* what) {
  return Error{"", "", fmt::format("output 'window': {}: {}", what, SDL_GetError())};
}

class SdlWindows final : public Presenter {
 public:
  explicit SdlWindows(bool perChannel) : perChannel_(perChannel) {}
  ~SdlWindows() override {
    for (View& v : views_) {
      if (v.texture) SDL_DestroyTexture(v.texture);
      if (v.renderer) SDL_DestroyRenderer(v.renderer);
      if (v.window) SDL_DestroyWindow(v.window);
    }
    SDL_QuitSubSystem(SDL_INIT_VIDEO);
  }

  Status present(const Frame& frame) override {
    pumpEvents();
    if (closed_ || frame.channels.empty()) return {};
    if (!perChannel_) {
      if (frame.channels.size() == 1) return show(0, frame.channels[0], "synthvis", 0);
      return show(0, mosaic({frame.channels.begin(), frame.channels.end()}), "synthvis", 0);
    }
    int x = 0;
    for (size_t i = 0; i < frame.channels.size(); ++i) {
      const std::string title = i < frame.names.size() ? frame.names[i] : fmt::format("channel{}", i);
      if (Status s = show(i, frame.channels[i], title, x); !s) return s;
      x += frame.channels[i].width;
    }
    return {};
  }

  bool closed() const override { return closed_; }

 private:
  void pumpEvents() {
    SDL_Event e;
    while (SDL_PollEvent(&e)) {
      if (e.type == SDL_QUIT) closed_ = true;
      if (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_CLOSE) closed_ = true;
    }
  }

  // Creates view i's window on first use, at the image's size unless the desktop is smaller (then
  // scaled down to fit, keeping the aspect); `x` is its offset from the desktop's left edge when
  // there is one window per channel.
  Status openView(size_t i, const Image& image, const std::string& title, int x) {
    SDL_Rect desk{0, 0, image.width, image.height};
    SDL_GetDisplayUsableBounds(0, &desk);
    const double fit = std::min({1.0, double(desk.w) / image.width, double(desk.h) / image.height});
    const int w = std::max(1, int(image.width * fit)), h = std::max(1, int(image.height * fit));
    const int px = perChannel_ ? desk.x + int(x * fit) : int(SDL_WINDOWPOS_CENTERED);
    const int py = perChannel_ ? desk.y : int(SDL_WINDOWPOS_CENTERED);
    View& v = views_[i];
    v.window = SDL_CreateWindow(title.c_str(), px, py, w, h, SDL_WINDOW_RESIZABLE);
    if (!v.window) return sdlError("cannot create a window");
    v.renderer = SDL_CreateRenderer(v.window, -1, 0);
    if (!v.renderer) return sdlError("cannot create a renderer");
    return {};
  }

  Status show(size_t i, const Image& image, const std::string& title, int x) {
    if (image.width <= 0 || image.height <= 0) return {};
    if (views_.size() <= i) views_.resize(i + 1);
    View& v = views_[i];
    if (!v.window)
      if (Status s = openView(i, image, title, x); !s) return s;
    if (!v.texture || v.width != image.width || v.height != image.height) {
      if (v.texture) SDL_DestroyTexture(v.texture);
      v.texture = SDL_CreateTexture(v.renderer, SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING,
                                    image.width, image.height);
      if (!v.texture) return sdlError("cannot create a texture");
      // Scaled to the window with the aspect kept (bars where it differs); smooth when scaled,
      // and at 1:1 every pixel as rendered.
      SDL_SetTextureScaleMode(v.texture, SDL_ScaleModeLinear);
      SDL_RenderSetLogicalSize(v.renderer, image.width, image.height);
      v.width = image.width;
      v.height = image.height;
    }
    if (SDL_UpdateTexture(v.texture, nullptr, image.rgb.data(), image.width * 3) != 0)
      return sdlError("cannot update the texture");
    SDL_SetRenderDrawColor(v.renderer, 0, 0, 0, 255);
    SDL_RenderClear(v.renderer);
    SDL_RenderCopy(v.renderer, v.texture, nullptr, nullptr);
    SDL_RenderPresent(v.renderer);
    return {};
  }

  bool perChannel_;
  bool closed_ = false;
  std::vector<View> views_;
};

}  // namespace

Result<std::unique_ptr<Presenter>> makeWindow(bool perChannel) {
  // The frame loop owns SIGINT and SIGTERM; SDL would otherwise turn them into quit events.
  SDL_SetHint(SDL_HINT_NO_SIGNAL_HANDLERS, "1");
  if (SDL_InitSubSystem(SDL_INIT_VIDEO) != 0)
    return sdlError("no display (is DISPLAY set?): SDL_Init failed");
  return std::unique_ptr<Presenter>(new SdlWindows(perChannel));
}

}  // namespace sv::present::detail
