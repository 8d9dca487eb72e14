// VESA MPCDI (Multiple Projection Common Data Interchange) files: the reader, the writer, and the
// display mappings a region's warp gives (issue 34 item 1; docs/display.md "MPCDI").
//
// A file is a zip archive holding `mpcdi.xml` and, per region, a PFM geometry warp, optional PNG
// alpha and beta blend maps and an optional PFM distortion map, named by the XML's <files>. The
// subset read and written: profiles 2d (2D media) and 3d (3D simulation), levels 1 … 4, one- or
// three-component float PFM, 8- and 16-bit greyscale PNG blend maps. Everything the reader keeps
// the writer writes back, and the reader reads the writer's files back exactly (floats bit for
// bit).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "display/geometry.h"
#include "synthvis/result.h"

namespace sv::display {

// What a file may claim before anything is allocated. Sizes beyond these are refused with an
// error naming the file, the entry and the limit.
struct MpcdiLimits {
  uint64_t maxArchiveBytes = uint64_t(1) << 30;  // the .mpcdi file itself
  uint64_t maxEntryBytes = uint64_t(1) << 30;    // one decompressed zip entry
  uint64_t maxXmlBytes = uint64_t(16) << 20;     // mpcdi.xml decompressed
  int maxEntries = 1024;                         // entries in the archive's directory
  int maxRegions = 64;                           // in all buffers together
  int maxSide = 16384;                           // a warp or blend map's side, and a resolution
  uint64_t maxSamples = uint64_t(1) << 26;       // a warp or blend map's width × height
};

// A PFM grid (Debevec's Portable Float Map): width × height samples of `channels` floats (1 for
// "Pf", 3 for "PF"), rows top first in memory (the file stores them bottom first).
struct FloatMap {
  int width = 0, height = 0, channels = 3;
  std::vector<float> values;  // width · height · channels
  const float* at(int x, int y) const {
    return values.data() + (size_t(y) * size_t(width) + size_t(x)) * size_t(channels);
  }
};

// A greyscale PNG blend map: codes 0 … 2^bitDepth − 1, rows top first.
struct BlendMap {
  int width = 0, height = 0;
  int bitDepth = 8;  // 8 or 16
  std::vector<uint16_t> codes;
};

// The region's view frustum (MPCDI 3d profile): the eye's orientation and window, the same
// conventions as Orientation and Window (geometry.h).
struct MpcdiFrustum {
  Orientation orientation;
  Window window;
};

// <coordinateFrame>: kept as read and written back; the mappings below do not use it.
struct MpcdiCoordinateFrame {
  double pos[3] = {0, 0, 0};
  double yaw[3] = {0, 0, 0}, pitch[3] = {0, 0, 0}, roll[3] = {0, 0, 0};
};

struct MpcdiRegion {
  std::string id;
  int xResolution = 0, yResolution = 0;           // the region's pixels
  double x = 0, y = 0, xSize = 1, ySize = 1;      // its place in the buffer, normalized
  std::optional<MpcdiFrustum> frustum;            // required in the 3d profile
  std::optional<MpcdiCoordinateFrame> coordinateFrame;
  // <fileset>: the geometry warp (required) and what goes with it.
  std::string warpPath;
  FloatMap warp;                                  // 3 channels
  std::string geometricUnit = "m";                // as written; 2d and 3d warps are normalized
  std::string interpolation = "linear";
  std::string originOf3DData = "idealEyePoint";
  std::string alphaPath;
  std::optional<BlendMap> alpha;
  double alphaGammaEmbedded = 1;                  // linear alpha = (code / max)^gammaEmbedded
  std::string betaPath;
  std::optional<BlendMap> beta;
  std::string distortionPath;
  std::optional<FloatMap> distortion;             // kept, not interpreted
};

struct MpcdiBuffer {
  std::string id;
  int xResolution = 0, yResolution = 0;
  std::vector<MpcdiRegion> regions;
};

enum class MpcdiProfile : uint8_t { media2d, simulation3d };  // "2d", "3d"

struct Mpcdi {
  MpcdiProfile profile = MpcdiProfile::simulation3d;
  int level = 1;  // 1 … 4
  std::string version = "1.0";
  std::string date;  // as written, e.g. "2026-12-05 14:00:00"
  std::vector<MpcdiBuffer> buffers;
};

// The file at `path`, or `size` bytes at `data` named `name` in errors. An error's file is the
// archive and its position the entry (and line, for mpcdi.xml): "rig.mpcdi:mpcdi.xml:12: …".
Result<Mpcdi> readMpcdi(const std::string& path, const MpcdiLimits& limits = {});
Result<Mpcdi> parseMpcdi(const void* data, size_t size, const std::string& name,
                         const MpcdiLimits& limits = {});

// The archive bytes of `m` (deflate-compressed entries), or the file at `path`. Regions whose
// paths are empty get "<buffer>/<region>_warp.pfm" (and _alpha.png, _beta.png,
// _distortion.pfm). Refuses (with `name` or `path` in the error) what the reader would refuse:
// duplicate ids, sizes beyond the default limits, non-finite numbers outside the warp's invalid
// marker.
Result<std::string> encodeMpcdi(const Mpcdi& m, const std::string& name);
Status writeMpcdi(const std::string& path, const Mpcdi& m);

// PFM bytes alone (the warp format), for the tests and the fuzz target: the writer writes
// little-endian (scale −1) rows bottom first; the reader takes either byte order.
std::string encodePfm(const FloatMap& map);
Result<FloatMap> parsePfm(const std::string& bytes, const std::string& name,
                          const MpcdiLimits& limits = {});

// Warp samples: a sample is valid when its x and y are finite; the invalid marker is x and y both
// NaN (its third value is then anything). Sample (i, j) of a w × h warp sits at the region pixel
// position ((i + 0.5)·W/w, (j + 0.5)·H/h) of a W × H region, so a warp of the region's own size
// (level 2's per-pixel warp) has one sample at each pixel centre. Between samples the warp is
// bilinear; in the half cell beyond the outermost sample centres it is extrapolated linearly from
// the edge cell. A pixel is invalid when any sample weighing in it is. The warp's x, y are content coordinates normalized to [0, 1]:
// (0, 0) the content's top-left corner, x right, y down — of the buffer's content in the 2d
// profile, of the frustum's image in the 3d profile.
struct ContentMap {
  int width = 0, height = 0;
  std::vector<Vec2> uv;
  std::vector<uint8_t> valid;
};
// The warp at region pixel (px, py) (continuous, pixel centres at +0.5), or nothing when invalid.
std::optional<Vec2> sampleWarp(const MpcdiRegion& region, double px, double py);
ContentMap contentMap(const MpcdiRegion& region);

// The 3d profile's display mapping: each pixel centre's content coordinate taken through the
// region's frustum to a unit direction in the eye frame (geometry.h) — the frustum's orientation
// applied to (tan l + u·(tan r − tan l), tan t − v·(tan t − tan b), −1). Fails when the region has
// no frustum.
Result<DirectionMap> directionMap(const MpcdiRegion& region);

// A 3d-profile region for a projector of `geometry` drawn from `frustum` (the image generator's
// view): a w × h warp (sample centres as above) holding where each sample's screen point lies in
// the frustum's image, NaN where the projector misses the screen or the point is behind the
// frustum's eye or at its horizon (beyond 10^6 image widths). No blend maps.
MpcdiRegion regionFromGeometry(const DisplayGeometry& geometry, const MpcdiFrustum& frustum,
                               int warpWidth, int warpHeight, const std::string& id);

}  // namespace sv::display
