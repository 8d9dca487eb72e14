// KHR_draco_mesh_compression's payload through libdraco (scene/draco_mesh.h).
#include "formats/draco_mesh.h"

#include <draco/compression/decode.h>
#include <fmt/format.h>

#include <memory>

namespace sv::formats::detail {

Result<DracoMesh> decodeDracoMesh(const uint8_t* data, size_t size, const DracoAttributes& ids,
                                  uint64_t maxVertices, uint64_t maxTriangles) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data), size);
  auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok())
    return Error{"", "", fmt::format("invalid Draco data: {}", type.status().error_msg_string())};
  if (type.value() != draco::TRIANGULAR_MESH)
    return Error{"", "", "Draco data holds a point cloud, not a triangle mesh"};
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    return Error{"", "",
                 fmt::format("invalid Draco data: {}", decoded.status().error_msg_string())};
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  const uint64_t points = mesh->num_points(), faces = mesh->num_faces();
  if (points > maxVertices || faces > maxTriangles)
    return Error{
        "", "",
        fmt::format("Draco mesh of {} points and {} triangles exceeds the limits", points, faces)};
  // Each attribute as `components` floats per point (normalized integers to 0…1 or −1…1).
  auto read = [&](int id, const char* name, int components, auto&& store) -> std::optional<Error> {
    if (id < 0) return std::nullopt;
    const draco::PointAttribute* a = mesh->GetAttributeByUniqueId(uint32_t(id));
    if (!a) return Error{"", "", fmt::format("Draco data has no attribute {} ({})", id, name)};
    if (a->num_components() < 1 || a->num_components() > 4)
      return Error{"", "",
                   fmt::format("Draco attribute {} ({}) has {} components", id, name,
                               int(a->num_components()))};
    float v[4] = {0, 0, 0, 1};
    for (uint32_t p = 0; p < points; ++p) {
      if (!a->ConvertValue<float>(a->mapped_index(draco::PointIndex(p)),
                                  int8_t(std::min<int>(components, a->num_components())), v))
        return Error{"", "", fmt::format("Draco attribute {} ({}) cannot be read", id, name)};
      store(p, v);
    }
    return std::nullopt;
  };
  DracoMesh out;
  if (ids.position < 0) return Error{"", "", "the Draco extension names no POSITION attribute"};
  out.positions.resize(points);
  if (auto e = read(ids.position, "POSITION", 3, [&](uint32_t p, const float* v) {
        out.positions[p] = {v[0], v[1], v[2]};
      }))
    return *e;
  if (ids.normal >= 0) out.normals.resize(points);
  if (auto e = read(ids.normal, "NORMAL", 3, [&](uint32_t p, const float* v) {
        out.normals[p] = {v[0], v[1], v[2]};
      }))
    return *e;
  if (ids.color >= 0) out.colors.resize(points);
  if (auto e = read(ids.color, "COLOR_0", 4, [&](uint32_t p, const float* v) {
        out.colors[p] = {v[0], v[1], v[2], v[3]};
      }))
    return *e;
  if (ids.texcoord >= 0) out.uvs.resize(points);
  if (auto e = read(ids.texcoord, "TEXCOORD_0", 2, [&](uint32_t p, const float* v) {
        out.uvs[p] = {v[0], v[1]};
      }))
    return *e;
  out.indices.reserve(faces * 3);
  for (uint32_t f = 0; f < faces; ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = face[k].value();
      if (i >= points)
        return Error{"", "", fmt::format("Draco face {} refers to point {} of {}", f, i, points)};
      out.indices.push_back(i);
    }
  }
  return out;
}

}  // namespace sv::formats::detail
