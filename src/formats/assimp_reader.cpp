// Based on: Assimp's C API (cimport.h, scene.h, mesh.h, material.h) — used through dlopen in a
// forked child (scene/assimp_loader.h says why).
#include "formats/assimp_reader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <dlfcn.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <string_view>

#include "formats/child_process.h"
#include "formats/reader.h"
#include "texture/texture.h"

namespace sv::formats::detail {
namespace {

constexpr int kTimeLimitSeconds = 120;
// The address space the child may take beyond what it starts with: Assimp allocates what a file
// claims, and a hostile one may claim any size.
constexpr uint64_t kMemoryBudget = uint64_t(4) << 30;

// Assimp's C entry points, looked up in the child.
struct AssimpApi {
  const aiScene* (*importFile)(const char*, unsigned int) = nullptr;
  void (*release)(const aiScene*) = nullptr;
  const char* (*errorString)() = nullptr;
  int (*extensionSupported)(const char*) = nullptr;
};

// A material property's value by key, semantic and index (material.h's layout), or nullptr.
const aiMaterialProperty* property(const aiMaterial* m, std::string_view key, unsigned semantic) {
  for (unsigned i = 0; i < m->mNumProperties; ++i) {
    const aiMaterialProperty* p = m->mProperties[i];
    if (p && std::string_view(p->mKey.data, p->mKey.length) == key && p->mSemantic == semantic &&
        p->mIndex == 0)
      return p;
  }
  return nullptr;
}

Mat4 toMat4(const aiMatrix4x4& a) {  // Assimp's is row-major, ours column-major
  Mat4 m;
  const float r[4][4] = {{a.a1, a.a2, a.a3, a.a4},
                         {a.b1, a.b2, a.b3, a.b4},
                         {a.c1, a.c2, a.c3, a.c4},
                         {a.d1, a.d2, a.d3, a.d4}};
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) m.m[col][row] = r[row][col];
  return m;
}

// The line faces (two indices) of `am` placed by `world`: segments in the vertex colours (averaged)
// times the material's diffuse colour. Returns an empty string or what is wrong.
std::string placeLines(const aiMesh& am, const Mat4& world, Scene& s) {
  if (!(am.mPrimitiveTypes & aiPrimitiveType_LINE)) return {};
  const Vec4 base = am.mMaterialIndex < s.materials.size()
                        ? s.materials[am.mMaterialIndex].baseColor
                        : Vec4{1, 1, 1, 1};
  auto color = [&](unsigned v) {
    if (!am.mColors[0]) return Vec3{base.x, base.y, base.z};
    const aiColor4D& c = am.mColors[0][v];
    return Vec3{std::clamp(c.r, 0.0f, 1.0f) * base.x, std::clamp(c.g, 0.0f, 1.0f) * base.y,
                std::clamp(c.b, 0.0f, 1.0f) * base.z};
  };
  for (unsigned f = 0; f < am.mNumFaces; ++f) {
    const aiFace& face = am.mFaces[f];
    if (face.mNumIndices != 2) continue;
    const unsigned i = face.mIndices[0], j = face.mIndices[1];
    if (i >= am.mNumVertices || j >= am.mNumVertices) return "a line's index is out of range";
    if (s.lines.size() >= kMaxLines) return fmt::format("more than {} line segments", kMaxLines);
    const aiVector3D &p = am.mVertices[i], &q = am.mVertices[j];
    s.lines.push_back({world.transformPoint({p.x, p.y, p.z}), world.transformPoint({q.x, q.y, q.z}),
                       (color(i) + color(j)) * 0.5f});
  }
  return {};
}

// Assimp's scene as ours: one mesh per triangle mesh, its diffuse colour, opacity and diffuse
// texture (a file beside the model: PNG or JPEG) as the material, one instance per node that holds
// it. Returns an empty string or what is wrong.
std::string convert(const aiScene& a, const std::string& path, const LoadOptions& options,
                    Scene& s) {
  const std::string dir = directoryOf(path);
  std::map<std::string, int> textures;
  for (unsigned i = 0; i < a.mNumMaterials; ++i) {
    const aiMaterial* am = a.mMaterials[i];
    Material m;
    if (const aiMaterialProperty* p = property(am, "?mat.name", 0);
        p && p->mType == aiPTI_String && p->mDataLength > 4)
      m.name = std::string(p->mData + 4, std::min<size_t>(p->mDataLength - 4, 1024));
    if (const aiMaterialProperty* p = property(am, "$clr.diffuse", 0);
        p && p->mType == aiPTI_Float && p->mDataLength >= 12) {
      float c[4] = {1, 1, 1, 1};
      std::memcpy(c, p->mData, std::min<size_t>(p->mDataLength, 16));
      for (float& x : c) x = std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : 1.0f;
      m.baseColor = {c[0], c[1], c[2], 1};
    }
    if (const aiMaterialProperty* p = property(am, "$mat.opacity", 0);
        p && p->mType == aiPTI_Float && p->mDataLength >= 4) {
      float o = 1;
      std::memcpy(&o, p->mData, 4);
      if (std::isfinite(o) && o < 1) {
        m.baseColor.w = std::clamp(o, 0.0f, 1.0f);
        m.alphaMode = AlphaMode::blend;
      }
    }
    if (const aiMaterialProperty* p = property(am, "$tex.file", aiTextureType_DIFFUSE);
        p && p->mType == aiPTI_String && p->mDataLength > 4 && options.followReferences) {
      const std::string file(p->mData + 4, std::min<size_t>(p->mDataLength - 4, 4096));
      if (!file.empty() && file[0] != '*') {  // '*n': embedded, not read
        auto it = textures.find(file);
        if (it == textures.end()) {
          Result<texture::Level> level = texture::readTextureImage(resolvePath(dir, file));
          if (!level) {
            s.warnings.push_back(
                fmt::format("material '{}': texture not read: {}", m.name, level.error().str()));
          } else {
            s.textures.push_back({file, std::make_shared<texture::Texture>(std::move(level.value()),
                                                                           texture::Wrap::repeat,
                                                                           texture::Wrap::repeat)});
            it = textures.emplace(file, int(s.textures.size()) - 1).first;
          }
        }
        if (it != textures.end()) m.texture = it->second;
      }
    }
    s.materials.push_back(std::move(m));
  }
  // Meshes: triangles, and lines (SortByPType split each kind into meshes of its own; lines are
  // placed with their nodes below, points are named, not drawn).
  std::vector<int> ours(a.mNumMeshes, -1);
  uint64_t points = 0;
  for (unsigned i = 0; i < a.mNumMeshes; ++i) {
    const aiMesh* am = a.mMeshes[i];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) {
      if (am->mPrimitiveTypes & aiPrimitiveType_POINT) points += am->mNumFaces;
      continue;
    }
    Mesh m;
    m.name = std::string(am->mName.data, am->mName.length);
    m.positions.resize(am->mNumVertices);
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      m.positions[v] = {am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z};
    if (am->mNormals) {
      m.normals.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v)
        m.normals[v] = {am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z};
    }
    if (am->mColors[0]) {
      m.colors.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v) {
        const aiColor4D& c = am->mColors[0][v];
        m.colors[v] = {std::clamp(c.r, 0.0f, 1.0f), std::clamp(c.g, 0.0f, 1.0f),
                       std::clamp(c.b, 0.0f, 1.0f), std::clamp(c.a, 0.0f, 1.0f)};
      }
    }
    if (am->mTextureCoords[0]) {
      m.uvs.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v)
        m.uvs[v] = {am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y};
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= am->mNumVertices)
          return fmt::format("mesh {}: index out of range", i);
        m.indices.push_back(face.mIndices[k]);
      }
    }
    if (am->mMaterialIndex < s.materials.size()) m.material = int(am->mMaterialIndex);
    ours[i] = int(s.meshes.size());
    s.meshes.push_back(std::move(m));
  }
  if (points)
    s.warnings.push_back(
        fmt::format("{} points are not drawn (only triangles and lines are)", points));
  // Nodes, depth first with an explicit stack (a hostile file may nest deeply).
  uint64_t triangles = 0;
  std::vector<std::pair<const aiNode*, Mat4>> stack;
  if (a.mRootNode) stack.push_back({a.mRootNode, Mat4{}});
  size_t visited = 0;
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    if (++visited > (size_t(1) << 22)) return "more than 4 194 304 nodes";
    const Mat4 world = parent * toMat4(node->mTransformation);
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const unsigned mesh = node->mMeshes[k];
      if (mesh >= a.mNumMeshes)
        return fmt::format("a node names mesh {} of {}", mesh, a.mNumMeshes);
      if (ours[mesh] < 0) {
        if (std::string e = placeLines(*a.mMeshes[mesh], world, s); !e.empty()) return e;
        continue;
      }
      triangles += s.meshes[size_t(ours[mesh])].triangleCount();
      if (triangles > options.maxTriangles)
        return fmt::format("the scene would have more than {} triangles", options.maxTriangles);
      s.instances.push_back({ours[mesh], world});
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c)
      if (node->mChildren[c]) stack.push_back({node->mChildren[c], world});
  }
  return validate(s, "").ok() ? std::string() : validate(s, "").error().message;
}

