// Volume files (SPEC §11 voxel arrays; docs/scene-format.md "Volumes"): NIfTI-1 (.nii, .nii.gz),
// NRRD (.nrrd with its data attached, .nhdr with a detached data file; raw or gzip encoding) and
// OpenVDB (.vdb, through the OpenVDB library in a child process: formats/openvdb_reader.h).
// Every size in a header is checked against the limits before anything is allocated, a truncated
// file is named as such, and 8- and 16-bit data keep their exact values.
#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>

#include "formats/openvdb_reader.h"
#include "formats/reader.h"
#include "synthvis/scene.h"

namespace sv::formats {
namespace {

struct VolumeProblem {
  std::string message;
};
[[noreturn]] void fail(std::string message) { throw VolumeProblem{std::move(message)}; }

// A gzip stream (or plain bytes) read from the start, a piece at a time: the caller learns the
// sizes from the header before asking for the data.
class Source {
 public:
  Source(const std::string& bytes, size_t start, bool gzip)
      : bytes_(bytes), at_(start), gzip_(gzip) {
    if (!gzip_) return;
    z_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + start));
    z_.avail_in = uInt(std::min<size_t>(bytes.size() - start, 1u << 30));
    if (inflateInit2(&z_, 16 + MAX_WBITS) != Z_OK) fail("cannot start gzip decompression");
    open_ = true;
  }
  ~Source() {
    if (open_) inflateEnd(&z_);
  }
  Source(const Source&) = delete;
  Source& operator=(const Source&) = delete;

  // Fills out[0, n), or fails naming what was being read.
  void read(void* out, size_t n, const char* what) {
    if (!gzip_) {
      if (bytes_.size() - at_ < n)
        fail(fmt::format("truncated: {} needs {} bytes, {} remain", what, n, bytes_.size() - at_));
      std::memcpy(out, bytes_.data() + at_, n);
      at_ += n;
      return;
    }
    z_.next_out = static_cast<Bytef*>(out);
    while (n > 0) {
      const size_t piece = std::min<size_t>(n, 1u << 30);
      z_.avail_out = uInt(piece);
      const int r = inflate(&z_, Z_NO_FLUSH);
      const size_t got = piece - z_.avail_out;
      n -= got;
      if (n == 0) break;
      if (r == Z_STREAM_END) fail(fmt::format("truncated: the gzip data ends inside {}", what));
      if (r != Z_OK) fail(fmt::format("gzip data is damaged ({})", z_.msg ? z_.msg : "zlib error"));
      if (got == 0 && z_.avail_in == 0)
        fail(fmt::format("truncated: the gzip data ends inside {}", what));
    }
  }
  // The most bytes the rest of the input can hold: what remains, or for gzip what remains times
  // deflate's largest ratio (1032:1) — so that a short file claiming a huge grid is refused before
  // the grid is allocated.
  uint64_t most() const {
    return gzip_ ? uint64_t(z_.avail_in) * 1032 + 4096 : uint64_t(bytes_.size() - at_);
  }
  // Skips n bytes.
  void skip(size_t n, const char* what) {
    char buffer[4096];
    while (n > 0) {
      const size_t k = std::min(n, sizeof buffer);
      read(buffer, k, what);
      n -= k;
    }
  }

 private:
  const std::string& bytes_;
  size_t at_;
  bool gzip_;
  bool open_ = false;
  z_stream z_{};
};

enum class Type { u8, i8, u16, i16, u32, i32, f32, f64 };
size_t sizeOf(Type t) {
  switch (t) {
    case Type::u8:
    case Type::i8:
      return 1;
    case Type::u16:
    case Type::i16:
      return 2;
    case Type::u32:
    case Type::i32:
    case Type::f32:
      return 4;
    case Type::f64:
      return 8;
  }
  return 1;
}

