// Deferred shading (ShadeMode::material at one sample; Highway, per target): opaque triangles
// only record which triangle won each pixel (visibleBlock), and when the tile's lists are drawn
// each pixel is shaded once, by its winner — the split of visibility from shading that the
// image generators of the seeds made in hardware (SPEC §1).
//
// Per-target include guard (Highway's convention for -inl.h files): included by tile_kernel.cpp,
// once per SIMD target, so that everything here inlines into the kernel.
#if defined(SV_RASTER_DEFERRED_SHADING_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_RASTER_DEFERRED_SHADING_INL_H_
#undef SV_RASTER_DEFERRED_SHADING_INL_H_
#else
#define SV_RASTER_DEFERRED_SHADING_INL_H_
#endif

#include <algorithm>

#include "core/check.h"
#include "raster/kernel_common-inl.h"
#include "shade/shading.h"

HWY_BEFORE_NAMESPACE();
namespace sv::raster {
namespace HWY_NAMESPACE {

// Deferred shading's list of the triangles that won pixels since the last shading pass, in draw
// order, each with its box in the tile's 4×4 blocks: shadeVisible reads the blocks of each box for
// the pixels that still record the triangle — the triangle's pixels, batched without searching the
// tile for them. Scanning the whole tile costs the same however many triangles there are, the
// list's reads grow with their boxes' blocks: past kBudget blocks in all (4 a block — large
// triangles, or several layers) the scan is the cheaper. docs/performance.md.
struct WinnerList {
  static constexpr int kBudget = 4 * kBlocksPerTileSide * kBlocksPerTileSide;
  struct Entry {
    uint32_t id;                 // setup storage index
    uint8_t bx0, by0, bx1, by1;  // the box's first and last block column and row
  };
  int count = 0, blocks = 0;
  Entry entry[kBudget];  // (a box holds a block at least)

  // Triangle `id`, which won pixels in the tile-local pixel box [x0, x1] × [y0, y1].
  void add(uint32_t id, int x0, int y0, int x1, int y1) {
    SV_DCHECK(0 <= x0 && x0 <= x1 && x1 < kTileSize && 0 <= y0 && y0 <= y1 && y1 < kTileSize);
    if (blocks > kBudget) return;  // the scan's, for the rest of the pass
    const int bx0 = x0 >> kBlockLog2, by0 = y0 >> kBlockLog2;
    const int bx1 = x1 >> kBlockLog2, by1 = y1 >> kBlockLog2;
    blocks += (bx1 - bx0 + 1) * (by1 - by0 + 1);
    if (blocks <= kBudget)
      entry[count++] = {id, uint8_t(bx0), uint8_t(by0), uint8_t(bx1), uint8_t(by1)};
  }
  // Whether shadeVisible reads the list rather than scanning the tile.
  bool useful() const { return blocks <= kBudget; }
  void reset() { count = blocks = 0; }
};

// Deferred shading (PixelOp::visibility's second half): shades every pixel that records a
// triangle, with that triangle's planes and material (or its Gouraud colour), and clears the
// records. Pixels are batched by triangle, up to 16 to a batch from anywhere in the tile, so that
// a batch fills the SIMD lanes even for triangles of a few pixels (a batch per 4×4 block and
// triangle shaded 3 lanes for every pixel on tris 100k × 10 px). The pass in three steps:
//   1. find each triangle's pixels (findFromList, findByScan): in the blocks of its box
//      (WinnerList), triangle after triangle; where the list is over its budget, by a scan of the
//      tile, with open batches in a small table by triangle, a batch leaving it when full or when
//      another triangle needs its slot (take, takeWhole);
//   2. evaluate each batch (emit): its attributes and texture coordinates, the texels requested
//      (shade::textureCoordinates); a pixel-shaded batch short of 16 (on tris 100k × 10 px a batch
//      held 7.2 pixels on average) joins other triangles' pixels of its material in the mixer
//      (mixIn), which passes on whole batches (shipMix);
//   3. shade and write (finishQueue): pixel-shaded batches wait in a queue, so that the texels
//      each will read have been requested a whole queue's work earlier.
// A pixel's planes are evaluated at it directly, (c0 + dx·X) + dy·Y. docs/performance.md.
class DeferredShader {
 public:
  explicit DeferredShader(const TileContext& ctx) : ctx_(ctx) {}

  void run() {
    WinnerList* list = ctx_.winners;
    if (list && list->useful())
      findFromList(*list);
    else
      findByScan();
    if (list) list->reset();
    if (mix_.count) shipMix();
    finishQueue();
  }

