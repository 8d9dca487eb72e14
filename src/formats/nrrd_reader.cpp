// NRRD volumes (.nrrd with its data attached, .nhdr with a detached data file; raw or gzip
// encoding; 3 dimensions; spacings or space directions' lengths; docs/scene-format.md "Volumes").
// Based on: the NRRD file format (teem, nrrd format 0001–0005).
#include <cmath>
#include <sstream>

#include "formats/volume_samples.h"

namespace sv::formats::volumes {
namespace {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

}  // namespace

VolumeGrid nrrd(const std::string& bytes, const std::string& path, bool followReferences,
                size_t maxSamples) {
  if (bytes.compare(0, 7, "NRRD000") != 0 || bytes.size() < 8)
    fail("not a NRRD file (no 'NRRD000x' magic)");
  // The header: lines up to the first empty one.
  size_t at = bytes.find('\n');
  std::map<std::string, std::string> fields;
  for (int lines = 0;; ++lines) {
    if (at == std::string::npos || lines > 4096)
      fail("truncated: the header has no end (an empty line)");
    const size_t next = bytes.find('\n', at + 1);
    const std::string line =
        trim(bytes.substr(at + 1, (next == std::string::npos ? bytes.size() : next) - at - 1));
    at = next;
    if (line.empty()) break;
    if (line[0] == '#' || line.find(":=") != std::string::npos) continue;
    const size_t colon = line.find(": ");
    if (colon == std::string::npos)
      fail(fmt::format("a header line without 'field: value': '{}'", line.substr(0, 60)));
    std::string key = line.substr(0, colon);
    std::transform(key.begin(), key.end(), key.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    fields[key] = trim(line.substr(colon + 2));
  }
  auto get = [&](const char* key) -> const std::string* {
    auto it = fields.find(key);
    return it == fields.end() ? nullptr : &it->second;
  };
  const std::string* dimension = get("dimension");
  if (!dimension || *dimension != "3")
    fail(fmt::format("dimension is {}: only 3-dimensional data is read",
                     dimension ? *dimension : "missing"));
  const std::string* sizes = get("sizes");
  if (!sizes) fail("no 'sizes' field");
  std::istringstream sizeText(*sizes);
  int64_t n[3] = {0, 0, 0};
  if (!(sizeText >> n[0] >> n[1] >> n[2]))
    fail(fmt::format("sizes '{}' are not three integers", *sizes));
  VolumeGrid g = sizedGrid(n[0], n[1], n[2], maxSamples);
  const std::string* typeName = get("type");
  if (!typeName) fail("no 'type' field");
  static const std::pair<const char*, Type> kTypes[] = {{"uchar", Type::u8},
                                                        {"unsigned char", Type::u8},
                                                        {"uint8", Type::u8},
                                                        {"uint8_t", Type::u8},
                                                        {"signed char", Type::i8},
                                                        {"int8", Type::i8},
                                                        {"int8_t", Type::i8},
                                                        {"short", Type::i16},
                                                        {"short int", Type::i16},
                                                        {"signed short", Type::i16},
                                                        {"signed short int", Type::i16},
                                                        {"int16", Type::i16},
                                                        {"int16_t", Type::i16},
                                                        {"ushort", Type::u16},
                                                        {"unsigned short", Type::u16},
                                                        {"unsigned short int", Type::u16},
                                                        {"uint16", Type::u16},
                                                        {"uint16_t", Type::u16},
                                                        {"int", Type::i32},
                                                        {"signed int", Type::i32},
                                                        {"int32", Type::i32},
                                                        {"int32_t", Type::i32},
                                                        {"uint", Type::u32},
                                                        {"unsigned int", Type::u32},
                                                        {"uint32", Type::u32},
                                                        {"uint32_t", Type::u32},
                                                        {"float", Type::f32},
                                                        {"double", Type::f64}};
  Type type = Type::u8;
  bool known = false;
  for (const auto& [name, t] : kTypes)
    if (*typeName == name) type = t, known = true;
  if (!known) fail(fmt::format("type '{}' is not read", *typeName));
  if (const std::string* spacings = get("spacings")) {
    std::istringstream s(*spacings);
    double sp[3];
    if (s >> sp[0] >> sp[1] >> sp[2])
      g.spacing = {spacingOf(sp[0]), spacingOf(sp[1]), spacingOf(sp[2])};
  } else if (const std::string* directions = get("space directions")) {
    // Three vectors "(a,b,c) (d,e,f) (g,h,i)": the spacings are their lengths.
    std::string d = *directions;
    for (char& c : d)
      if (c == '(' || c == ')' || c == ',') c = ' ';
    std::istringstream s(d);
    double v[9];
    bool ok = true;
    for (double& x : v) ok = ok && bool(s >> x);
    if (ok)
      g.spacing = {spacingOf(std::hypot(v[0], v[1], v[2])), spacingOf(std::hypot(v[3], v[4], v[5])),
                   spacingOf(std::hypot(v[6], v[7], v[8]))};
  }
  const std::string* encoding = get("encoding");
  if (!encoding) fail("no 'encoding' field");
  const bool gzip = *encoding == "gzip" || *encoding == "gz";
  if (!gzip && *encoding != "raw")
    fail(fmt::format("encoding '{}' is not read (raw or gzip)", *encoding));
  const std::string* endian = get("endian");
  const bool big = endian && *endian == "big";
  if (sizeOf(type) > 1 && !endian) fail("no 'endian' field for multi-byte samples");
  // The data: after the header, or in the file `data file` names (relative to this one).
  const std::string* dataFile = get("data file");
  if (!dataFile) dataFile = get("datafile");
  std::string detached;
  size_t start = at == std::string::npos ? bytes.size() : at + 1;
  if (dataFile) {
    if (dataFile->rfind("LIST", 0) == 0 || dataFile->find('%') != std::string::npos)
      fail("a data file list or pattern is not read: one data file only");
    if (!followReferences) fail(fmt::format("data file '{}' is not opened here", *dataFile));
    Result<std::string> data =
        detail::readFile(detail::resolvePath(detail::directoryOf(path), *dataFile));
    if (!data) fail(fmt::format("data file: {}", data.error().str()));
    detached = std::move(data.value());
    start = 0;
  }
  const std::string& data = dataFile ? detached : bytes;
  if (const std::string* skip = get("byte skip")) {
    const long long k = std::atoll(skip->c_str());
    const size_t need = size_t(g.nx) * size_t(g.ny) * size_t(g.nz) * sizeOf(type);
    if (k == -1 && !gzip) {
      if (data.size() < need) fail("truncated: fewer bytes than the samples need");
      start = data.size() - need;
    } else if (k >= 0 && uint64_t(k) <= data.size() - start) {
      start += size_t(k);
    } else {
      fail(fmt::format("byte skip {} is not within the data", *skip));
    }
  }
  Source in(data, start, gzip);
  readSamples(g, in, type, big);
  return g;
}

}  // namespace sv::formats::volumes
