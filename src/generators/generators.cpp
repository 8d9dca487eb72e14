// BENCH.md's generators by name (synthvis/generators.h).
#include "synthvis/generators.h"

#include <fmt/format.h>

#include <array>
#include <utility>

#include "generators/generator_common.h"

namespace sv::generators {
namespace {

constexpr std::array<std::pair<Generator, const char*>, 9> kGenerators = {{
    {Generator::tris, "tris"},
    {Generator::layers, "layers"},
    {Generator::grazing, "grazing"},
    {Generator::freeform, "freeform"},
    {Generator::freeformOne, "freeform-one"},
    {Generator::terrain, "terrain"},
    {Generator::volume, "volume"},
    {Generator::lights, "lights"},
    {Generator::city, "city"},
}};

}  // namespace

Result<Generator> parseGenerator(const std::string& name) {
  std::string names;
  for (const auto& [generator, n] : kGenerators) {
    if (name == n) return generator;
    names += names.empty() ? n : fmt::format(", {}", n);
  }
  return Error{"", "", fmt::format("unknown generator '{}' ({})", name, names)};
}

const char* generatorName(Generator generator) {
  for (const auto& [g, n] : kGenerators)
    if (g == generator) return n;
  return "";
}

}  // namespace sv::generators
