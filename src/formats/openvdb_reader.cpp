// Based on: OpenVDB's io::File and tree API (openvdb/io/File.h, Grid.h, tree/ValueAccessor.h),
// run in a forked child (formats/openvdb_reader.h says why); the pattern of formats/assimp_reader.cpp.
//
// The exchange through the pipe, child to parent: 'E' and a one-line reason; or 'G', a Header, the
// grid's name, then nx·ny·nz samples (x fastest) — written in pieces as they are densified, so
// that the child never holds the dense grid, and is held back by the full pipe (64 KiB) until the
// parent has accepted the grid's size; a size refused stops the child before the parent reads or
// allocates a sample.
#include "formats/openvdb_reader.h"

#include <fmt/format.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <vector>

#include "formats/child_process.h"
#include "formats/reader.h"

namespace sv::formats::detail {
namespace {

using Clock = std::chrono::steady_clock;

// What follows 'G'. Written and read by the same binary, so its layout is shared as it is.
struct Header {
  VdbGrid::Type type;
  int64_t n[3];
  double spacing[3];
  uint32_t nameSize;
};
constexpr uint32_t kMaxNameBytes = 256;

// The child's limits. Its work grows with the samples it may densify (the tree that holds them,
// the accessor's lookups) and the bytes it reads (decompressed, they may be many times the file);
// the fixed parts cover OpenVDB's start and a small file. A malformed file makes OpenVDB allocate
// (and fill) whatever sizes it claims, up to the limit: for a small budget the limit stays small
// (1/4 GiB for 2^20 samples and a short file) so that such an input costs the fuzzer little, and
// below libFuzzer's malloc limit (scripts/fuzz: -rss_limit_mb=2048, which sets it), so that the
// allocation fails in the child rather than being reported as the fuzzer's out-of-memory.
int timeLimitSeconds(size_t bytes, size_t maxSamples) {
  return int(5 + (maxSamples >> 23) + (bytes >> 24));
}
uint64_t memoryBudget(size_t bytes, size_t maxSamples) {
  return (uint64_t(1) << 28) + 8 * uint64_t(maxSamples) + 4 * uint64_t(bytes);
}

// ---- The child ----

struct ChildProblem {
  std::string message;
};
[[noreturn]] void refuse(std::string message) { throw ChildProblem{std::move(message)}; }

// Text from the file (a grid's name, what OpenVDB quotes in its messages) as part of a one-line
// message: at most `most` bytes, control characters as '?'.
std::string printable(std::string_view text, size_t most) {
  std::string out(text.substr(0, most));
  for (char& c : out)
    if (uint8_t(c) < 0x20 || c == 0x7f) c = '?';
  return out;
}

void writeAll(int fd, const void* data, size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t k = write(fd, p, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) _exit(3);  // the parent stopped reading: it needs nothing more
    p += k, n -= size_t(k);
  }
}

bool scalar(const openvdb::GridBase& g) {
  return g.isType<openvdb::FloatGrid>() || g.isType<openvdb::DoubleGrid>() ||
         g.isType<openvdb::Int32Grid>();
}

// Sends `grid`: its header, then its samples over the active voxels' bounding box, read through
// an accessor (voxels outside the active ones give the background, or an inactive tile's or
// voxel's value, as OpenVDB's tools::copyToDense does). Serial on purpose: the parent's TBB
// workers, if it has any, did not survive the fork.
template <class GridT>
void sendGrid(const GridT& grid, const std::string& name, VdbGrid::Type type, int out) {
  const openvdb::math::Transform& transform = grid.transform();
  if (!transform.isLinear())
    refuse(fmt::format("grid '{}' has a non-linear transform ({}): only linear ones are read", name,
                       transform.mapType()));
  openvdb::CoordBBox box;
  if (!grid.tree().evalActiveVoxelBoundingBox(box))
    refuse(fmt::format("grid '{}' has no active voxels", name));
  Header h{};
  h.type = type;
  int64_t lo[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = box.min()[a];
    h.n[a] = int64_t(box.max()[a]) - lo[a] + 1;
    // A sheet one voxel thick: one more voxel beside it, since a grid has at least 2 samples a
    // side (synthvis/volumes.h).
    if (h.n[a] == 1) {
      h.n[a] = 2;
      if (box.max()[a] == INT32_MAX) --lo[a];
    }
    h.spacing[a] = transform.voxelSize()[a];
  }
  h.nameSize = uint32_t(std::min<size_t>(name.size(), kMaxNameBytes));
  writeAll(out, "G", 1);
  writeAll(out, &h, sizeof h);
  writeAll(out, name.data(), h.nameSize);
  // The samples, x fastest, a piece at a time; the pipe holds the child back until the parent has
  // accepted the size and reads them.
  using Value = typename GridT::ValueType;
  constexpr size_t kPiece = 1 << 14;
  std::vector<Value> piece;
  piece.reserve(kPiece);
  typename GridT::ConstAccessor voxels = grid.getConstAccessor();
  for (int64_t k = 0; k < h.n[2]; ++k)
    for (int64_t j = 0; j < h.n[1]; ++j)
      for (int64_t i = 0; i < h.n[0]; ++i) {
        piece.push_back(
            voxels.getValue(openvdb::Coord(int(lo[0] + i), int(lo[1] + j), int(lo[2] + k))));
        if (piece.size() == kPiece) {
          writeAll(out, piece.data(), piece.size() * sizeof(Value));
          piece.clear();
        }
      }
  writeAll(out, piece.data(), piece.size() * sizeof(Value));
}

// Opens the file (the bytes, handed to OpenVDB as an in-memory file: io::File reads a chosen grid
// alone, where io::Stream would read them all), chooses the grid and sends it.
void readAndSend(const std::string& bytes, int out) {
  openvdb::initialize();
  const int fd = memfd_create("synthvis-vdb", 0);
  if (fd < 0) refuse("cannot hand the file to OpenVDB (memfd_create failed)");
  writeAll(fd, bytes.data(), bytes.size());
  openvdb::io::File file(fmt::format("/proc/self/fd/{}", fd));
  file.open(false);  // no delayed loading: it would map the file and read voxels lazily
  // The grid named "density" (clouds' usual name), else the first scalar grid by name.
  std::string chosen, others;
  for (auto it = file.beginName(); it != file.endName(); ++it) {
    const openvdb::GridBase::Ptr meta = file.readGridMetadata(*it);
    if (!scalar(*meta)) {
      if (others.size() < 200)
        others += fmt::format("{}'{}' ({})", others.empty() ? "" : ", ",
                              printable(meta->getName(), 64), printable(meta->valueType(), 32));
      continue;
    }
    if (chosen.empty() || (meta->getName() == "density" && chosen != "density")) chosen = *it;
  }
  if (chosen.empty())
    // OpenVDB does not check its reads of the header: a truncated or damaged one often reads as
    // a file of no grids.
    refuse(others.empty()
               ? std::string("OpenVDB finds no grid in it (an empty or damaged file)")
               : fmt::format("no scalar grid (float, double or int32): it holds {}", others));
  const openvdb::GridBase::Ptr grid = file.readGrid(chosen);
  const std::string name = printable(chosen, kMaxNameBytes);
  if (const auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(grid))
    sendGrid(*f, name, VdbGrid::Type::f32, out);
  else if (const auto d = openvdb::gridPtrCast<openvdb::DoubleGrid>(grid))
    sendGrid(*d, name, VdbGrid::Type::f64, out);
  else if (const auto i = openvdb::gridPtrCast<openvdb::Int32Grid>(grid))
    sendGrid(*i, name, VdbGrid::Type::i32, out);
  else
    refuse(fmt::format("grid '{}' changed its type between its metadata and its data", name));
}

[[noreturn]] void child(const std::string& bytes, size_t maxSamples, int pipeEnd) {
  const uint64_t budget = memoryBudget(bytes.size(), maxSamples);
  const int out = isolateChild(pipeEnd, budget);
  std::string why;
  try {
    readAndSend(bytes, out);
    _exit(0);
  } catch (const ChildProblem& p) {
    why = p.message;
  } catch (const std::bad_alloc&) {
    why = fmt::format("OpenVDB ran out of memory (the reader's limit is {} MiB)", budget >> 20);
  } catch (const std::exception& e) {
    // OpenVDB's messages name the file as OpenVDB saw it, and quote what it read, which may be
    // a long run of anything (copied whole, it could exhaust the memory again): the first 200
    // bytes, runs of blanks as one.
    why = "OpenVDB: " + printable(oneLine(std::string(e.what(), strnlen(e.what(), 200))), 200);
    for (size_t at; (at = why.find("/proc/self/fd/")) != std::string::npos;)
      why.replace(at, why.find_first_not_of("0123456789", at + 14) - at, "the file");
    why.erase(
        std::unique(why.begin(), why.end(), [](char a, char b) { return a == ' ' && b == ' '; }),
        why.end());
  } catch (...) {
    why = "OpenVDB failed";
  }
  writeAll(out, "E", 1);
  writeAll(out, why.data(), std::min<size_t>(why.size(), 4000));
  _exit(1);
}

// ---- The parent ----

// The running child: reads its pipe against the deadline; killed if still running when this
// ends, and always reaped.
class Child {
 public:
  Child(pid_t pid, int fd, int seconds)
      : pid_(pid),
        fd_(fd),
        seconds_(seconds),
        deadline_(Clock::now() + std::chrono::seconds(seconds)) {}
  ~Child() {
    close(fd_);
    if (!reaped_) {
      kill(pid_, SIGKILL);
      reap();
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // Fills out[0, n) or stops short at the end of the child's output or at the deadline.
  size_t read(void* out, size_t n) {
    char* p = static_cast<char*>(out);
    size_t got = 0;
    while (got < n && !timedOut_) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - Clock::now());
      if (left.count() <= 0) {
        timedOut_ = true;
        break;
      }
      pollfd ready{fd_, POLLIN, 0};
      if (poll(&ready, 1, int(std::min<int64_t>(left.count(), INT_MAX))) <= 0) continue;
      const ssize_t k = ::read(fd_, p + got, std::min<size_t>(n - got, size_t(1) << 30));
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) break;
      got += size_t(k);
    }
    return got;
  }

