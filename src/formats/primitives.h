// Mesh generators for the JSON scene format's "primitive" objects (docs/scene-format.md).
//
// Conventions shared by every generator: Y is up, the shape is centred on the origin (the plane
// and checker lie in y = 0), triangles are counter-clockwise seen from outside (the glTF front
// face), every vertex has a unit normal pointing outward and a texture coordinate. Output depends
// only on the parameters: no global state, the same bits on every run.
#pragma once

#include <array>
#include <cstdint>

#include "formats/reader.h"

namespace sv::formats::detail {

enum class PrimitiveKind { kBox, kSphere, kPlane, kChecker, kCylinder, kCone, kTorus };

// Division counts accepted for every primitive (segments, rings, sides, subdivisions, squares).
// The upper bound keeps one primitive within about 2^25 triangles; the scene-wide triangle limit
// is checked on top.
inline constexpr int kMinSegments = 3;
inline constexpr int kMinRings = 2;
inline constexpr int kMinDivisions = 1;
inline constexpr int kMaxSegments = 4096;

// The parameters of every kind; each generator reads the fields its comment names. Preconditions
// (the JSON loader checks them): lengths finite and > 0, counts within the bounds above.
struct PrimitiveParams {
  PrimitiveKind kind = PrimitiveKind::kBox;
  Vec3 size{1, 1, 1};   // box: edge lengths; plane, checker: extents along x and z (.y unused)
  float radius = 0.5f;  // sphere, cylinder, cone (base); torus: from the axis to the tube centre
  float height = 1.0f;  // cylinder, cone
  float tube = 0.125f;  // torus: tube radius
  int segments = 32;    // sphere, cylinder, cone, torus: divisions around the Y axis
  int rings = 16;       // sphere: latitude bands from pole to pole
  int sides = 16;       // torus: divisions around the tube
  int divisionsX = 1;   // plane: grid cells along x; checker: squares along x
  int divisionsZ = 1;   // plane: grid cells along z; checker: squares along z
  bool caps = true;     // cylinder: both ends closed; cone: base closed
  // checker: the colour of square (0, 0) and of its neighbours.
  std::array<Vec4, 2> colors{Vec4{0.8f, 0.8f, 0.8f, 1}, Vec4{0.2f, 0.2f, 0.2f, 1}};
};

// The number of triangles makePrimitive(p) will produce, computed without building it, so a
// caller can check its triangle budget first.
uint64_t primitiveTriangleCount(const PrimitiveParams& p);
Mesh makePrimitive(const PrimitiveParams& p);

// The generators behind makePrimitive.
Mesh makeBox(Vec3 size);                                 // 24 vertices, flat normals per face
Mesh makeSphere(float radius, int segments, int rings);  // UV sphere, 2·segments·(rings − 1)
// A grid in y = 0 facing +Y, vertices shared between cells: 2·nx·nz triangles.
Mesh makePlane(float sizeX, float sizeZ, int nx, int nz);
// Like the plane, but every square has its own four vertices carrying its colour, so that colour
// interpolation cannot blur the squares into each other.
Mesh makeChecker(float sizeX, float sizeZ, int nx, int nz, Vec4 color0, Vec4 color1);
// Axis Y, from −height/2 to height/2. Smooth side normals; caps have their own flat vertices.
Mesh makeCylinder(float radius, float height, int segments, bool caps);
// Base at −height/2, apex at +height/2. The apex is split per segment so that each side facet
// gets the normal of its own middle.
Mesh makeCone(float radius, float height, int segments, bool cap);
// Ring in the XZ plane around the Y axis.
Mesh makeTorus(float radius, float tube, int segments, int sides);

}  // namespace sv::formats::detail
