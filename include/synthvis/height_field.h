// Height fields (SPEC §11, seed 003's scalar perturbations): a 2D table of heights over a base
// surface, displaced along the base's normal, defined in the infinite prism over the table's
// footprint — the ground of a flight or driving simulator. Plain records (public API), held by the
// scene (Scene::terrains) and read by the terrain stage (src/terrain), which ray casts them.
//
// Map coordinates. A table is a grid of `width` × `height` samples, row 0 the northern edge (the
// order GDAL and image files keep). Sample (i, j) sits at map position
//   u = originU + i·spacingU  (east),   v = originV − j·spacingV  (north),
// in metres. Heights are metres up along the base's normal, held at 16 bits:
//   h = offset + scale·q,  q ∈ [0, 65535]  (SPEC §11 does not fix a precision; 16 bits with the
// table's own scale keep 1/65535 of its range — 0.15 m over a 10 km range — at a quarter of the
// memory of double, and a 16384² table fits in 512 MB).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "synthvis/math.h"

namespace sv::scene {

// The largest table accepted, a side and in all (issue 29: maps up to 16384² in memory). Readers
// refuse anything larger — or a header declaring it — before allocating.
inline constexpr int kMaxHeightSide = 16384;
inline constexpr int64_t kMaxHeightSamples = int64_t(kMaxHeightSide) * kMaxHeightSide;

// What a stage derives from a record that does not change, kept with the record: built once, on
// first use, by whichever thread asks first (the others wait for it), and shared by every frame
// and query after. The terrain stage keeps a table's min/max and mean pyramids here (one per
// interpolation: slots 0 and 1), so that the pictures and the host's height queries of every
// frame use the pyramids one load built. The database never builds or reads it; a copy of the
// record starts without it (it derives its own when asked).
class DerivedData {
 public:
  static constexpr int kSlots = 2;
  DerivedData() = default;
  DerivedData(const DerivedData&) {}
  DerivedData& operator=(const DerivedData&) {
    slots_ = std::make_unique<Slots>();
    return *this;
  }

  // Slot `slot`'s object, made by `build()` (returning a std::unique_ptr<T> or shared_ptr<T>) the
  // first time. The slot's type is its one user's to keep the same.
  template <class T, class Build>
  const T& get(int slot, Build&& build) const {
    Slots& s = *slots_;
    std::call_once(s.once[slot], [&] { s.data[slot] = std::shared_ptr<const T>(build()); });
    return *static_cast<const T*>(s.data[slot].get());
  }
  // Slot `slot`'s object if it has been built, else null. For statistics after a frame: not to be
  // called while another thread may be building it.
  template <class T>
  const T* built(int slot) const {
    return static_cast<const T*>(slots_->data[slot].get());
  }

 private:
  struct Slots {
    std::once_flag once[kSlots];
    std::shared_ptr<const void> data[kSlots];
  };
  std::unique_ptr<Slots> slots_ = std::make_unique<Slots>();
};

struct HeightField {
  int width = 0, height = 0;          // samples
  double originU = 0, originV = 0;    // map position of sample (0, 0), metres
  double spacingU = 1, spacingV = 1;  // metres between samples, east and south (> 0)
  double offset = 0, scale = 1;       // h = offset + scale·q
  std::vector<uint16_t> q;            // width × height, row-major, row 0 north
  std::string source;                 // the file (or generator) it came from, for messages
  // A geographic raster's own grid (a GDAL reader's): sample (0, 0) at (lon0, lat0), steps dLon
  // east and dLat south, in the SRS's angular unit (radiansPerUnit); the placement above is its
  // conversion to map metres (docs/terrain.md, "Geographic tables"). A mosaic of such tiles
  // converts them all at once, so tiles in different rows share one grid.
  struct Geographic {
    bool on = false;
    double lon0 = 0, lat0 = 0, dLon = 0, dLat = 0, radiansPerUnit = 0;
  } geographic;
  // Reading (or generating) the table, and building what the stages derive from it at load time,
  // in milliseconds (statistics: FrameStats::terrainLoadMs).
  double loadMs = 0;
  DerivedData derived;  // the terrain stage's pyramids (terrain/ground.h)

  double at(int i, int j) const {
    return offset + scale * q[size_t(j) * size_t(width) + size_t(i)];
  }
  uint16_t code(int i, int j) const { return q[size_t(j) * size_t(width) + size_t(i)]; }
  // Map extent: u from originU to eastU(), v from southV() to originV.
  double eastU() const { return originU + (width - 1) * spacingU; }
  double southV() const { return originV - (height - 1) * spacingV; }
  size_t bytes() const { return q.size() * sizeof(uint16_t); }
};

// A terrain's colour by height, where it has no draped image (Terrain::ramp).
struct TerrainColorStop {
  double height = 0;  // metres
  Vec3 color;         // linear
};

}  // namespace sv::scene