 private:
  using DF = hn::CappedTag<float, kBlockPixels>;
  using DI = hn::RebindToSigned<DF>;
  using DU = hn::RebindToUnsigned<DF>;
  using DU16 = hn::Rebind<uint16_t, DF>;
  static constexpr DF df{};
  static constexpr DI di{};
  static constexpr DU du{};
  static constexpr DU16 du16{};
  static size_t lanes() { return hn::Lanes(df); }
  // Lane i holds i: the pixel numbers of a vector of a block (Highway's Iota builds its vector in
  // memory, lane by lane; a constant table is one load).
  static hn::Vec<DI> laneIndex() { return hn::Load(di, kLaneIndex); }

  // A pixel is named by its index in the tile's block-major layout (framebuffer.h): block·16 +
  // lane.
  struct Batch {
    uint32_t id = kNoTriangle;
    int count = 0;
    // Room for a whole vector appended past a count of up to 15 (take).
    alignas(64) int32_t pixel[2 * kBlockPixels];
  };
  struct Queued {
    shade::Fragments fragments;
    shade::TexCoords coordinates;
    const shade::MaterialShading* material;
    int count;
    alignas(64) int32_t pixel[kBlockPixels];
  };
  // Pixels of one material from batches of fewer than 16 — triangles of a few pixels, or the
  // last pixels of larger ones — gathered with what shading needs of them (their attributes,
  // texture coordinates and levels of detail, each from its own triangle) until they fill a
  // queued batch, so that a 10-pixel triangle does not shade 16 lanes of its own. Room for 15
  // waiting lanes and a whole batch appended (an append writes 16 lanes).
  static constexpr int kMixLanes = 2 * kBlockPixels;
  struct Mixer {
    const shade::MaterialShading* material = nullptr;
    int count = 0;
    alignas(64) float q[kMixLanes];
    alignas(64) float color[kColorChannels][kMixLanes];
    alignas(64) float attribute[shade::kAttributeCount][kMixLanes];
    alignas(64) float lod[kMixLanes];
    alignas(64) float x0[kMixLanes];
    alignas(64) float y0[kMixLanes];
    alignas(64) int32_t pixel[kMixLanes];
  };
  // 256 open batches: a 64 × 64 tile of 10-pixel triangles holds about 400, and with 64 slots
  // their hash collisions emitted many batches half empty (docs/performance.md).
  static constexpr int kSlotBits = 8, kSlots = 1 << kSlotBits, kQueue = 32;
  // Where a vector holds a whole batch, the mixer joins batches by turning lanes in registers;
  // through memory, lanes written at an offset and read back whole wait for those stores to retire
  // (store-to-load forwarding fails). Narrower vectors append through memory.
  static constexpr bool kRotate = !HWY_HAVE_SCALABLE && hn::MaxLanes(DF()) == size_t(kBlockPixels);

  // ---- Step 1: each triangle's pixels, into batches.

  // Each triangle's blocks, in draw order (WinnerList): the pixels of a block that still record
  // the triangle are its own, taken by one compare and one compress; a block it holds whole is a
  // batch by itself, lane for lane (store's vector path). A batch's pixels stay in scan order.
  void findFromList(const WinnerList& list) {
    ++ctx_.stats->shadedByList;
    const auto none = hn::Set(du, kNoTriangle);
    const size_t n = lanes();
    Batch b;
    for (int e = 0; e < list.count; ++e) {
      const WinnerList::Entry entry = list.entry[e];
      if (b.count) emit(b);
      b.id = entry.id;
      const auto id = hn::Set(du, entry.id);
      for (int by = entry.by0; by <= entry.by1; ++by)
        for (int bx = entry.bx0; bx <= entry.bx1; ++bx) {
          const int block = by * kBlocksPerTileSide + bx;
          uint32_t* visible = ctx_.visible + block * kBlockPixels;
          const int first = block * kBlockPixels;
          bool whole = b.count == 0;
          for (size_t i = 0; whole && i < size_t(kBlockPixels); i += n)
            whole = hn::AllTrue(du, hn::Eq(hn::LoadU(du, visible + i), id));
          if (whole) {
            takeWhole(b, entry.id, first);
            continue;
          }
          for (size_t i = 0; i < size_t(kBlockPixels); i += n) {
            const auto mine = hn::Eq(hn::LoadU(du, visible + i), id);
            storeWhere(none, mine, du, visible + i);
            take(b, entry.id, hn::Add(laneIndex(), hn::Set(di, first + int(i))), mine);
          }
        }
    }
    if (b.count) emit(b);
  }

