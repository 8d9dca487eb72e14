// Multi-level ray casting of a height field (SPEC §12): bundles of rays — a screen window's, down
// to one sample's — marched in depth through the min/max pyramid (pyramid.h), the level of each
// step chosen from the window's projected size, a step skipped whenever the bundle's bounding box
// lies above the largest height its footprint allows; at the finest level one ray solves against
// the interpolated surface. The same cast answers the host's height and line-of-sight queries, so
// they agree with the picture exactly.
//
// Placement in the world (y up, the scene's convention): map east is +x, north is −z, height is
// +y. The map position (refU, refV) lies at the world origin. The base surface is the plane y = 0,
// or (radius > 0) a sphere of that radius through the origin, centre (0, −radius, 0): a table on
// a sphere is laid out on the tangent plane at the origin and carried onto the sphere by central
// (gnomonic) projection from its centre, heights along the sphere's radius. Gnomonic coordinates
// stretch distances by 1 + (ρ/R)² at ρ from the origin: 0.1 % at 200 km, where the Earth's
// curvature has dropped the ground by 3 km.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/quadric.h"
#include "terrain/height_field.h"
#include "terrain/packet_walk.h"
#include "terrain/pyramid.h"

namespace sv::terrain {

struct Placement {
  double refU = 0, refV = 0;  // the map position at the world origin
  double radius = 0;          // 0: the plane base; else the sphere's radius
};

// What the casts did, for the frame statistics.
struct CastCounters {
  uint64_t windows = 0;  // screen windows marched
  uint64_t steps = 0;    // depth steps tested against the pyramid
  uint64_t samples = 0;  // sample rays cast (each once, whether in a packet or alone)
  uint64_t lanes = 0;    // rays walked in packets (walkPacket's live lanes; once per packet walk)
  uint64_t rays = 0;     // single rays cast to the surface
  uint64_t solves = 0;   // finest-level steps solved against the interpolated surface
  uint64_t hits = 0;
  void add(const CastCounters& o) {
    windows += o.windows, steps += o.steps, samples += o.samples, lanes += o.lanes, rays += o.rays,
        solves += o.solves, hits += o.hits;
  }
};

// A bundle of rays from `origin` through the convex hull of up to four directions (a screen
// window's corner rays; a single ray repeats its one direction), a point of it at parameter s
// being origin + s·direction.
struct Bundle {
  Vec3d origin;
  Vec3d corner[4];
};

// A ray in a level's grid: x = x0 + s·ex, y = y0 + s·ey in its sample steps, heights
// z = z0 + s·ez in codes of the table (h = offset + scale·code).
struct GridRay {
  double x0, y0, z0, ex, ey, ez;
};

class Caster {
 public:
  Caster(const HeightField& field, const Pyramid& pyramid, Interpolation interp,
         const Placement& placement);

  // Grid coordinates (samples at integers, x east, y south) and height above the base of a world
  // point, and back.
  struct MapPoint {
    double gx, gy, h;
  };
  MapPoint toMap(Vec3d world) const {
    if (placement_.radius <= 0) return {ax_ * world.x + bx_, ay_ * world.z + by_, world.y};
    return toMapOnSphere(world);
  }
  Vec3d toWorld(double gx, double gy, double h) const;
  // The map position (metres) of grid coordinates.
  double mapU(double gx) const { return field_.originU + gx * field_.spacingU; }
  double mapV(double gy) const { return field_.originV - gy * field_.spacingV; }

  // Levels of detail (SPEC §11: the level from the projected size). A frame casts each ray against
  // the surface of the mean pyramid's level whose samples are as far apart as the ray's pixel is
  // long on the ground there (pyramid.h, Pyramid::mean) — the table's own interpolated surface
  // (level n) wherever a pixel covers at most a grid step, a filtered one beyond, as a texture's
  // MIP levels are: a far ridge is drawn from its mean heights instead of aliasing from samples
  // the pixel skips. `pixel`: the pixel's width per unit s in grid steps; the length on the ground
  // is that width stretched by 1/sin of the ray's angle with the base (at most kMaxStretch).
  // pixel = 0: level n everywhere (the host's queries).
  static constexpr double kMaxStretch = 4;
  int lodLevel(double s, double pixel, double stretch) const {
    const double w = pixel * s * stretch;
    const int n = pyramid_.gridLevel();
    if (!(w > 1)) return n;
    return std::max(n - int(std::ceil(std::log2(w))), 0);
  }
  double stretch(Vec3d d) const {
    const double r = std::sqrt(dot(d, d));
    // On a sphere the base's normal varies; the view's vertical is near enough for a level choice.
    return std::min(kMaxStretch, r / std::max(std::fabs(d.y), 1e-300));
  }

  // The surface's height at grid (gx, gy) — level `level` of detail, the table's interpolated
  // surface at level n (and by default); NaN beyond the table's footprint.
  double surface(double gx, double gy, int level = 1 << 30) const;
  // The unit outward normal of that surface (world) at grid (gx, gy), and the world directions of
  // map east and north there (unit, tangent to the base).
  Vec3d normal(double gx, double gy, Vec3d* east = nullptr, Vec3d* north = nullptr,
               int level = 1 << 30) const;