// The child: import, convert, write `out` (a .glb); on failure the reason to `report`, exit 1.
[[noreturn]] void child(const std::string& path, const std::string& extension,
                        const LoadOptions& options, const std::string& out, int report) {
  report = isolateChild(report, kMemoryBudget);
  auto die = [&](const std::string& why) {
    const ssize_t ignored = write(report, why.data(), std::min<size_t>(why.size(), 4000));
    (void)ignored;
    _exit(1);
  };
  void* lib = dlopen("libassimp.so.5", RTLD_NOW | RTLD_LOCAL);
  if (!lib)
    die(
        fmt::format("unknown scene file type '{}' (synthvis reads .json, .gltf, .glb and .obj "
                    "itself, other formats through Assimp, which is not installed: {})",
                    extension, dlerror()));
  AssimpApi api;
  api.importFile = reinterpret_cast<decltype(api.importFile)>(dlsym(lib, "aiImportFile"));
  api.release = reinterpret_cast<decltype(api.release)>(dlsym(lib, "aiReleaseImport"));
  api.errorString = reinterpret_cast<decltype(api.errorString)>(dlsym(lib, "aiGetErrorString"));
  api.extensionSupported =
      reinterpret_cast<decltype(api.extensionSupported)>(dlsym(lib, "aiIsExtensionSupported"));
  if (!api.importFile || !api.release || !api.errorString || !api.extensionSupported)
    die("the installed Assimp lacks its C API");
  if (!api.extensionSupported(extension.c_str()))
    die(fmt::format("unknown scene file type '{}' (neither synthvis nor Assimp reads it)",
                    extension));
  const aiScene* scene =
      api.importFile(path.c_str(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                       aiProcess_SortByPType | aiProcess_FlipUVs |
                                       aiProcess_ValidateDataStructure);
  if (!scene) die(fmt::format("Assimp: {}", oneLine(api.errorString())));
  Scene ours;
  const std::string problem = convert(*scene, path, options, ours);
  api.release(scene);
  if (!problem.empty()) die(problem);
  for (const std::string& w : ours.warnings) {
    const std::string line = "warning " + w + "\n";
    const ssize_t ignored = write(report, line.data(), line.size());
    (void)ignored;
  }
  // Nothing to draw: no file (a glTF of no buffer is not one); the parent says so.
  if (ours.meshes.empty() && ours.lines.empty()) {
    const ssize_t ignored = write(report, "empty\n", 6);
    (void)ignored;
    _exit(0);
  }
  if (Status s = saveGltf(ours, out); !s) die(s.error().message);
  _exit(0);
}

}  // namespace

