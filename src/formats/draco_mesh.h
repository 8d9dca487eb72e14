// Draco-compressed meshes (glTF's KHR_draco_mesh_compression), decoded with Google's libdraco into
// plain arrays, so that the glTF converter never sees Draco's types.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "synthvis/math.h"
#include "synthvis/result.h"

namespace sv::formats::detail {

struct DracoMesh {
  std::vector<Vec3> positions, normals;  // normals empty unless asked for
  std::vector<Vec4> colors;              // RGBA (RGB given: alpha 1)
  std::vector<Vec2> uvs;
  std::vector<uint32_t> indices;  // 3 per triangle, each < positions.size()
};

// The attribute ids the glTF extension names (its `attributes`), −1 for one it does not give.
struct DracoAttributes {
  int position = -1, normal = -1, color = -1, texcoord = -1;
};

// Decodes `size` bytes at `data` (a bufferView's) as a Draco triangle mesh of at most
// `maxVertices` points and `maxTriangles` faces. Errors say what is wrong (no position attribute,
// a point cloud, corrupt data); the caller names the file and place.
Result<DracoMesh> decodeDracoMesh(const uint8_t* data, size_t size, const DracoAttributes& ids,
                                  uint64_t maxVertices, uint64_t maxTriangles);

}  // namespace sv::formats::detail
