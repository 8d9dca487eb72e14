// Fuzz target: the polygon core on raw vertex bytes (RASTER-NOTES: NaN, huge coordinates,
// degenerate and behind-the-eye triangles). The first two bytes choose a raster of 1…64 × 1…64
// pixels; the rest is read as clip-space vertices (8 floats each: x y z w r g b a), three per
// triangle, half of them with back-face culling.
// Checks: setup accounts for every triangle (drawn + culled = in), and the quadtree frame equals
// the brute-force reference (tests/support) pixel for pixel, depth and colour included.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "support/raster_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sv;
  if (size < 2) return 0;
  render::FrameSettings settings;
  settings.width = 1 + data[0] % 64;
  settings.height = 1 + data[1] % 64;
  settings.shade = (data[0] & 0x80) ? raster::ShadeMode::overdraw : raster::ShadeMode::gouraud;
  data += 2;
  size -= 2;
  constexpr size_t kVertexBytes = sizeof(geometry::ClipVertex);
  const size_t triangles = std::min<size_t>(size / (3 * kVertexBytes), 512);
  render::DrawPackets packets;
  packets.vertices.resize(triangles * 3);
  if (triangles) std::memcpy(packets.vertices.data(), data, triangles * 3 * kVertexBytes);
  for (uint32_t i = 0; i < triangles * 3; ++i) packets.indices.push_back(i);
  const uint32_t half = uint32_t(triangles / 2);
  packets.calls.push_back({0, half, geometry::CullMode::back});
  packets.calls.push_back({half, uint32_t(triangles) - half, geometry::CullMode::none});

  FrameStats stats;
  const test::Frame quad = test::renderQuadtree(packets, settings, 1, &stats);
  if (stats.trianglesIn != triangles || stats.drawn + stats.culled() != triangles) {
    std::fprintf(stderr, "setup lost triangles: %s\n", stats.summary().c_str());
    std::abort();
  }
  if (!(quad == test::renderReference(packets, settings))) {
    std::fprintf(stderr, "quadtree frame differs from the brute-force reference\n");
    std::abort();
  }
  return 0;
}
