// Based on: marching tetrahedra on interval-octree leaves (tessellate.h).
#include "freeform/tessellate.h"

#include <algorithm>
#include <cmath>

namespace sv::freeform {
namespace {

bool inside(double v) { return v >= 0; }

Interval boundOf(const FreeForm& f, const Box& b) {
  return f.bound({b[0].x, b[1].x}, {b[0].y, b[1].y}, {b[0].z, b[1].z});
}

void grow(std::optional<Box>& box, const Box& b) {
  if (!box) {
    box = b;
    return;
  }
  (*box)[0] = {std::min((*box)[0].x, b[0].x), std::min((*box)[0].y, b[0].y),
               std::min((*box)[0].z, b[0].z)};
  (*box)[1] = {std::max((*box)[1].x, b[1].x), std::max((*box)[1].y, b[1].y),
               std::max((*box)[1].z, b[1].z)};
}

Box child(const Box& b, int c) {
  const Vec3d m = (b[0] + b[1]) * 0.5;
  return {Vec3d{c & 1 ? m.x : b[0].x, c & 2 ? m.y : b[0].y, c & 4 ? m.z : b[0].z},
          Vec3d{c & 1 ? b[1].x : m.x, c & 2 ? b[1].y : m.y, c & 4 ? b[1].z : m.z}};
}

struct Search {
  Search(const FreeForm& form, double e) : f(form), extent(e) {}
  const FreeForm& f;
  double extent;
  size_t budget = size_t(1) << 22;
  bool unbounded = false;
  std::optional<Box> box;

  void collect(const Box& b, int levels) {
    if (unbounded || !boundOf(f, b).containsZero()) return;
    if (budget-- == 0) {
      unbounded = true;
      return;
    }
    if (levels == 0) {
      // A leaf on the search cube's faces: the surface may go on beyond it.
      if (b[0].x <= -extent || b[0].y <= -extent || b[0].z <= -extent || b[1].x >= extent ||
          b[1].y >= extent || b[1].z >= extent)
        unbounded = true;
      return grow(box, b);
    }
    for (int c = 0; c < 8; ++c) collect(child(b, c), levels - 1);
  }
};

class Tessellator {
 public:
  Tessellator(const FreeForm& f, double cell, size_t maxTriangles, TriangleSoup& out)
      : f_(f), cell_(cell), max_(maxTriangles), out_(out) {}

  bool run(const Box& b) {
    visit(b);
    return !full_;
  }

 private:
  void visit(const Box& b) {
    if (full_ || !boundOf(f_, b).containsZero()) return;
    const Vec3d d = b[1] - b[0];
    if (std::max({d.x, d.y, d.z}) <= cell_) return leaf(b);
    // Halve the longer sides only, so that leaves stay near cubes whatever the box's shape.
    const double longest = std::max({d.x, d.y, d.z});
    const bool sx = d.x > 0.5 * longest, sy = d.y > 0.5 * longest, sz = d.z > 0.5 * longest;
    const Vec3d m = (b[0] + b[1]) * 0.5;
    for (int c = 0; c < 8; ++c) {
      if (((c & 1) && !sx) || ((c & 2) && !sy) || ((c & 4) && !sz)) continue;
      Box k = b;
      if (sx) (c & 1 ? k[0].x : k[1].x) = m.x;
      if (sy) (c & 2 ? k[0].y : k[1].y) = m.y;
      if (sz) (c & 4 ? k[0].z : k[1].z) = m.z;
      visit(k);
    }
  }

  // The cube's corners (bit 0: x, 1: y, 2: z) in six tetrahedra around the diagonal 0–7.
  void leaf(const Box& b) {
    Vec3d p[8];
    double v[8];
    for (int c = 0; c < 8; ++c) {
      p[c] = {c & 1 ? b[1].x : b[0].x, c & 2 ? b[1].y : b[0].y, c & 4 ? b[1].z : b[0].z};
      v[c] = f_.evaluate(p[c]);
    }
    static constexpr int kTetrahedra[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7},
                                              {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
    for (const auto& t : kTetrahedra) {
      int in[4], out[4], ni = 0, no = 0;
      for (int k = 0; k < 4; ++k) (inside(v[t[k]]) ? in[ni++] : out[no++]) = t[k];
      if (ni == 0 || no == 0) continue;
      if (ni == 1 || no == 1) {  // one vertex apart: one triangle on its three edges
        const int apart = ni == 1 ? in[0] : out[0];
        const int* rest = ni == 1 ? out : in;
        triangle(edgePoint(p, v, apart, rest[0]), edgePoint(p, v, apart, rest[1]),
                 edgePoint(p, v, apart, rest[2]));
      } else {  // two and two: a quadrilateral on the four mixed edges
        const Vec3d a = edgePoint(p, v, in[0], out[0]), b2 = edgePoint(p, v, in[0], out[1]),
                    c = edgePoint(p, v, in[1], out[1]), d = edgePoint(p, v, in[1], out[0]);
        triangle(a, b2, c);
        triangle(a, c, d);
      }
    }
  }

  // The surface point on edge i–j (one end inside, the other not): bisection from the ends.
  Vec3d edgePoint(const Vec3d* p, const double* v, int i, int j) {
    Vec3d a = p[i], b = p[j];
    const bool insideA = inside(v[i]);
    for (int k = 0; k < 24; ++k) {
      const Vec3d m = (a + b) * 0.5;
      (inside(f_.evaluate(m)) == insideA ? a : b) = m;
    }
    return (a + b) * 0.5;
  }

  void triangle(Vec3d a, Vec3d b, Vec3d c) {
    if (out_.triangles() >= max_) {
      full_ = true;
      return;
    }
    const Vec3d centre = (a + b + c) * (1.0 / 3);
    // Counter-clockwise seen from outside: the face normal along −∇F'.
    if (dot(cross(b - a, c - a), f_.gradient(centre)) > 0) std::swap(b, c);
    for (const Vec3d& q : {a, b, c}) {
      out_.positions.push_back(q);
      out_.normals.push_back(normalize(f_.gradient(q) * -1.0));
    }
  }

  const FreeForm& f_;
  double cell_;
  size_t max_;
  TriangleSoup& out_;
  bool full_ = false;
};

}  // namespace

std::optional<Box> surfaceBounds(const FreeForm& form, double extent, int levels, bool& unbounded) {
  Search s(form, extent);
  s.collect({Vec3d{-extent, -extent, -extent}, Vec3d{extent, extent, extent}}, levels);
  unbounded = s.unbounded;
  return s.unbounded ? std::nullopt : s.box;
}

bool tessellate(const FreeForm& form, const Box& box, double cell, size_t maxTriangles,
                TriangleSoup& out) {
  return Tessellator(form, cell, maxTriangles, out).run(box);
}

}  // namespace sv::freeform
