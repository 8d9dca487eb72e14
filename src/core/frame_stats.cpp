// FrameStats' one-line summary (include/synthvis/frame_stats.h).
#include "synthvis/frame_stats.h"

#include <fmt/format.h>

#include <algorithm>

namespace sv {

// " | LOD 0:n 1:m …, dissolving d, beyond b" when some instance has levels of detail.
std::string FrameStats::lodSummary() const {
  int last = kLodLevels - 1;
  while (last >= 0 && !lodDrawn[last]) --last;
  if (last < 0 && !lodBeyond) return {};
  std::string s = " | LOD";
  for (int i = 0; i <= last; ++i) s += fmt::format(" {}:{}", i, lodDrawn[i]);
  s += fmt::format(", dissolving {}, beyond {}", lodDissolving, lodBeyond);
  if (mergedCells) s += fmt::format(", merged {} in {} cells", mergedInstances, mergedCells);
  return s;
}

FrameStats& FrameStats::operator+=(const FrameStats& o) {
  trianglesIn += o.trianglesIn;
  culledFacing += o.culledFacing, culledOutside += o.culledOutside;
  culledDegenerate += o.culledDegenerate, culledInvalid += o.culledInvalid;
  culledOccluded += o.culledOccluded, drawn += o.drawn, culledInstances += o.culledInstances;
  for (int i = 0; i < kLodLevels; ++i) lodDrawn[i] += o.lodDrawn[i];
  lodDissolving += o.lodDissolving, lodBeyond += o.lodBeyond;
  mergedCells += o.mergedCells, mergedInstances += o.mergedInstances;
  for (int i = 0; i < 6; ++i) windows[i] += o.windows[i];
  fullWindows += o.fullWindows, partialBlocks += o.partialBlocks, fragments += o.fragments;
  hiddenFragments += o.hiddenFragments, hybridWoken += o.hybridWoken;
  shadedByList += o.shadedByList, shadedByScan += o.shadedByScan;
  occludedWindows += o.occludedWindows, occludedTriangles += o.occludedTriangles;
  occludedObjects += o.occludedObjects;
  freeForms += o.freeForms, freeFormCells += o.freeFormCells;
  freeFormMaskedCells += o.freeFormMaskedCells, freeFormBounds += o.freeFormBounds;
  freeFormRays += o.freeFormRays, freeFormHits += o.freeFormHits;
  terrains += o.terrains, terrainWindows += o.terrainWindows, terrainSteps += o.terrainSteps;
  terrainSampleRays += o.terrainSampleRays, terrainPacketRays += o.terrainPacketRays;
  terrainRays += o.terrainRays;
  terrainHits += o.terrainHits, terrainMs += o.terrainMs;
  terrainBytes = std::max(terrainBytes, o.terrainBytes);  // the scene's, in every view alike
  terrainLoadMs = std::max(terrainLoadMs, o.terrainLoadMs);
  lightPoints += o.lightPoints, lightsDrawn += o.lightsDrawn, lightsMs += o.lightsMs;
  lines += o.lines, linesDrawn += o.linesDrawn, linesMs += o.linesMs;
  segments += o.segments, segmentRuns += o.segmentRuns, repeatedLines += o.repeatedLines;
  shareBytes += o.shareBytes, shareMs += o.shareMs;
  volumes += o.volumes, volumeRays += o.volumeRays, volumeSamples += o.volumeSamples;
  volumeSkipped += o.volumeSkipped, volumeTerminated += o.volumeTerminated;
  volumeMs += o.volumeMs, volumeInterpolated += o.volumeInterpolated;
  volumeClosedForm += o.volumeClosedForm;
  vertexMs += o.vertexMs, setupMs += o.setupMs, rasterMs += o.rasterMs, totalMs += o.totalMs;
  return *this;
}

std::string FrameStats::summary() const {
  // A segment-pipeline frame (RenderOptions::Pipeline::segments) has no windows, fragments or
  // tiles to report: its triangles, its segments and runs, and its times.
  if (segments || repeatedLines)
    return fmt::format(
               "triangles in {} / culled {} (facing {}, outside {}, degenerate {}, invalid "
               "{}) / drawn {} | segments {}: runs {}, lines repeated {} | {:.2f} ms "
               "(vertex {:.2f}, setup {:.2f}, lines {:.2f})",
               trianglesIn, culled(), culledFacing, culledOutside, culledDegenerate, culledInvalid,
               drawn, segments, segmentRuns, repeatedLines, totalMs, vertexMs, setupMs, rasterMs) +
           lodSummary();
  return fmt::format(
             "triangles in {} / culled {} (facing {}, outside {}{}, degenerate {}, invalid {}{}) / "
             "drawn {} "
             "| windows 64:{} 32:{} 16:{} 8:{} 4:{} px-tests:{} full:{} occluded:{} (triangles {}, "
             "objects {}{}) | fragments {} (hidden {}{}) | {:.2f} ms (vertex {:.2f}, setup {:.2f}, "
             "tiles "
             "{:.2f} incl. resolve)",
             trianglesIn, culled(), culledFacing, culledOutside,
             culledInstances ? fmt::format(" of which {} instances whole", culledInstances)
                             : std::string(),
             culledDegenerate, culledInvalid,
             culledOccluded ? fmt::format(", occluded {}", culledOccluded) : std::string(), drawn,
             windows[0], windows[1], windows[2], windows[3], windows[4], windows[5], fullWindows,
             occludedWindows, occludedTriangles, occludedObjects,
             hybridWoken ? fmt::format(", hybrid woke in {} tiles", hybridWoken) : std::string(),
             fragments, hiddenFragments,
             shadedByList + shadedByScan ? fmt::format("; shading passes by list {}, by scan {}",
                                                       shadedByList, shadedByScan)
                                         : std::string(),
             totalMs, vertexMs, setupMs, rasterMs) +
         lodSummary() +
         (freeForms ? fmt::format(" | free forms {}: cells {} (masked {}), bounds {}, rays {}, "
                                  "hits {}",
                                  freeForms, freeFormCells, freeFormMaskedCells, freeFormBounds,
                                  freeFormRays, freeFormHits)
                    : std::string()) +
         (terrains
              ? fmt::format(" | terrain {}: windows {}, steps {}, rays {} in packets and {} "
                            "alone, hits {}, {:.2f} ms, {:.1f} MB, loaded in {:.1f} ms",
                            terrains, terrainWindows, terrainSteps, terrainPacketRays, terrainRays,
                            terrainHits, terrainMs, terrainBytes / 1e6, terrainLoadMs)
              : std::string()) +
         (lightPoints
              ? fmt::format(" | lights {}: drawn {}, {:.2f} ms", lightPoints, lightsDrawn, lightsMs)
              : std::string()) +
         (lines ? fmt::format(" | lines {}: drawn {}, {:.2f} ms", lines, linesDrawn, linesMs)
                : std::string()) +
         (shareBytes ? fmt::format(" | shared: {} bytes exchanged, {:.2f} ms", shareBytes, shareMs)
                     : std::string()) +
         (volumes
              ? fmt::format(" | volumes {}: rays {}, samples {}, skipped {}, in closed form {}, "
                            "terminated {}, pixels interpolated {}, {:.2f} ms",
                            volumes, volumeRays, volumeSamples, volumeSkipped, volumeClosedForm,
                            volumeTerminated, volumeInterpolated, volumeMs)
              : std::string());
}

}  // namespace sv
