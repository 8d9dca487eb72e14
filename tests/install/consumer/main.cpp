// A program that uses synthvis as a library: renders the built-in demo scene to a PNG file.
#include <synthvis/formats.h>
#include <synthvis/render.h>

#include <cstdio>

int main(int argc, char** argv) {
  sv::Renderer renderer(sv::RenderOptions{.width = 160, .height = 90});
  sv::Image image;
  sv::Status status = renderer.render(sv::formats::demoScene(), image);
  if (status) status = sv::writeImage(image, argc > 1 ? argv[1] : "frame.png");
  if (!status) return std::fprintf(stderr, "%s\n", status.error().str().c_str()), 1;
  std::printf("%dx%d\n", image.width, image.height);
}
