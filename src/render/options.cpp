// The options' checks and names (synthvis/render.h).
#include <fmt/format.h>

#include "synthvis/render.h"

namespace sv {

Status validate(const RenderOptions& o) {
  if (o.width < 1 || o.width > kMaxRasterSize || o.height < 1 || o.height > kMaxRasterSize)
    return Error{"", "",
                 fmt::format("image size {}x{} is out of range (1…{} each)", o.width, o.height,
                             kMaxRasterSize)};
  if (o.threads < 0 || o.threads > kMaxThreads)
    return Error{"", "",
                 fmt::format("thread count {} is out of range (0…{})", o.threads, kMaxThreads)};
  if (o.camera < 0) return Error{"", "", "camera index must not be negative"};
  if (o.supersample != 1 && o.supersample != 2 && o.supersample != 4 && o.supersample != 8 &&
      o.supersample != 16)
    return Error{
        "", "", fmt::format("supersampling {} is not supported (1, 2, 4, 8 or 16)", o.supersample)};
  if (o.supersample > 1 &&
      (o.width * o.supersample > kMaxRasterSize || o.height * o.supersample > kMaxRasterSize))
    return Error{"", "",
                 fmt::format("supersampling {}x{} by {} exceeds the {}-pixel raster", o.width,
                             o.height, o.supersample, kMaxRasterSize)};
  const bool debug = o.debugView != RenderOptions::DebugView::none;
  if (o.supersample > 1 && debug)
    return Error{"", "", "a debug view shows one value per pixel; it cannot be supersampled"};
  if (!isSampleCount(o.samples))
    return Error{
        "", "",
        fmt::format("{} samples per pixel is not supported ({})", o.samples, sampleCountNames())};
  if (o.samples > 1 && o.supersample > 1)
    return Error{"", "", "anti-aliasing and supersampling are alternatives; choose one"};
  if (o.samples > 1 && debug)
    return Error{"", "", "a debug view shows one value per pixel; it cannot be anti-aliased"};
  if (o.filter != RenderOptions::Filter::box && debug)
    return Error{"", "", "a debug view cannot be filtered"};
  if (o.debugView == RenderOptions::DebugView::occupancy && o.hsr == RenderOptions::Hsr::zbuffer)
    return Error{"", "", "the occupancy view shows masking: use --hsr priority or hybrid"};
  if (o.marchSteps < 1 || o.marchSteps > 1000000)
    return Error{"", "", fmt::format("{} march steps is out of range (1…1000000)", o.marchSteps)};
  if (!(o.lodScale > 1e-6f && o.lodScale < 1e6f))
    return Error{"", "", fmt::format("LOD scale {} is out of range (1e-6…1e6)", o.lodScale)};
  if (o.gamma != 0 && !(o.gamma >= 0.5 && o.gamma <= 5))
    return Error{"", "", fmt::format("gamma {} is out of range (0.5…5, or 0 for sRGB)", o.gamma)};
  const RenderOptions::SegmentChannel& sc = o.segmentChannel;
  if (o.pipeline == RenderOptions::Pipeline::segments) {
    if (o.samples != 1 || o.supersample != 1)
      return Error{"", "",
                   "the segment pipeline samples pixel centres; its anti-aliasing is the "
                   "recipient–donor filter (--donor) and --filter tent3: drop --aa and "
                   "--supersample"};
    if (debug) return Error{"", "", "the debug views show the tile pipeline"};
  } else if (sc.donor || sc.interlaced || sc.wordsPerLine != 0) {
    return Error{"", "",
                 "the recipient–donor filter, interlaced fields and the segment rate belong to the "
                 "segment pipeline: add --pipeline segments"};
  }
  if (sc.wordsPerLine < 0 || sc.wordsPerLine > 1000000000)
    return Error{"", "",
                 fmt::format("{} segment words per line is out of range (0…1e9, 0 = unlimited)",
                             sc.wordsPerLine)};
  if (sc.criticalLines < 1 || sc.criticalLines > 1024)
    return Error{"", "",
                 fmt::format("{} critical lines is out of range (1…1024)", sc.criticalLines)};
  if (sc.fifoWords < 16 || sc.fifoWords > (1 << 24))
    return Error{"", "",
                 fmt::format("a FIFO of {} segment words is out of range (16…16777216)",
                             sc.fifoWords)};
  return {};
}

Result<RenderOptions::Pipeline> parsePipeline(const std::string& text) {
  if (text == "tiles") return RenderOptions::Pipeline::tiles;
  if (text == "segments") return RenderOptions::Pipeline::segments;
  return Error{"", "", fmt::format("unknown pipeline '{}' (tiles or segments)", text)};
}

const char* pipelineName(RenderOptions::Pipeline pipeline) {
  return pipeline == RenderOptions::Pipeline::segments ? "segments" : "tiles";
}

Result<RenderOptions::Hsr> parseHsr(const std::string& text) {
  if (text == "zbuffer") return RenderOptions::Hsr::zbuffer;
  if (text == "priority") return RenderOptions::Hsr::priority;
  if (text == "hybrid") return RenderOptions::Hsr::hybrid;
  return Error{
      "", "",
      fmt::format("unknown hidden-surface method '{}' (zbuffer, priority or hybrid)", text)};
}

const char* hsrName(RenderOptions::Hsr hsr) {
  switch (hsr) {
    case RenderOptions::Hsr::priority:
      return "priority";
    case RenderOptions::Hsr::hybrid:
      return "hybrid";
    default:
      return "zbuffer";
  }
}

Result<RenderOptions::TerrainFilter> parseTerrainFilter(const std::string& text) {
  if (text == "scene") return RenderOptions::TerrainFilter::scene;
  if (text == "bilinear") return RenderOptions::TerrainFilter::bilinear;
  if (text == "bicubic") return RenderOptions::TerrainFilter::bicubic;
  return Error{"", "",
               fmt::format("unknown terrain filter '{}' (scene, bilinear or bicubic)", text)};
}

Result<RenderOptions::Correction> parseCorrection(const std::string& text) {
  if (text == "subfrusta") return RenderOptions::Correction::subFrusta;
  if (text == "bilinear") return RenderOptions::Correction::bilinear;
  if (text == "bicubic") return RenderOptions::Correction::bicubic;
  return Error{"", "",
               fmt::format("correction '{}': expected subfrusta, bilinear or bicubic", text)};
}

const char* correctionName(RenderOptions::Correction correction) {
  switch (correction) {
    case RenderOptions::Correction::bilinear:
      return "bilinear";
    case RenderOptions::Correction::bicubic:
      return "bicubic";
    default:
      return "subfrusta";
  }
}

}  // namespace sv