Result<Scene> loadWithAssimp(const std::string& path, const std::string& extension,
                             const LoadOptions& options) {
  if (!options.followReferences)
    return Error{path, "",
                 fmt::format("unknown scene file type '{}' (.json, .gltf, .glb or .obj "
                             "here)",
                             extension)};
  char tmp[] = "/tmp/synthvis-assimp-XXXXXX";
  const int fd = mkstemp(tmp);
  if (fd < 0) return Error{path, "", "cannot make a temporary file for Assimp's output"};
  close(fd);
  const std::string out = std::string(tmp) + ".glb";
  std::filesystem::remove(tmp);
  int pipeFds[2];
  if (pipe(pipeFds) != 0) return Error{path, "", "cannot start Assimp (pipe)"};
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipeFds[0]);
    close(pipeFds[1]);
    return Error{path, "", "cannot start Assimp (fork)"};
  }
  if (pid == 0) {
    close(pipeFds[0]);
    child(path, extension, options, out, pipeFds[1]);
  }
  close(pipeFds[1]);
  // The child's report, until it closes the pipe or the time runs out.
  std::string report;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kTimeLimitSeconds);
  bool timedOut = false;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timedOut = true;
      break;
    }
    pollfd p{pipeFds[0], POLLIN, 0};
    if (poll(&p, 1, int(left.count())) <= 0) continue;
    char buffer[4096];
    const ssize_t n = read(pipeFds[0], buffer, sizeof buffer);
    if (n <= 0) break;
    if (report.size() < 65536) report.append(buffer, size_t(n));
  }
  close(pipeFds[0]);
  if (timedOut) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  auto cleanup = [&] {
    std::error_code ec;
    std::filesystem::remove(out, ec);
  };
  if (timedOut) {
    cleanup();
    return Error{path, "",
                 fmt::format("Assimp did not finish reading it in {} s", kTimeLimitSeconds)};
  }
  if (WIFSIGNALED(status)) {
    cleanup();
    return Error{path, "", fmt::format("Assimp crashed reading it (signal {})", WTERMSIG(status))};
  }
  // The report: warnings, one a line, then (on failure) the reason.
  std::vector<std::string> warnings;
  std::string reason;
  bool empty = false;
  for (size_t start = 0; start < report.size();) {
    size_t end = report.find('\n', start);
    if (end == std::string::npos) end = report.size();
    const std::string line = report.substr(start, end - start);
    if (line.rfind("warning ", 0) == 0)
      warnings.push_back(fmt::format("{}: {}", path, line.substr(8)));
    else if (line == "empty")
      empty = true;
    else
      reason += line;
    start = end + 1;
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    cleanup();
    return Error{path, "", reason.empty() ? "Assimp failed" : oneLine(reason)};
  }
  if (empty) {  // loadScene adds "nothing to draw"
    Scene none;
    none.warnings = std::move(warnings);
    return none;
  }
  Result<Scene> scene = loadGltf(out);
  cleanup();
  if (!scene) return Error{path, "", fmt::format("Assimp's output: {}", scene.error().message)};
  scene.value().warnings = std::move(warnings);
  return scene;
}

}  // namespace sv::formats::detail
