// Shared by the benchmarks: BENCH.md `tris` as clip-space draw packets (the vertex stage done once,
// outside the timing), seen by the BENCH.md camera on a width × height raster.
#pragma once

#include <numbers>

#include "render/frame_renderer.h"
#include "synthvis/generators.h"

namespace sv::bench {

inline render::DrawPackets trisPackets(int count, double area, int width = 1920,
                                       int height = 1080) {
  generators::TrisParams p;
  p.count = count;
  p.area = area;
  p.width = width;
  p.height = height;
  const scene::Scene s = generators::generateTris(p);
  render::DrawPackets packets;
  const Mat4 vp = Mat4::perspective(60 * std::numbers::pi_v<float> / 180,
                                    float(width) / float(height), 0.1f, 100) *
                  Mat4::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
  const auto& m = s.meshes[0];
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const Vec4 c = vp * Vec4{m.positions[i].x, m.positions[i].y, m.positions[i].z, 1};
    packets.vertices.push_back(
        {c.x, c.y, c.z, c.w, m.colors[i].x, m.colors[i].y, m.colors[i].z, 1});
  }
  packets.indices = m.indices;
  packets.calls.push_back({0, uint32_t(m.triangleCount()), geometry::CullMode::none});
  return packets;
}

}  // namespace sv::bench
