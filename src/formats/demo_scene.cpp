// The built-in demo scene: scenes/demo.json, compiled into the library (demo_scene_text.cpp).
#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "formats/reader.h"

namespace sv::formats {

Scene demoScene() {
  const char* text = demoSceneJson();
  Result<Scene> scene =
      parseJsonScene(std::string(text, std::strlen(text)), "demo.json (built in)");
  if (!scene) {
    // The text is part of the build and a test parses it, so this is a build defect, not an input
    // error: stop loudly rather than render an empty picture.
    fmt::print(stderr, "synthvis: the built-in demo scene is broken: {}\n", scene.error().str());
    std::abort();
  }
  return std::move(scene.value());
}

}  // namespace sv::formats