  // How the child ended: "" for a clean exit, otherwise why it failed (`reason`, its own report,
  // when it gave one).
  std::string end(const std::string& reason) {
    if (timedOut_) kill(pid_, SIGKILL);
    const int status = reap();
    if (timedOut_) return fmt::format("the OpenVDB reader did not finish in {} s", seconds_);
    if (WIFSIGNALED(status))
      return fmt::format("the OpenVDB reader crashed reading it (signal {}: {})", WTERMSIG(status),
                         strsignal(WTERMSIG(status)));
    if (!reason.empty()) return reason;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
      return "the OpenVDB reader failed without a reason (out of memory?)";
    return "";
  }

 private:
  int reap() {
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    reaped_ = true;
    return status;
  }

  pid_t pid_;
  int fd_;
  int seconds_;
  Clock::time_point deadline_;
  bool timedOut_ = false;
  bool reaped_ = false;
};

size_t sampleBytes(VdbGrid::Type t) { return t == VdbGrid::Type::f64 ? 8 : 4; }

}  // namespace

bool isOpenVdb(const std::string& bytes) {
  return bytes.size() >= 8 && std::memcmp(bytes.data(), "\x20\x42\x44\x56\0\0\0\0", 8) == 0;
}

std::string readOpenVdb(const std::string& bytes, size_t maxSamples,
                        const std::function<std::string(const VdbGrid&)>& accept, VdbGrid& grid,
                        std::string& samples) {
  int fds[2];
  if (pipe(fds) != 0) return "cannot start the OpenVDB reader (pipe)";
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return "cannot start the OpenVDB reader (fork)";
  }
  if (pid == 0) {
    close(fds[0]);
    child(bytes, maxSamples, fds[1]);
  }
  close(fds[1]);
  Child reader(pid, fds[0], timeLimitSeconds(bytes.size(), maxSamples));
  // A short read below means the child's output ended (it exited) or its time ran out: `stopped`
  // says which, and how.
  auto stopped = [&reader](const char* early) {
    const std::string why = reader.end("");
    return why.empty() ? std::string(early) : why;
  };
  char tag = 0;
  if (reader.read(&tag, 1) != 1) return stopped("the OpenVDB reader sent nothing");
  if (tag == 'E') {
    std::string why(4000, '\0');
    why.resize(reader.read(why.data(), why.size()));
    return reader.end(why.empty() ? "the OpenVDB reader failed" : why);
  }
  Header h{};
  if (tag != 'G') return "the OpenVDB reader sent what it should not";  // ~Child stops it
  if (reader.read(&h, sizeof h) != sizeof h) return stopped("the OpenVDB reader stopped early");
  if (h.nameSize > kMaxNameBytes || uint8_t(h.type) > uint8_t(VdbGrid::Type::i32))
    return "the OpenVDB reader sent what it should not";
  grid.name.assign(h.nameSize, '\0');
  if (reader.read(grid.name.data(), h.nameSize) != h.nameSize)
    return stopped("the OpenVDB reader stopped early");
  grid.type = h.type;
  grid.nx = h.n[0], grid.ny = h.n[1], grid.nz = h.n[2];
  std::copy(h.spacing, h.spacing + 3, grid.spacing);
  // The size is the caller's to accept before anything of that size exists (~Child stops the
  // child otherwise).
  if (std::string why = accept(grid); !why.empty()) return why;
  samples.resize(size_t(grid.nx) * size_t(grid.ny) * size_t(grid.nz) * sampleBytes(grid.type));
  if (reader.read(samples.data(), samples.size()) != samples.size())
    return stopped("the OpenVDB reader stopped before sending every sample");
  return reader.end("");
}

}  // namespace sv::formats::detail