  // Otherwise the tile's records a vector at a time: each triangle in a vector takes all its
  // pixels there at once (a compress of their numbers), so the work goes with the triangles a
  // block holds, not with its pixels. A batch's pixels stay in scan order.
  void findByScan() {
    ++ctx_.stats->shadedByScan;
    const auto none = hn::Set(du, kNoTriangle);
    const size_t n = lanes();
    for (int start = 0; start < kTilePixels; start += int(n)) {
      uint32_t* visible = ctx_.visible + start;
      if ((start & (kBlockPixels - 1)) == 0) {
        // A block one triangle holds whole (takeWhole).
        const uint32_t first = visible[0];
        bool whole = first != kNoTriangle;
        for (size_t i = 0; whole && i < size_t(kBlockPixels); i += n)
          whole = hn::AllTrue(du, hn::Eq(hn::LoadU(du, visible + i), hn::Set(du, first)));
        if (whole) {
          Batch b;
          takeWhole(b, first, start);
          start += kBlockPixels - int(n);
          continue;
        }
      }
      const auto ids = hn::LoadU(du, visible);
      auto left = hn::Ne(ids, none);
      if (hn::AllFalse(du, left)) continue;
      hn::StoreU(none, du, visible);
      alignas(64) uint32_t id[kBlockPixels];
      hn::Store(ids, du, id);
      const auto pixels = hn::Add(laneIndex(), hn::Set(di, start));
      do {
        const uint32_t t = id[hn::FindKnownFirstTrue(du, left)];
        const auto mine = hn::And(left, hn::Eq(ids, hn::Set(du, t)));
        left = hn::AndNot(mine, left);
        Batch& b = slots_[(t * 0x9E3779B1u) >> (32 - kSlotBits)];  // a multiplicative hash
        if (b.id != t) {
          if (b.count) emit(b);
          b.id = t;
        }
        take(b, t, pixels, mine);
      } while (!hn::AllFalse(du, left));
    }
    for (Batch& b : slots_)
      if (b.count) emit(b);
  }

  // Appends the lanes `mine` of `pixels` to triangle t's batch b, which leaves when full (the rest
  // start its next).
  template <class VI, class M>
  void take(Batch& b, uint32_t t, VI pixels, M mine) {
    SV_DCHECK_LT(b.count, kBlockPixels);  // room for a whole vector past it
    hn::StoreU(hn::Compress(pixels, hn::RebindMask(di, mine)), di, b.pixel + b.count);
    b.count += int(hn::CountTrue(du, mine));
    if (b.count >= kBlockPixels) {
      const int rest = b.count - kBlockPixels;
      b.count = kBlockPixels;
      emit(b);
      std::copy_n(b.pixel + kBlockPixels, rest, b.pixel);
      b.id = t;
      b.count = rest;
    }
  }

  // Block `first`'s 16 pixels, all triangle t's, as a batch b by itself, lane for lane (store's
  // vector path), their records cleared; b is left open for t.
  void takeWhole(Batch& b, uint32_t t, int first) {
    const auto none = hn::Set(du, kNoTriangle);
    for (size_t i = 0; i < size_t(kBlockPixels); i += lanes()) {
      hn::StoreU(none, du, ctx_.visible + first + i);
      hn::Store(hn::Add(laneIndex(), hn::Set(di, first + int(i))), di, b.pixel + i);
    }
    b.id = t;
    b.count = kBlockPixels;
    emit(b);
    b.id = t;
  }

  // ---- Step 2: a batch's attributes, whole batches to the queue.

  // shade::attributesUsed of the material last asked about (batches run in long runs of one).
  unsigned attributesOf(const shade::MaterialShading* m) {
    if (m != usedMaterial_) {
      usedMaterial_ = m;
      usedBits_ = shade::attributesUsed(*m, *ctx_.environment);
    }
    return usedBits_;
  }

