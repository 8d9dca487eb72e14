#include "reference/vtk_volume.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "render/camera.h"
#include "synthvis/files.h"

#ifndef SV_VTK_SCRIPT_PATH
#define SV_VTK_SCRIPT_PATH ""
#endif

namespace sv::reference {
namespace {

namespace fs = std::filesystem;

// Replies slower than this mean the script is stuck (a 1024² frame of the head takes seconds).
constexpr int kReplySeconds = 300;

std::string envOr(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

// The last non-empty line of a file (the script's one-line error), or "".
std::string lastLine(const fs::path& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

// Why `scene` is not one the script can draw as synthvis does, or "".
std::string unsupported(const scene::Scene& s) {
  if (s.volumes.empty()) return "the scene has no volumes";
  if (std::string beside = besideVolumes(s); !beside.empty()) return "the scene also has " + beside;
  if (!s.channels.empty()) return "the scene has channels";
  if (s.fog.enabled) return "the scene has fog";
  return "";
}

}  // namespace

std::string besideVolumes(const scene::Scene& s) {
  if (s.triangleCount() > 0) return fmt::format("{} triangles", s.triangleCount());
  if (!s.freeForms.empty()) return "free forms";
  if (!s.terrains.empty()) return "terrain";
  if (!s.lightPoints.empty()) return "light points";
  if (!s.lines.empty()) return "lines";
  return "";
}

scene::Scene volumesAlone(const scene::Scene& s) {
  scene::Scene v;
  v.background = s.background;
  v.cameras = s.cameras;
  v.channels = s.channels;
  v.light = s.light;
  v.fog = s.fog;
  v.volumes = s.volumes;
  v.volumeSettings = s.volumeSettings;
  return v;
}

struct VtkVolumeRenderer::Impl {
  pid_t child = -1;
  int toChild = -1, fromChild = -1;
  std::string pending;  // bytes read past the last line
  fs::path dir;         // the job's files
  std::string description = "VTK vtkFixedPointVolumeRayCastMapper";
  int width = 0, height = 0;

  ~Impl() {
    if (toChild >= 0) {
      const char quit[] = "quit\n";
      [[maybe_unused]] ssize_t n = ::write(toChild, quit, sizeof quit - 1);
      ::close(toChild);
    }
    if (fromChild >= 0) ::close(fromChild);
    if (child > 0) {
      // A moment to quit; then it is killed (its Xvfb goes with xvfb-run's group).
      for (int i = 0; i < 50; ++i) {
        if (::waitpid(child, nullptr, WNOHANG) == child) {
          child = -1;
          break;
        }
        ::usleep(20000);
      }
      if (child > 0) {
        ::kill(-child, SIGKILL);
        ::waitpid(child, nullptr, 0);
      }
    }
    std::error_code ec;
    if (!dir.empty()) fs::remove_all(dir, ec);
  }

  Error failure(const std::string& what) const {
    const std::string said = lastLine(dir / "stderr.txt");
    return Error{"", "",
                 said.empty() ? fmt::format("vtk reference: {}", what)
                              : fmt::format("vtk reference: {} ({})", what, said)};
  }

  Status send(const std::string& line) {
    const std::string text = line + "\n";
    size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(toChild, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return failure("the script has ended");
      done += size_t(n);
    }
    return {};
  }

  Result<std::string> receive() {
    for (;;) {
      if (const size_t eol = pending.find('\n'); eol != std::string::npos) {
        std::string line = pending.substr(0, eol);
        pending.erase(0, eol + 1);
        return line;
      }
      pollfd p{fromChild, POLLIN, 0};
      const int ready = ::poll(&p, 1, kReplySeconds * 1000);
      if (ready < 0 && errno == EINTR) continue;
      if (ready == 0) return failure(fmt::format("no reply in {} s", kReplySeconds));
      char buffer[4096];
      const ssize_t n = ::read(fromChild, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return failure("the script has ended");
      pending.append(buffer, size_t(n));
      if (pending.size() > (1u << 20)) return failure("an over-long reply");
    }
  }
};

VtkVolumeRenderer::VtkVolumeRenderer() : impl_(std::make_unique<Impl>()) {}
VtkVolumeRenderer::~VtkVolumeRenderer() = default;
const std::string& VtkVolumeRenderer::description() const { return impl_->description; }

Result<std::unique_ptr<VtkVolumeRenderer>> VtkVolumeRenderer::create(
    const scene::Scene& scene, const RenderOptions& options) {
  if (const std::string why = unsupported(scene); !why.empty())
    return Error{"", "", fmt::format("the vtk reference draws volumes alone: {}", why)};
  const std::string script = envOr("SV_VTK_SCRIPT", SV_VTK_SCRIPT_PATH);
  const std::string python = envOr("SV_VTK_PYTHON", "/usr/bin/python3");
  if (script.empty() || !fs::exists(script))
    return Error{script, "", "vtk reference: the script is missing (set SV_VTK_SCRIPT)"};
  if (!fs::exists(python)) return Error{python, "", "vtk reference: no python3 there"};
  const bool display = std::getenv("DISPLAY") && *std::getenv("DISPLAY");
  if (!display && !fs::exists("/usr/bin/xvfb-run"))
    return Error{"", "", "vtk reference: no $DISPLAY and no xvfb-run (Debian package xvfb)"};
  Result<render::FrameCamera> cam = render::chooseCamera(scene, options);
  if (!cam.ok()) return cam.error();

  std::unique_ptr<VtkVolumeRenderer> r(new VtkVolumeRenderer());
  Impl& m = *r->impl_;
  m.width = options.width, m.height = options.height;
  std::string pattern = (fs::temp_directory_path() / "synthvis-vtk-XXXXXX").string();
  if (!::mkdtemp(pattern.data()))
    return Error{pattern, "", fmt::format("vtk reference: cannot make a folder: {}", std::strerror(errno))};
  m.dir = pattern;

  // The job: what the script needs, in the world synthvis draws (bench/vtk_volume.py says how).
  const scene::Camera& c = cam.value().camera;
  const Vec3 toward = normalize(scene.light.direction);
  nlohmann::json job = {
      {"width", options.width},
      {"height", options.height},
      {"threads", options.threads},
      {"background", {scene.background.x, scene.background.y, scene.background.z}},
      {"camera",
       {{"position", {c.position.x, c.position.y, c.position.z}},
        {"target", {c.target.x, c.target.y, c.target.z}},
        {"up", {c.up.x, c.up.y, c.up.z}},
        {"yfov", c.yfovDegrees},
        {"near", c.znear},
        {"far", c.zfar}}},
      {"light",
       {{"on", scene.light.enabled},
        {"direction", {toward.x, toward.y, toward.z}},
        {"color", {scene.light.color.x, scene.light.color.y, scene.light.color.z}},
        {"ambient", scene.light.ambient}}},
      {"volumes", nlohmann::json::array()}};
  for (size_t i = 0; i < scene.volumes.size(); ++i) {
    const scene::VolumeObject& v = scene.volumes[i];
    const scene::VolumeGrid& g = *v.grid;
    const fs::path raw = m.dir / fmt::format("volume-{}.raw", i);
    // The codes as they are in memory: little-endian on every machine synthvis builds for.
    if (Status s = core::writeFile(
            raw.string(), {core::bytesOf(g.codes.data(), g.codes.size() * sizeof(uint16_t))});
        !s)
      return Error{raw.string(), "", "vtk reference: " + s.error().message};
    // The transform's uniform scale (the cube root of its determinant): VTK's fixed-point mapper
    // casts in the volume's own space (under the user matrix), so its sample distance and opacity
    // unit are own lengths; synthvis's opacity unit is a world length.
    const auto& t = v.transform.m;
    const double scale = std::cbrt(std::fabs(linearDeterminant(v.transform)));
    const double smallest = std::min({g.spacing.x, g.spacing.y, g.spacing.z});
    nlohmann::json matrix = nlohmann::json::array();
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) matrix.push_back(t[size_t(col)][size_t(row)]);
    nlohmann::json transfer = nlohmann::json::array();
    for (const scene::TransferPoint& p : v.transfer)
      transfer.push_back({(p.value - g.offset) / g.scale, p.color.x, p.color.y, p.color.z,
                          p.opacity});
    job["volumes"].push_back(
        {{"raw", raw.string()},
         {"dims", {g.nx, g.ny, g.nz}},
         {"spacing", {g.spacing.x, g.spacing.y, g.spacing.z}},
         {"matrix", matrix},
         {"transfer", transfer},
         {"opacity_unit", v.opacityUnit > 0 ? double(v.opacityUnit) / scale : smallest},
         {"sample_distance", double(scene.volumeSettings.step) * smallest},
         {"shaded", v.shaded}});
  }
  const fs::path jobPath = m.dir / "job.json";
  if (Status s = core::writeFile(jobPath.string(), {job.dump() + "\n"}); !s)
    return Error{jobPath.string(), "", "vtk reference: " + s.error().message};

  int in[2], out[2];
  if (::pipe(in) != 0) return Error{"", "", "vtk reference: pipe failed"};
  if (::pipe(out) != 0) {
    ::close(in[0]), ::close(in[1]);
    return Error{"", "", "vtk reference: pipe failed"};
  }
  const std::string screen = fmt::format("-screen 0 {}x{}x24", options.width, options.height);
  std::vector<std::string> argv;
  if (!display) argv = {"/usr/bin/xvfb-run", "-a", "-s", screen};
  argv.insert(argv.end(), {python, script, jobPath.string()});
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  const std::string errPath = (m.dir / "stderr.txt").string();
  const pid_t pid = ::fork();
  if (pid < 0) return Error{"", "", "vtk reference: fork failed"};
  if (pid == 0) {
    ::setpgid(0, 0);  // its own group: xvfb-run's Xvfb is killed with it
    ::dup2(in[0], 0);
    ::dup2(out[1], 1);
    const int err = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (err >= 0) ::dup2(err, 2);
    ::close(in[0]), ::close(in[1]), ::close(out[0]), ::close(out[1]);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  ::close(in[0]), ::close(out[1]);
  m.child = pid;
  m.toChild = in[1];
  m.fromChild = out[0];
  ::signal(SIGPIPE, SIG_IGN);  // a script that died is a failed write, not our end
  Result<std::string> ready = m.receive();
  if (!ready.ok()) return ready.error();
  if (ready.value().rfind("ready ", 0) != 0) return m.failure("unexpected '" + ready.value() + "'");
  m.description = ready.value().substr(6) + " vtkFixedPointVolumeRayCastMapper";
  return r;
}

Result<double> VtkVolumeRenderer::render() {
  Impl& m = *impl_;
  if (Status s = m.send("render"); !s) return s.error();
  Result<std::string> reply = m.receive();
  if (!reply.ok()) return reply.error();
  double ms = 0;
  if (std::sscanf(reply.value().c_str(), "ms %lf", &ms) != 1 || !(ms >= 0))
    return m.failure("unexpected '" + reply.value() + "'");
  return ms;
}

Status VtkVolumeRenderer::readImage(Image& image) {
  Impl& m = *impl_;
  const fs::path path = m.dir / "frame.rgb";
  if (Status s = m.send("image " + path.string()); !s) return s;
  Result<std::string> reply = m.receive();
  if (!reply.ok()) return reply.error();
  if (reply.value() != "ok") return m.failure("unexpected '" + reply.value() + "'");
  std::ifstream in(path, std::ios::binary);
  image.width = m.width, image.height = m.height;
  image.rgb.assign(size_t(m.width) * size_t(m.height) * 3, 0);
  in.read(reinterpret_cast<char*>(image.rgb.data()), std::streamsize(image.rgb.size()));
  if (in.gcount() != std::streamsize(image.rgb.size()))
    return m.failure(fmt::format("{}: a short frame", path.string()));
  return {};
}

}  // namespace sv::reference
