// Mesh generators (see primitives.h for the shared conventions).
//
// Angles are computed in double from integer steps, with the step taken modulo the division count,
// so that the seam column (step == count) gets bit-identical positions to column 0 and the mesh is
// watertight for an exact rasterizer; texture coordinates keep the unwrapped value (u = 1 at the
// seam). Quads are split as (a, b, c) + (a, c, d) with a, b, c, d counter-clockwise from outside.
#include "formats/primitives.h"

#include <cmath>
#include <numbers>

namespace sv::formats::detail {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// Appends vertices and triangles to a Mesh.
class MeshBuilder {
 public:
  MeshBuilder(size_t vertices, size_t triangles) {
    mesh_.positions.reserve(vertices);
    mesh_.normals.reserve(vertices);
    mesh_.uvs.reserve(vertices);
    mesh_.indices.reserve(3 * triangles);
  }
  uint32_t vertex(Vec3 p, Vec3 n, Vec2 uv) {
    mesh_.positions.push_back(p);
    mesh_.normals.push_back(normalize(n));
    mesh_.uvs.push_back(uv);
    return static_cast<uint32_t>(mesh_.positions.size() - 1);
  }
  void triangle(uint32_t a, uint32_t b, uint32_t c) {
    mesh_.indices.insert(mesh_.indices.end(), {a, b, c});
  }
  // a, b, c, d counter-clockwise seen from the front.
  void quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
  Mesh& mesh() { return mesh_; }

 private:
  Mesh mesh_;
};

float f(double x) { return static_cast<float>(x); }

// The point at angle step `s` of `n` around the Y axis, on the unit circle in XZ: step 0 is +Z,
// increasing steps turn toward +X.
Vec2 circle(int s, int n) {
  double phi = kTwoPi * (s % n) / n;
  return {f(std::sin(phi)), f(std::cos(phi))};
}

}  // namespace

uint64_t primitiveTriangleCount(const PrimitiveParams& p) {
  const uint64_t s = uint64_t(p.segments);
  switch (p.kind) {
    case PrimitiveKind::kBox:
      return 12;
    case PrimitiveKind::kSphere:
      return 2 * s * uint64_t(p.rings - 1);
    case PrimitiveKind::kPlane:
    case PrimitiveKind::kChecker:
      return 2 * uint64_t(p.divisionsX) * uint64_t(p.divisionsZ);
    case PrimitiveKind::kCylinder:
      return p.caps ? 4 * s : 2 * s;
    case PrimitiveKind::kCone:
      return p.caps ? 2 * s : s;
    case PrimitiveKind::kTorus:
      return 2 * s * uint64_t(p.sides);
  }
  return 0;
}

Mesh makePrimitive(const PrimitiveParams& p) {
  switch (p.kind) {
    case PrimitiveKind::kBox:
      return makeBox(p.size);
    case PrimitiveKind::kSphere:
      return makeSphere(p.radius, p.segments, p.rings);
    case PrimitiveKind::kPlane:
      return makePlane(p.size.x, p.size.z, p.divisionsX, p.divisionsZ);
    case PrimitiveKind::kChecker:
      return makeChecker(p.size.x, p.size.z, p.divisionsX, p.divisionsZ, p.colors[0], p.colors[1]);
    case PrimitiveKind::kCylinder:
      return makeCylinder(p.radius, p.height, p.segments, p.caps);
    case PrimitiveKind::kCone:
      return makeCone(p.radius, p.height, p.segments, p.caps);
    case PrimitiveKind::kTorus:
      return makeTorus(p.radius, p.tube, p.segments, p.sides);
  }
  return {};
}

