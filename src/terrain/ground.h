// A ground as a scene holds it: the height table and, built on first use and kept, its min/max
// pyramid for each interpolation (a scene chooses one, the CLI may choose the other).
#pragma once

#include <memory>
#include <mutex>

#include "terrain/caster.h"

namespace sv::terrain {

struct Ground {
  explicit Ground(HeightField f) : field(std::move(f)) {}
  HeightField field;
  // Reading (or generating) the table and building the pyramid the scene asks for (loaders build
  // it; another interpolation's is built by the first frame that asks, in that frame's time).
  double loadMs = 0;

  // The pyramid over `interp`'s surface (thread-safe; built once).
  const Pyramid& pyramid(Interpolation interp) const {
    Slot& s = slots_[interp == Interpolation::bicubic ? 1 : 0];
    std::call_once(s.once, [&] { s.pyramid = std::make_unique<Pyramid>(field, interp); });
    return *s.pyramid;
  }
  size_t bytes() const {
    size_t b = field.bytes();
    for (const Slot& s : slots_)
      if (s.pyramid) b += s.pyramid->bytes();
    return b;
  }

 private:
  struct Slot {
    std::once_flag once;
    std::unique_ptr<Pyramid> pyramid;
  };
  mutable Slot slots_[2];
};

}  // namespace sv::terrain