  // Shades (Gouraud) or queues (material) batch b and empties it: a whole batch (or one to be
  // filtered anisotropically, which reads the triangle's gradients) as a queue entry of its own,
  // a partial one through the mixer. Texels are requested (shade::textureCoordinates) as the
  // batch is evaluated, one bounding box per batch (so a mixed batch's come in several; a whole
  // batch's only when it starts a run, requestedWhole_).
  void emit(Batch& b) {
    const shade::MaterialShading* material = ctx_.attributes[b.id].material;
    if (!material) {
      alignas(64) uint16_t c16[kColorChannels][kBlockPixels];
      evaluate(b, nullptr, c16);
      store(b.pixel, b.count, c16);
    } else if (b.count == kBlockPixels || (material->texture && material->anisotropic)) {
      Queued& q = queue_[queued_];
      evaluate(b, &q.fragments, nullptr);
      if (material->texture)
        shade::textureCoordinates(*material, q.fragments, q.coordinates, b.id != requestedWhole_);
      requestedWhole_ = b.id;
      std::copy_n(b.pixel, b.count, q.pixel);  // (store reads no further)
      enqueue(material, b.count);
    } else {
      shade::Fragments f;
      shade::TexCoords tc;
      evaluate(b, &f, nullptr);
      if (material->texture) shade::textureCoordinates(*material, f, tc);
      if (mix_.count && mix_.material != material) shipMix();
      mix_.material = material;
      mixIn(b, f, tc);
    }
    b.id = kNoTriangle;
    b.count = 0;
  }

  // The attributes of batch b's pixels into f (material) or their Gouraud colour into c16; unused
  // lanes repeat the last pixel: valid positions, no extra texels.
  void evaluate(const Batch& b, shade::Fragments* f, uint16_t (*c16)[kBlockPixels]) {
    const TriangleSetup& t = ctx_.setups[b.id];
    const AttributeSetup& a = ctx_.attributes[b.id];
    const auto lastPixel = hn::Set(di, b.pixel[b.count - 1]);
    const unsigned used = f ? attributesOf(a.material) : 0;
    for (size_t i = 0; i < size_t(kBlockPixels); i += lanes()) {
      const auto p = hn::IfThenElse(hn::FirstN(di, size_t(std::max(b.count - int(i), 0))),
                                    hn::Load(di, b.pixel + i), lastPixel);
      const auto block = hn::ShiftRight<2 * kBlockLog2>(p);
      const auto lane = hn::And(p, hn::Set(di, kBlockPixels - 1));
      const auto x =
          hn::Or(hn::ShiftLeft<kBlockLog2>(hn::And(block, hn::Set(di, kBlocksPerTileSide - 1))),
                 hn::And(lane, hn::Set(di, kBlockSize - 1)));
      const auto y = hn::Or(hn::ShiftLeft<kBlockLog2>(hn::ShiftRight<4>(block)),
                            hn::ShiftRight<kBlockLog2>(lane));
      static_assert(kBlocksPerTileSide == 16, "block row = block >> 4");
      const auto X = hn::ConvertTo(df, hn::Add(x, hn::Set(di, ctx_.originX - t.minX)));
      const auto Y = hn::ConvertTo(df, hn::Add(y, hn::Set(di, ctx_.originY - t.minY)));
      auto at = [&](const Plane& pl) {
        return hn::Add(hn::Add(hn::Set(df, pl.c0), hn::Mul(hn::Set(df, pl.dx), X)),
                       hn::Mul(hn::Set(df, pl.dy), Y));
      };
      const auto qv = at(t.invW);
      const Plane* color[kColorChannels] = {&t.red, &t.green, &t.blue};
      if (!f) {
        // shadeBlock's Gouraud colour.
        const auto w = hn::Div(hn::Set(df, 1.0f), qv);
        for (int ch = 0; ch < kColorChannels; ++ch)
          hn::Store(hn::DemoteTo(du16, colorToLanes(df, at(*color[ch]), w)), du16, c16[ch] + i);
        continue;
      }
      hn::Store(qv, df, f->q + i);
      const auto w = hn::Div(hn::Set(df, 1.0f), hn::Max(qv, hn::Set(df, 1e-30f)));
      for (int ch = 0; ch < kColorChannels; ++ch)
        hn::Store(hn::Min(hn::Max(hn::Mul(at(*color[ch]), w), hn::Zero(df)), hn::Set(df, 1.0f)), df,
                  f->color[ch] + i);
      for (int k = 0; k < shade::kAttributeCount; ++k)
        if (used & (1u << k)) hn::Store(at(a.planes[k]), df, f->attribute[k] + i);
    }
    if (f) {
      f->count = kBlockPixels;
      f->qdx = t.invW.dx;
      f->qdy = t.invW.dy;
      f->udx = a.planes[shade::kU].dx;
      f->udy = a.planes[shade::kU].dy;
      f->vdx = a.planes[shade::kV].dx;
      f->vdy = a.planes[shade::kV].dy;
    }
  }