// The grid of nx × ny × nz samples, checked against the limits (before any allocation).
VolumeGrid sizedGrid(int64_t nx, int64_t ny, int64_t nz, size_t maxSamples) {
  for (int64_t n : {nx, ny, nz})
    if (n < 2 || n > kMaxVolumeSide)
      fail(fmt::format("{} × {} × {} samples: each side must be 2 … {}", nx, ny, nz,
                       kMaxVolumeSide));
  if (uint64_t(nx) * uint64_t(ny) * uint64_t(nz) > maxSamples)
    fail(fmt::format("{} × {} × {} samples: more than {}", nx, ny, nz, maxSamples));
  VolumeGrid g;
  g.nx = int(nx), g.ny = int(ny), g.nz = int(nz);
  return g;
}

// The samples of `g` read from `in` as `type` in the given byte order, turned into codes: 8- and
// 16-bit integers exactly (signed ones offset), wider ones and floats quantized over their range.
void readSamples(VolumeGrid& g, Source& in, Type type, bool bigEndian) {
  const size_t n = size_t(g.nx) * size_t(g.ny) * size_t(g.nz), size = sizeOf(type);
  if (in.most() < uint64_t(n) * size)
    fail(fmt::format("truncated: {} samples of {} bytes need {} bytes, the file holds at most {}",
                     n, size, uint64_t(n) * size, in.most()));
  g.codes.resize(n);
  std::vector<double> wide;
  if (size > 2 || type == Type::f32) wide.resize(n);
  constexpr size_t kChunk = 1 << 16;
  std::vector<unsigned char> buffer(kChunk * size);
  for (size_t first = 0; first < n; first += kChunk) {
    const size_t count = std::min(kChunk, n - first);
    in.read(buffer.data(), count * size, "the samples");
    for (size_t i = 0; i < count; ++i) {
      unsigned char b[8];
      std::memcpy(b, buffer.data() + i * size, size);
      if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(b, b + size);
      auto as = [&]<class T>(T) {
        T v;
        std::memcpy(&v, b, sizeof v);
        return v;
      };
      const size_t at = first + i;
      switch (type) {
        case Type::u8:
          g.codes[at] = b[0];
          break;
        case Type::i8:
          g.codes[at] = uint16_t(int(as(int8_t{})) + 128);
          break;
        case Type::u16:
          g.codes[at] = as(uint16_t{});
          break;
        case Type::i16:
          g.codes[at] = uint16_t(int(as(int16_t{})) + 32768);
          break;
        case Type::u32:
          wide[at] = as(uint32_t{});
          break;
        case Type::i32:
          wide[at] = as(int32_t{});
          break;
        case Type::f32:
          wide[at] = as(float{});
          break;
        case Type::f64:
          wide[at] = as(double{});
          break;
      }
    }
  }
  g.offset = type == Type::i8 ? -128.0f : type == Type::i16 ? -32768.0f : 0.0f;
  g.scale = 1;
  if (wide.empty()) return;
  double lo = INFINITY, hi = -INFINITY;
  for (double v : wide) {
    if (!std::isfinite(v)) fail("a sample is not finite");
    lo = std::min(lo, v), hi = std::max(hi, v);
  }
  const double step = hi > lo ? (hi - lo) / 65535 : 1;
  if (!std::isfinite(step) || !std::isfinite(float(lo)) || !(float(step) > 0))
    fail("the samples' range is not representable");
  for (size_t i = 0; i < n; ++i) g.codes[i] = uint16_t(std::lrint((wide[i] - lo) / step));
  g.offset = float(lo);
  g.scale = float(step);
}

