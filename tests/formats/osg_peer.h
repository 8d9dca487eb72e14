// OpenSceneGraph as the OpenFlight reader's peer (Debian's openscenegraph; its osgconv tool): our
// reading of a .flt against OSG's, which osgconv writes out as OBJ. Shared by the tests and by
// tools/openflight_sweep (scripts/openflight-peer).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "formats/formats_test_util.h"

namespace sv::formats::testing {

// OpenFlight's (x, y, z) of a synthvis world point: the reader maps z up to y up, y to −z.
inline std::array<double, 3> fltOf(Vec3 p) { return {p.x, -double(p.z), p.y}; }

// Every triangle corner of every instance (visible or not), in OpenFlight coordinates.
inline std::vector<std::array<double, 3>> corners(const Scene& s) {
  std::vector<std::array<double, 3>> out;
  for (const Instance& inst : s.instances) {
    std::vector<int> meshes{inst.mesh};
    if (inst.lod >= 0)
      for (const LodLevel& l : s.lodGroups[size_t(inst.lod)].levels) meshes.push_back(l.mesh);
    std::sort(meshes.begin(), meshes.end());
    meshes.erase(std::unique(meshes.begin(), meshes.end()), meshes.end());
    for (int m : meshes)
      for (uint32_t i : s.meshes[size_t(m)].indices)
        out.push_back(fltOf(inst.transform.transformPoint(s.meshes[size_t(m)].positions[i])));
  }
  return out;
}
inline size_t allTriangles(const Scene& s) { return corners(s).size() / 3; }

// The distinct points of `p`, rounded to 1e-3.
inline std::set<std::array<long long, 3>> distinct(const std::vector<std::array<double, 3>>& p) {
  std::set<std::array<long long, 3>> out;
  for (const auto& q : p)
    out.insert({std::llround(q[0] * 1e3), std::llround(q[1] * 1e3), std::llround(q[2] * 1e3)});
  return out;
}

inline bool haveOsgconv() { return std::system("command -v osgconv >/dev/null 2>&1") == 0; }

// osgconv `from` `to`; true on success.
// Run in the output's directory: OSG's OpenFlight exporter writes a texture attribute file
// (`<texture>.attr`) into the current directory for every texture it exports.
inline bool osgconv(const std::string& from, const std::string& to) {
  namespace fs = std::filesystem;
  const fs::path out = fs::absolute(to);
  const std::string cmd = "cd '" + out.parent_path().string() + "' && osgconv '" +
                          fs::absolute(from).string() + "' '" + out.string() + "' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

// The triangle corners OSG wrote into an OBJ file (its reading of a model), polygons fanned.
inline std::vector<std::array<double, 3>> objCorners(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::array<double, 3>> v, out;
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    if (key == "v") {
      std::array<double, 3> p{};
      s >> p[0] >> p[1] >> p[2];
      v.push_back(p);
    } else if (key == "f") {
      std::vector<size_t> f;
      for (std::string c; s >> c;) {
        const long i = std::stol(c.substr(0, c.find('/')));
        f.push_back(i > 0 ? size_t(i - 1) : v.size() + size_t(i));
      }
      for (size_t k = 2; k < f.size(); ++k)
        for (size_t j : {f[0], f[k - 1], f[k]}) out.push_back(v.at(j));
    }
  }
  return out;
}

// What compareWithOsg found: triangle counts, the largest difference of the bounds' six
// coordinates, the distinct vertices (to 1e-3) only one side has; or why it could not compare.
struct PeerComparison {
  std::string error;
  size_t ours = 0, theirs = 0;
  double boundsDifference = 0;
  size_t verticesOnlyOurs = 0, verticesOnlyTheirs = 0;
  bool same() const {
    return error.empty() && ours == theirs && boundsDifference <= 1e-3 &&
           verticesOnlyOurs + verticesOnlyTheirs == 0;
  }
};

// Loads `flt` with synthvis and has osgconv write its own reading of it to `obj`.
inline PeerComparison compareWithOsg(const std::string& flt, const std::string& obj) {
  PeerComparison c;
  Result<Scene> ours = loadScene(flt);
  if (!ours) return c.error = ours.error().str(), c;
  if (!osgconv(flt, obj)) return c.error = "osgconv could not read " + flt, c;
  const auto theirs = objCorners(obj);
  const auto mine = corners(ours.value());
  c.ours = mine.size() / 3;
  c.theirs = theirs.size() / 3;
  auto bounds = [](const std::vector<std::array<double, 3>>& p) {
    std::array<double, 6> b{1e300, 1e300, 1e300, -1e300, -1e300, -1e300};
    for (const auto& q : p)
      for (int k = 0; k < 3; ++k) b[k] = std::min(b[k], q[k]), b[k + 3] = std::max(b[k + 3], q[k]);
    return b;
  };
  if (!mine.empty() && !theirs.empty()) {
    const auto bm = bounds(mine), bt = bounds(theirs);
    for (int k = 0; k < 6; ++k)
      c.boundsDifference = std::max(c.boundsDifference, std::fabs(bm[k] - bt[k]));
  } else if (mine.size() != theirs.size()) {
    c.boundsDifference = 1e300;
  }
  const auto dm = distinct(mine), dt = distinct(theirs);
  for (const auto& p : dm) c.verticesOnlyOurs += dt.count(p) ? 0 : 1;
  for (const auto& p : dt) c.verticesOnlyTheirs += dm.count(p) ? 0 : 1;
  return c;
}

}  // namespace sv::formats::testing