  // A partial batch's evaluated lanes (f, tc) into the mixer, which queues 16 once it has them.
  void mixIn(const Batch& b, const shade::Fragments& f, const shade::TexCoords& tc) {
    const shade::MaterialShading* material = mix_.material;
    const unsigned used = attributesOf(material);
    if constexpr (kRotate) {
      // The batch turned by the mixer's count: its first lanes land after those waiting, and the
      // lanes that do not fit are then already at the start, where they wait in turn.
      const bool full = mix_.count + b.count >= kBlockPixels;
      Queued& q = queue_[queued_];
      const auto keep = hn::FirstN(di, size_t(mix_.count));
      const auto turn =
          hn::And(hn::Sub(laneIndex(), hn::Set(di, mix_.count)), hn::Set(di, kBlockPixels - 1));
      auto join = [&](auto d, const auto* from, auto* held, auto* to) {
        const auto r = hn::TableLookupLanes(hn::Load(d, from), hn::IndicesFromVec(d, turn));
        const auto c = hn::IfThenElse(hn::RebindMask(d, keep), hn::Load(d, held), r);
        if (full) hn::Store(c, d, to);
        hn::Store(full ? r : c, d, held);
      };
      join(df, f.q, mix_.q, q.fragments.q);
      for (int ch = 0; ch < kColorChannels; ++ch)
        join(df, f.color[ch], mix_.color[ch], q.fragments.color[ch]);
      for (int k = 0; k < shade::kAttributeCount; ++k)
        if (used & (1u << k)) join(df, f.attribute[k], mix_.attribute[k], q.fragments.attribute[k]);
      if (material->texture) {
        join(df, tc.lod, mix_.lod, q.coordinates.lod);
        join(df, tc.x0, mix_.x0, q.coordinates.x0);
        join(df, tc.y0, mix_.y0, q.coordinates.y0);
      }
      join(di, b.pixel, mix_.pixel, q.pixel);
      if (full) {
        q.fragments.count = kBlockPixels;
        mix_.count += b.count - kBlockPixels;
        enqueue(material, kBlockPixels);
      } else {
        mix_.count += b.count;
      }
    } else {
      auto append = [&](const float* from, float* to) {
        for (size_t i = 0; i < size_t(kBlockPixels); i += lanes())
          hn::StoreU(hn::Load(df, from + i), df, to + mix_.count + i);
      };
      append(f.q, mix_.q);
      for (int ch = 0; ch < kColorChannels; ++ch) append(f.color[ch], mix_.color[ch]);
      for (int k = 0; k < shade::kAttributeCount; ++k)
        if (used & (1u << k)) append(f.attribute[k], mix_.attribute[k]);
      if (material->texture) {
        append(tc.lod, mix_.lod);
        append(tc.x0, mix_.x0);
        append(tc.y0, mix_.y0);
      }
      for (size_t i = 0; i < size_t(kBlockPixels); i += lanes())
        hn::StoreU(hn::Load(di, b.pixel + i), di, mix_.pixel + mix_.count + i);
      mix_.count += b.count;
      if (mix_.count >= kBlockPixels) shipMix();
    }
  }

  // Lanes [0, 16) of one of the mixer's arrays to `to` (lanes from `count` on repeat lane
  // count − 1), and, when more are waiting, lanes [16, 32) down to [0, 16).
  static void shipLanes(float* from, float* to, int count, bool rest) {
    const auto last = hn::Set(df, from[count - 1]);
    for (size_t i = 0; i < size_t(kBlockPixels); i += lanes()) {
      hn::Store(hn::IfThenElse(hn::FirstN(df, size_t(std::max(count - int(i), 0))),
                               hn::Load(df, from + i), last),
                df, to + i);
      if (rest) hn::Store(hn::Load(df, from + kBlockPixels + i), df, from + i);
    }
  }

