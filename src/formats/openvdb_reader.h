// OpenVDB files (.vdb, sparse volumes such as clouds; SPEC §11 voxel arrays) read by the OpenVDB
// library in a child process: its reader is not hardened against malformed files (it may throw,
// crash, loop or allocate without bound), so that must cost only the child, which has a time and
// a memory limit. The child densifies the chosen grid and pipes its samples to the parent, which
// builds the VolumeGrid (volume_files.cpp). OpenVDB's headers stay in openvdb_reader.cpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace sv::formats::detail {

// Whether `bytes` begin with OpenVDB's magic: 0x56444220 ("VDB " read as a little-endian int64).
bool isOpenVdb(const std::string& bytes);

// The grid the child chose, as it reports it before its samples.
struct VdbGrid {
  std::string name;
  enum class Type : uint8_t { f32, f64, i32 } type = Type::f32;  // FloatGrid, DoubleGrid, Int32Grid
  int64_t nx = 0, ny = 0, nz = 0;  // the active voxels' bounding box (a side of 1 widened to 2)
  double spacing[3] = {1, 1, 1};   // the linear transform's voxel size
};

// Reads the OpenVDB file `bytes` in a child process and densifies its grid named "density", or
// else its first scalar grid (float, double or int32) in name order. `accept` is called with the
// grid's size before any sample is read, and returns "" to go on or why the grid is refused (the
// child is then stopped). On success returns "" with `grid` and `samples`: nx·ny·nz values of its
// type in native byte order, x fastest, sample (0, 0, 0) the bounding box's least corner — each
// the grid's value there (its active values, and elsewhere its background or inactive values, as
// OpenVDB's own densifying gives them). Otherwise returns the reason, one line. `maxSamples`
// scales the child's time and memory limits.
std::string readOpenVdb(const std::string& bytes, size_t maxSamples,
                        const std::function<std::string(const VdbGrid&)>& accept, VdbGrid& grid,
                        std::string& samples);

}  // namespace sv::formats::detail
