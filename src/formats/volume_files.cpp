// Volume files (SPEC §11 voxel arrays; docs/scene-format.md "Volumes"): NIfTI-1 (.nii, .nii.gz),
// NRRD (.nrrd with its data attached, .nhdr with a detached data file; raw or gzip encoding) and
// OpenVDB (.vdb, through the OpenVDB library in a child process: formats/openvdb_reader.h).
// Every size in a header is checked against the limits before anything is allocated, a truncated
// file is named as such, and 8- and 16-bit data keep their exact values. This file tells the
// formats apart; each has a file of its own (nifti_reader.cpp, nrrd_reader.cpp, openvdb_reader.cpp).
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>

#include "formats/openvdb_reader.h"
#include "formats/reader.h"
#include "formats/volume_samples.h"
#include "synthvis/scene.h"

namespace sv::formats {
namespace {

using namespace volumes;  // NOLINT(google-build-using-namespace)

// An OpenVDB file: the child densifies its grid (SPEC §11: a sparse volume becomes the dense
// voxel array the volume pass casts), this side checks the size before any sample is read and
// builds the grid as a NIfTI file's samples of the same type. The grid's own index space is kept:
// sample (0, 0, 0) is the active voxels' least corner; its transform gives only the spacing.
VolumeGrid openVdb(const std::string& bytes, size_t maxSamples) {
  VolumeGrid g;
  detail::VdbGrid shape;
  std::string samples;
  const std::string problem = detail::readOpenVdb(
      bytes, maxSamples,
      [&g, maxSamples](const detail::VdbGrid& s) {
        try {
          g = sizedGrid(s.nx, s.ny, s.nz, maxSamples);
        } catch (const VolumeProblem& p) {
          return fmt::format("grid '{}': {}", s.name, p.message);
        }
        return std::string();
      },
      shape, samples);
  if (!problem.empty()) fail(problem);
  const Type type = shape.type == detail::VdbGrid::Type::f64   ? Type::f64
                    : shape.type == detail::VdbGrid::Type::i32 ? Type::i32
                                                               : Type::f32;
  Source in(samples, 0, false);
  readSamples(g, in, type, std::endian::native == std::endian::big);
  g.spacing = {spacingOf(shape.spacing[0]), spacingOf(shape.spacing[1]),
               spacingOf(shape.spacing[2])};
  return g;
}

}  // namespace

Result<VolumeGrid> parseVolume(const std::string& bytes, const std::string& path,
                               bool followReferences, size_t maxSamples) {
  const std::string ext = detail::lowerExtension(path);
  maxSamples = std::min(maxSamples, kMaxVolumeSamples);
  try {
    if (bytes.compare(0, 4, "NRRD") == 0) return nrrd(bytes, path, followReferences, maxSamples);
    if (ext == ".nrrd" || ext == ".nhdr") fail("not a NRRD file (no 'NRRD000x' magic)");
    if (detail::isOpenVdb(bytes)) return openVdb(bytes, maxSamples);
    if (ext == ".vdb") fail("not an OpenVDB file (no 'VDB ' magic)");
    return nifti(bytes, maxSamples);
  } catch (const VolumeProblem& p) {
    return Error{path, "", p.message};
  } catch (const std::bad_alloc&) {
    return Error{path, "", "out of memory"};
  }
}

Result<VolumeGrid> loadVolume(const std::string& path) {
  Result<std::string> bytes = detail::readFile(path);
  if (!bytes) return bytes.error();
  return parseVolume(bytes.value(), path, true);
}

}  // namespace sv::formats
