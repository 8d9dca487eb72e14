// A height table as the terrain stage draws it: the table (synthvis/height_field.h) and, built on
// first use and kept with it (HeightField::derived), its min/max pyramid for each interpolation —
// a scene chooses one, the CLI may choose the other. Readers build the scene's at load time, so
// that no frame waits for it.
#pragma once

#include <chrono>
#include <memory>

#include "terrain/pyramid.h"

namespace sv::terrain {

// The pyramid over `interp`'s surface of `field` (thread-safe; built once per table).
inline const Pyramid& pyramidOf(const HeightField& field, Interpolation interp) {
  const int slot = interp == Interpolation::bicubic ? 1 : 0;
  return field.derived.get<Pyramid>(slot, [&] { return std::make_unique<Pyramid>(field, interp); });
}

// `field` ready for a scene (Terrain::heights): with the pyramid `interp` builds made at once —
// part of loading, not of the first frame — and its time added to the table's loadMs.
inline std::shared_ptr<const HeightField> prepareGround(HeightField field, Interpolation interp) {
  auto held = std::make_shared<HeightField>(std::move(field));
  const auto start = std::chrono::steady_clock::now();
  pyramidOf(*held, interp);
  held->loadMs +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return held;
}

// The memory the table and the pyramids built so far hold, in bytes (statistics, after a frame).
inline size_t groundBytes(const HeightField& field) {
  size_t b = field.bytes();
  for (int slot = 0; slot < scene::DerivedData::kSlots; ++slot)
    if (const Pyramid* p = field.derived.built<Pyramid>(slot)) b += p->bytes();
  return b;
}

}  // namespace sv::terrain