  // The bundle marched from s0 toward s1: the smallest s at which it may meet the surface at the
  // resolution of its own footprint (the pyramid level whose nodes are as wide as the bundle is
  // there, or as its level of detail if coarser), or s1 when it meets nothing before s1.
  // `footprint`: the bundle's width per unit s in grid steps (0 for one ray); `pixel`: as above.
  double march(const Bundle& b, double s0, double s1, double footprint, double pixel,
               CastCounters& c) const;
  // The first s in [s0, s1] at which origin + s·dir meets the surface (at the level of detail
  // `pixel` gives, as above) — or enters the solid below it through the prism's side — or NaN.
  // Exact to 10⁻⁴ of a grid step along the ray.
  double cast(Vec3d origin, Vec3d dir, double s0, double s1, CastCounters& c,
              double pixel = 0) const;

  // The rays of a block walked together (packet_walk.h), each at most `maxCells` steps over
  // `level`'s surface from its start — what cast() does for one ray first, for a packet: the walk
  // of every cell the ray crosses, the exact solve where it may touch its surface (bilinear, or
  // the table's bicubic patches, solved for the lanes parked at them together). Only on the
  // plane base (packetsApply).
  // Lane l: origin + s·dir[l] over [s0[l], s1[l]]; hit[l] its first crossing there (NaN: none in
  // the cells walked), reached[l] where a ray without one stopped (s1[l]: nothing before s1, else
  // where to go on from).
  struct Packet {
    Vec3d origin;
    int count = 0;
    Vec3d dir[kPacketRays];
    double s0[kPacketRays], s1[kPacketRays];
    double hit[kPacketRays], reached[kPacketRays];
  };
  bool packetsApply() const { return placement_.radius <= 0; }
  void walkPacket(Packet& p, int level, int maxCells, CastCounters& c) const;
  // The packet walked at the levels of detail along its rays (SPEC §11, work bounded by the
  // footprint): from the nearest lane's start at that start's level (`pixel` as for lodLevel,
  // `stretch` the longest of its rays'), each level over the span where it is the level of detail
  // — then the next coarser one. Results as walkPacket's; a lane whose walk stopped after
  // maxCells steps at some level, or that reached a level where packets do not apply, has
  // `reached` where to go on from alone (cast()).
  void walkPacketLevels(Packet& p, double pixel, double stretch, int maxCells,
                        CastCounters& c) const;

  const HeightField& field() const { return field_; }
  const Pyramid& pyramid() const { return pyramid_; }
  const Placement& placement() const { return placement_; }

 private:
  MapPoint toMapOnSphere(Vec3d world) const;
  // walkPacket's work for the packet's rays over spans [s0[l], s1[l]], its results into hit and
  // reached (walkPacketLevels walks a packet's rays over several spans without copying it).
  void walkLanes(const Packet& rays, const double* s0, const double* s1, double* hit,
                 double* reached, int level, int maxCells, CastCounters& c) const;
  struct Box {
    double gx0, gx1, gy0, gy1, h0, h1;  // grid rectangle and heights above the base
  };
  Box bounds(const Bundle& b, double sa, double sb) const;
  // f(s) = height above level `level`'s surface of origin + s·dir (+∞ beyond the footprint).
  double above(Vec3d origin, Vec3d dir, double s, int level) const;
  // The first root of `above` in [sa, sb], sampled at eighths of the level's cells, or NaN.
  double solve(Vec3d origin, Vec3d dir, double sa, double sb, double fa, int level) const;
  // The same for the plane base and a bilinear surface (the table's, bilinear; any mean level),
  // exactly: the ray walked cell by cell (a 2D DDA), in each cell the height above the surface a
  // quadratic in s, its first root.
  double solveBilinear(Vec3d origin, Vec3d dir, double sa, double sb, int level) const;
  // The same for the plane base and the table's Catmull–Rom surface: cell by cell, a cell solved
  // only where the ray may touch its bound, there its patch as a polynomial sampled at eighths of
  // a cell along the ray and the first bracket refined.
  double solveBicubic(Vec3d origin, Vec3d dir, double sa, double sb) const;
  // Its cell (i, j) over [s, out]: the first root there, or NaN. `bounded`: the ray may touch
  // the cell's Bézier hull (Pyramid::cellTops said so); else that is tested first.
  double solveBicubicCell(const GridRay& r, int i, int j, double s, double out, bool bounded) const;
  // The ray in the grid of a level `step` grid steps apart (GridRay).
  GridRay gridRay(Vec3d origin, Vec3d dir, double step) const;
  // The first root in [sa, sb] at `level`, by whichever of the three applies.
  double solveAt(Vec3d origin, Vec3d dir, double sa, double sb, int level) const;
  // Grid steps per unit s of the fastest of the bundle's directions, horizontally.
  double gridSpeed(const Bundle& b) const;

  const HeightField& field_;
  const Pyramid& pyramid_;
  Interpolation interp_;
  Placement placement_;
  // The world → grid map of the plane base: gx = ax·x + bx, gy = ay·z + by.
  double ax_ = 1, bx_ = 0, ay_ = 1, by_ = 0;
  double margin_ = 0;  // added to the pyramid's bounds against rounding: 10⁻⁹ of the relief
};

}  // namespace sv::terrain