Mesh makeBox(Vec3 size) {
  // Each face: outward normal n and in-plane axes u, v with u × v = n, so corners taken in the
  // order (−u−v, +u−v, +u+v, −u+v) run counter-clockwise seen from outside.
  struct Face {
    Vec3 n, u, v;
  };
  static constexpr Face kFaces[6] = {
      {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
      {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
      {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
  };
  const Vec3 half = size * 0.5f;
  MeshBuilder b(24, 12);
  for (const Face& face : kFaces) {
    uint32_t corner[4];
    static constexpr float kSu[4] = {-1, 1, 1, -1}, kSv[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; ++k) {
      Vec3 unit = face.n + face.u * kSu[k] + face.v * kSv[k];
      corner[k] = b.vertex(unit * half, face.n, {(kSu[k] + 1) / 2, (kSv[k] + 1) / 2});
    }
    b.quad(corner[0], corner[1], corner[2], corner[3]);
  }
  return std::move(b.mesh());
}

Mesh makeSphere(float radius, int segments, int rings) {
  // Vertex (r, s): polar angle theta = pi·r/rings from +Y, azimuth step s. The pole rows hold one
  // vertex per column (same position, own u) so that no triangle is degenerate.
  const int columns = segments + 1;
  MeshBuilder b(size_t(rings + 1) * size_t(columns), 2 * size_t(segments) * size_t(rings - 1));
  for (int r = 0; r <= rings; ++r) {
    double theta = std::numbers::pi * r / rings;
    // Exact poles: sin(pi) is not 0 in floating point.
    double sinTheta = (r == 0 || r == rings) ? 0.0 : std::sin(theta);
    double cosTheta = r == 0 ? 1.0 : r == rings ? -1.0 : std::cos(theta);
    for (int s = 0; s <= segments; ++s) {
      Vec2 c = circle(s, segments);
      Vec3 n{f(sinTheta * c.x), f(cosTheta), f(sinTheta * c.y)};
      b.vertex(n * radius, n, {f(double(s) / segments), f(double(r) / rings)});
    }
  }
  auto at = [columns](int r, int s) { return uint32_t(r * columns + s); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      uint32_t a = at(r, s), bl = at(r + 1, s), c = at(r + 1, s + 1), d = at(r, s + 1);
      if (r != rings - 1) b.triangle(a, bl, c);  // at the south pole bl and c coincide
      if (r != 0) b.triangle(a, c, d);           // at the north pole a and d coincide
    }
  return std::move(b.mesh());
}

namespace {

// Grid coordinate k of n across an extent centred on 0; k == n lands exactly on the far edge.
float gridCoordinate(int k, int n, float extent) { return f(extent * (double(k) / n - 0.5)); }

}  // namespace

Mesh makePlane(float sizeX, float sizeZ, int nx, int nz) {
  // Vertex (i, j): x grows with i, z shrinks with j, so (i,j), (i+1,j), (i+1,j+1), (i,j+1) run
  // counter-clockwise seen from +Y.
  MeshBuilder b(size_t(nx + 1) * size_t(nz + 1), 2 * size_t(nx) * size_t(nz));
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i)
      b.vertex({gridCoordinate(i, nx, sizeX), 0, -gridCoordinate(j, nz, sizeZ)}, {0, 1, 0},
               {f(double(i) / nx), f(double(j) / nz)});
  auto at = [nx](int i, int j) { return uint32_t(j * (nx + 1) + i); };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) b.quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  return std::move(b.mesh());
}

Mesh makeChecker(float sizeX, float sizeZ, int nx, int nz, Vec4 color0, Vec4 color1) {
  MeshBuilder b(4 * size_t(nx) * size_t(nz), 2 * size_t(nx) * size_t(nz));
  Mesh& mesh = b.mesh();
  mesh.colors.reserve(4 * size_t(nx) * size_t(nz));
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      // The same coordinate function as the plane: neighbouring squares share edge positions
      // bit for bit, only not vertices.
      float x0 = gridCoordinate(i, nx, sizeX), x1 = gridCoordinate(i + 1, nx, sizeX);
      float z0 = -gridCoordinate(j, nz, sizeZ), z1 = -gridCoordinate(j + 1, nz, sizeZ);
      float u0 = f(double(i) / nx), u1 = f(double(i + 1) / nx);
      float v0 = f(double(j) / nz), v1 = f(double(j + 1) / nz);
      uint32_t a = b.vertex({x0, 0, z0}, {0, 1, 0}, {u0, v0});
      uint32_t c1 = b.vertex({x1, 0, z0}, {0, 1, 0}, {u1, v0});
      uint32_t c2 = b.vertex({x1, 0, z1}, {0, 1, 0}, {u1, v1});
      uint32_t c3 = b.vertex({x0, 0, z1}, {0, 1, 0}, {u0, v1});
      b.quad(a, c1, c2, c3);
      Vec4 color = (i + j) % 2 == 0 ? color0 : color1;
      mesh.colors.insert(mesh.colors.end(), {color, color, color, color});
    }
  return std::move(mesh);
}