  // Queues the mixer's first 16 lanes (or all it has) and moves the rest down.
  void shipMix() {
    const int count = std::min(mix_.count, kBlockPixels);
    Queued& q = queue_[queued_];
    shade::Fragments& f = q.fragments;
    f.count = kBlockPixels;
    const bool rest = mix_.count > kBlockPixels;
    const unsigned used = attributesOf(mix_.material);
    shipLanes(mix_.q, f.q, count, rest);
    for (int ch = 0; ch < kColorChannels; ++ch) shipLanes(mix_.color[ch], f.color[ch], count, rest);
    for (int k = 0; k < shade::kAttributeCount; ++k)
      if (used & (1u << k)) shipLanes(mix_.attribute[k], f.attribute[k], count, rest);
    if (mix_.material->texture) {
      shipLanes(mix_.lod, q.coordinates.lod, count, rest);
      shipLanes(mix_.x0, q.coordinates.x0, count, rest);
      shipLanes(mix_.y0, q.coordinates.y0, count, rest);
    }
    for (size_t i = 0; i < size_t(kBlockPixels); i += lanes()) {
      hn::Store(hn::Load(di, mix_.pixel + i), di, q.pixel + i);
      if (rest) hn::Store(hn::Load(di, mix_.pixel + kBlockPixels + i), di, mix_.pixel + i);
    }
    mix_.count -= count;
    enqueue(mix_.material, count);
  }

  // ---- Step 3: shading the queue, writing the colours.

  void enqueue(const shade::MaterialShading* material, int count) {
    Queued& q = queue_[queued_];
    q.material = material;
    q.count = count;
    if (++queued_ == kQueue) finishQueue();
  }

  void finishQueue() {
    for (int e = 0; e < queued_; ++e) {
      const Queued& q = queue_[e];
      alignas(64) float rgba[4][kBlockPixels];
      shade::shadeFragments(*q.material, *ctx_.environment, q.fragments, q.coordinates, rgba);
      alignas(64) uint16_t c16[kColorChannels][kBlockPixels];
      for (int ch = 0; ch < kColorChannels; ++ch)
        for (size_t i = 0; i < size_t(kBlockPixels); i += lanes())
          hn::Store(hn::DemoteTo(du16, unitToLanes(df, hn::Load(df, rgba[ch] + i))), du16,
                    c16[ch] + i);
      store(q.pixel, q.count, c16);
    }
    queued_ = 0;
  }

  // Writes lanes [0, count) of 16-bit colour c16 to their pixels.
  void store(const int32_t* pixel, int count, const uint16_t (*c16)[kBlockPixels]) {
    // 16 lanes that are one block's pixels in order, whether one triangle's or several's: three
    // vector stores.
    bool block = count == kBlockPixels && (pixel[0] & (kBlockPixels - 1)) == 0 &&
                 pixel[kBlockPixels - 1] == pixel[0] + kBlockPixels - 1;
    for (size_t i = 0; block && i < size_t(kBlockPixels); i += lanes())
      block = hn::AllTrue(di, hn::Eq(hn::Load(di, pixel + i),
                                     hn::Add(laneIndex(), hn::Set(di, pixel[0] + int(i)))));
    if (block) {
      uint16_t* dst = ctx_.color + size_t(pixel[0] >> (2 * kBlockLog2)) * kColorPerBlock;
      for (int ch = 0; ch < kColorChannels; ++ch)
        for (size_t i = 0; i < size_t(kBlockPixels); i += lanes())
          hn::StoreU(hn::Load(du16, c16[ch] + i), du16, dst + ch * kBlockPixels + i);
      return;
    }
    for (int l = 0; l < count; ++l) {
      const int32_t p = pixel[l];
      uint16_t* dst = ctx_.color + size_t(p >> (2 * kBlockLog2)) * kColorPerBlock +
                      size_t(p & (kBlockPixels - 1));
      for (int ch = 0; ch < kColorChannels; ++ch) dst[ch * kBlockPixels] = c16[ch][l];
    }
  }

  const TileContext& ctx_;
  Batch slots_[kSlots];  // findByScan's open batches, by a hash of the triangle
  Queued queue_[kQueue];
  int queued_ = 0;
  // (Zeroed: the vector mixer reads its arrays whole, waiting lanes or not.)
  Mixer mix_{};
  const shade::MaterialShading* usedMaterial_ = nullptr;  // attributesOf's
  unsigned usedBits_ = 0;
  // The triangle of the last whole batch: a run of one triangle's whole blocks requests its
  // texels with its first block only. The blocks after it read texels next to those already read
  // (a block's box overlaps its neighbour's by about half); their requests cost more than the
  // misses they hid (docs/performance.md).
  uint32_t requestedWhole_ = kNoTriangle;
};

// The tile's deferred shading pass (DeferredShader).
HWY_NOINLINE void shadeVisible(const TileContext& ctx) { DeferredShader(ctx).run(); }

}  // namespace HWY_NAMESPACE
}  // namespace sv::raster
HWY_AFTER_NAMESPACE();

#endif  // SV_RASTER_DEFERRED_SHADING_INL_H_