// value' = slope·value + intercept, kept as codes with a positive scale.
void rescale(VolumeGrid& g, double slope, double intercept) {
  if (!std::isfinite(slope) || !std::isfinite(intercept) || slope == 0) return;
  if (slope < 0) {
    const uint16_t top = *std::max_element(g.codes.begin(), g.codes.end());
    for (uint16_t& c : g.codes) c = uint16_t(top - c);
    g.offset = float(slope * (double(g.offset) + double(g.scale) * top) + intercept);
    g.scale = float(-slope * g.scale);
  } else {
    g.offset = float(slope * g.offset + intercept);
    g.scale = float(slope * g.scale);
  }
  if (!std::isfinite(g.offset) || !(g.scale > 0) || !std::isfinite(g.scale))
    fail("its value scaling (scl_slope, scl_inter) is not representable");
}

float spacingOf(double v) {
  return std::isfinite(v) && std::fabs(v) > 1e-20 && std::fabs(v) < 1e20 ? float(std::fabs(v))
                                                                         : 1.0f;
}

bool gzipped(const std::string& bytes) {
  return bytes.size() >= 2 && uint8_t(bytes[0]) == 0x1f && uint8_t(bytes[1]) == 0x8b;
}

VolumeGrid nifti(const std::string& bytes, size_t maxSamples) {
  Source in(bytes, 0, gzipped(bytes));
  unsigned char h[348];
  in.read(h, sizeof h, "the NIfTI-1 header");
  int32_t sizeofHdr;
  std::memcpy(&sizeofHdr, h, 4);
  bool swap = false;
  if (sizeofHdr != 348) {
    if (int32_t(__builtin_bswap32(uint32_t(sizeofHdr))) != 348)
      fail(fmt::format("not a NIfTI-1 file (sizeof_hdr is {}, not 348)", sizeofHdr));
    swap = true;
  }
  auto field = [&]<class T>(T, size_t at) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, h + at, sizeof b);
    if (swap) std::reverse(b, b + sizeof b);
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  };
  if (std::memcmp(h + 344, "n+1\0", 4) != 0) {
    if (std::memcmp(h + 344, "ni1\0", 4) == 0)
      fail("a NIfTI-1 header without its data (.hdr/.img pair): only single files (.nii) are read");
    fail("not a NIfTI-1 file (no 'n+1' magic); NIfTI-2 is not read");
  }
  int64_t dim[8];
  for (int i = 0; i < 8; ++i) dim[i] = field(int16_t{}, 40 + 2 * size_t(i));
  if (dim[0] < 3 || dim[0] > 7)
    fail(fmt::format("dim[0] is {}: a volume has 3 dimensions", dim[0]));
  for (int i = 4; i <= dim[0]; ++i)
    if (dim[i] > 1)
      fail(
          fmt::format("a series of {} volumes (dim[{}]): only single volumes are read", dim[i], i));
  VolumeGrid g = sizedGrid(dim[1], dim[2], dim[3], maxSamples);
  const int16_t datatype = field(int16_t{}, 70);
  Type type;
  switch (datatype) {
    case 2:
      type = Type::u8;
      break;
    case 256:
      type = Type::i8;
      break;
    case 4:
      type = Type::i16;
      break;
    case 512:
      type = Type::u16;
      break;
    case 8:
      type = Type::i32;
      break;
    case 768:
      type = Type::u32;
      break;
    case 16:
      type = Type::f32;
      break;
    case 64:
      type = Type::f64;
      break;
    default:
      fail(fmt::format(
          "NIfTI datatype {} is not read (unsigned/signed 8, 16, 32-bit, float, double)",
          datatype));
  }
  g.spacing = {spacingOf(field(float{}, 80)), spacingOf(field(float{}, 84)),
               spacingOf(field(float{}, 88))};
  const float voxOffset = field(float{}, 108);
  if (!(voxOffset >= 348) || voxOffset > 1e6f)
    fail(fmt::format("vox_offset {} is not within 348 … 10^6", voxOffset));
  in.skip(size_t(voxOffset) - 348, "the header's extensions");
  readSamples(g, in, type, (std::endian::native == std::endian::little) == swap);
  rescale(g, field(float{}, 112), field(float{}, 116));
  return g;
}

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

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
