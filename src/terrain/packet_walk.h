// The rays of a screen block walked together over a height surface, one ray a SIMD lane (Highway,
// per target): the packet form of Caster::solveBilinear and solveBicubic (caster.h), the unit of work of
// the terrain's last levels (docs/terrain.md, "Packets").
//
// Each lane walks its own cells (a lane-masked Amanatides–Woo DDA) and, in every cell its ray may
// touch, solves the height above the surface exactly — a quadratic in t (bilinear), or the
// degree-6 polynomial of a Catmull–Rom patch along the ray (bicubic) — as the per-ray solve
// does, in float and in coordinates relative to the packet's anchor cell (a few hundred cells at
// most from it: 10⁻⁵ of a cell where the table's own coordinates would leave 10⁻³ at 16384). The
// lanes are independent — a lane's result depends only on its own ray, never on its neighbours or
// the lane count — so every SIMD target and the scalar fallback give the same bits.
//
// Based on: SPEC §12 (multi-level ray casting: at the finest level, the ray against the
// interpolated surface), §11 (bilinear or bicubic interpolation between the table's samples).
#pragma once

#include <cstdint>

namespace sv::terrain {

// Rays in a packet: a 4×4 block's.
constexpr int kPacketRays = 16;

// The surface a packet walks: one level's samples (Pyramid::MeanLevel, or the table itself), its
// cells [0, cellsX) × [0, cellsY), the table's footprint in the level's steps from the anchor
// (its last samples may lie beyond it), its skip map (Pyramid::TopLevel: the top of each square of
// Pyramid::kTopCells² cells), and the anchor the lanes' coordinates are relative to.
struct PacketGrid {
  const uint16_t* q = nullptr;  // width × (cellsY + 1) codes, row-major
  int width = 0;                // samples a row (≥ cellsX + 1)
  int cellsX = 0, cellsY = 0;
  const uint16_t* top = nullptr;  // topWidth × ⌈cellsY / kTopCells⌉ codes, and one of padding
  int topWidth = 0;
  // The table's bicubic surface (Pyramid::cellTops: per cell the top of its patch's Bézier hull,
  // cellsX a row): a lane walks the cells by these bounds and is parked at each whose bound its
  // ray may touch; the parked lanes' patches are solved together (Caster::solveBicubicCell's rule,
  // in float), and those that miss walk on. q is then the table. Null: the bilinear surface of q,
  // solved in the walk.
  const uint16_t* cellTop = nullptr;
  // The sample the lanes' x, y are measured from: a corner of a skip map's square (multiples of
  // Pyramid::kTopCells).
  int anchorI = 0, anchorJ = 0;
  float anchorZ = 0;  // the code their z is measured from (an integer)
  float footX0 = 0, footX1 = 0, footY0 = 0, footY1 = 0;
};

// A packet's lanes: lane l's ray is x = x0 + t·ex, y = y0 + t·ey (the level's sample steps from
// the anchor), z = z0 + t·ez (codes above anchorZ), walked over t in [t0, t1] clipped to the
// footprint. A lane with t0 > t1 is idle.
struct PacketLanes {
  alignas(64) float x0[kPacketRays], y0[kPacketRays], z0[kPacketRays];
  alignas(64) float ex[kPacketRays], ey[kPacketRays], ez[kPacketRays];
  alignas(64) float t0[kPacketRays], t1[kPacketRays];
  // Results: the first t at which the ray meets the surface (or is below it at its start: that
  // t), NaN where it met nothing in the cells walked; where its walk stopped: +∞ when it is done
  // (a hit, t1 reached, the footprint left, or idle), else — its steps taken — the t where its
  // next, unwalked cell begins.
  alignas(64) float hit[kPacketRays], reached[kPacketRays];
};

// Walks the packet's lanes at most `maxCells` steps each (the first `count` lanes; the rest are
// left idle). A step is a cell, or a square of the skip map passed at once: where a lane enters a
// square whose top its ray stays above until it leaves it. Cells: a lane solves only where its
// lowest point in the cell is not above the cell's highest corner, exactly as
// Caster::solveBilinear — on the bicubic table, not above its patch's top, as
// Caster::solveBicubic.
void walkPacket(const PacketGrid& grid, PacketLanes& lanes, int count, int maxCells);

}  // namespace sv::terrain