Mesh makeCylinder(float radius, float height, int segments, bool caps) {
  const float top = height / 2, bottom = -height / 2;
  const size_t capVertices = caps ? 2 * size_t(segments + 1) : 0;
  MeshBuilder b(2 * size_t(segments + 1) + capVertices,
                caps ? 4 * size_t(segments) : 2 * size_t(segments));
  // Side: columns of (top, bottom) vertices with horizontal normals.
  for (int s = 0; s <= segments; ++s) {
    Vec2 c = circle(s, segments);
    float u = f(double(s) / segments);
    b.vertex({radius * c.x, top, radius * c.y}, {c.x, 0, c.y}, {u, 0});
    b.vertex({radius * c.x, bottom, radius * c.y}, {c.x, 0, c.y}, {u, 1});
  }
  for (int s = 0; s < segments; ++s) {
    uint32_t a = uint32_t(2 * s), d = uint32_t(2 * s + 2);
    b.quad(a, a + 1, d + 1, d);
  }
  if (caps) {
    // Each cap: a centre and a ring with flat normals, as a fan.
    for (int side = 0; side < 2; ++side) {
      const float y = side == 0 ? top : bottom;
      const Vec3 n{0, side == 0 ? 1.0f : -1.0f, 0};
      uint32_t centre = b.vertex({0, y, 0}, n, {0.5f, 0.5f});
      for (int s = 0; s < segments; ++s) {
        Vec2 c = circle(s, segments);
        b.vertex({radius * c.x, y, radius * c.y}, n, {0.5f + c.x / 2, 0.5f + c.y / 2});
      }
      for (int s = 0; s < segments; ++s) {
        uint32_t p0 = centre + 1 + uint32_t(s), p1 = centre + 1 + uint32_t((s + 1) % segments);
        // Seen from +Y, the ring steps run counter-clockwise; the bottom cap is seen from −Y.
        if (side == 0)
          b.triangle(centre, p0, p1);
        else
          b.triangle(centre, p1, p0);
      }
    }
  }
  return std::move(b.mesh());
}

Mesh makeCone(float radius, float height, int segments, bool cap) {
  const float top = height / 2, bottom = -height / 2;
  // The outward normal of a cone side at azimuth phi is proportional to
  // (height·sin phi, radius, height·cos phi): perpendicular to the slant line from the base
  // point (radius·sin phi, −h/2, radius·cos phi) to the apex.
  auto sideNormal = [&](double phi) {
    return Vec3{f(height * std::sin(phi)), radius, f(height * std::cos(phi))};
  };
  MeshBuilder b(size_t(segments + 1) + size_t(segments) + (cap ? size_t(segments + 1) : 0),
                cap ? 2 * size_t(segments) : size_t(segments));
  for (int s = 0; s <= segments; ++s) {
    Vec2 c = circle(s, segments);
    b.vertex({radius * c.x, bottom, radius * c.y}, sideNormal(kTwoPi * (s % segments) / segments),
             {f(double(s) / segments), 1});
  }
  const uint32_t apexBase = uint32_t(segments + 1);
  for (int s = 0; s < segments; ++s)
    b.vertex({0, top, 0}, sideNormal(kTwoPi * (s + 0.5) / segments), {f((s + 0.5) / segments), 0});
  for (int s = 0; s < segments; ++s)
    b.triangle(apexBase + uint32_t(s), uint32_t(s), uint32_t(s + 1));
  if (cap) {
    uint32_t centre = b.vertex({0, bottom, 0}, {0, -1, 0}, {0.5f, 0.5f});
    for (int s = 0; s < segments; ++s) {
      Vec2 c = circle(s, segments);
      b.vertex({radius * c.x, bottom, radius * c.y}, {0, -1, 0}, {0.5f + c.x / 2, 0.5f + c.y / 2});
    }
    for (int s = 0; s < segments; ++s)
      b.triangle(centre, centre + 1 + uint32_t((s + 1) % segments), centre + 1 + uint32_t(s));
  }
  return std::move(b.mesh());
}

Mesh makeTorus(float radius, float tube, int segments, int sides) {
  // Vertex (i, j): azimuth step i around Y, tube angle step j (0 = outermost, growing upward).
  // Position ((R + t·cos θ)·sin φ, t·sin θ, (R + t·cos θ)·cos φ), normal (cos θ·sin φ, sin θ,
  // cos θ·cos φ) with R = radius, t = tube.
  const int columns = sides + 1;
  MeshBuilder b(size_t(segments + 1) * size_t(columns), 2 * size_t(segments) * size_t(sides));
  for (int i = 0; i <= segments; ++i) {
    Vec2 c = circle(i, segments);
    for (int j = 0; j <= sides; ++j) {
      double theta = kTwoPi * (j % sides) / sides;
      double ring = radius + tube * std::cos(theta);
      Vec3 p{f(ring * c.x), f(tube * std::sin(theta)), f(ring * c.y)};
      Vec3 n{f(std::cos(theta) * c.x), f(std::sin(theta)), f(std::cos(theta) * c.y)};
      b.vertex(p, n, {f(double(i) / segments), f(double(j) / sides)});
    }
  }
  auto at = [columns](int i, int j) { return uint32_t(i * columns + j); };
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < sides; ++j) b.quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  return std::move(b.mesh());
}

}  // namespace sv::formats::detail
