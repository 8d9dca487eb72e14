#include "reference/gl_renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "core/thread_pool.h"
#include "lights/light_pass.h"
#include "render/camera.h"
#include "render/passes.h"
#include "texture/texture.h"

#if SV_HAVE_GL
#define GL_GLEXT_PROTOTYPES 1
#define EGL_EGLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#endif

namespace sv::reference {

#if SV_HAVE_GL

namespace {

// SPEC §8's Gouraud model as geometry/vertex_stage.cpp computes it, per vertex.
constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 color;
layout(location = 3) in vec2 uv;
uniform mat4 mvp;
uniform mat4 modelView;
uniform vec2 uvScale;
uniform mat3 normalToWorld;
uniform vec4 baseColor;
uniform vec3 toLight;
uniform vec3 lightColor;
uniform float ambient;
uniform bool lit;
out vec4 vertexColor;
out vec2 texCoord;
out vec3 eyePosition;
void main() {
  gl_Position = mvp * vec4(position, 1.0);
  eyePosition = (modelView * vec4(position, 1.0)).xyz;
  texCoord = uv * uvScale;
  vec4 c = baseColor * color;
  vec3 intensity = vec3(1.0);
  if (lit) {
    vec3 n = normalize(normalToWorld * normal);
    intensity = vec3(ambient) + lightColor * ((1.0 - ambient) * max(0.0, dot(n, toLight)));
  }
  vertexColor = clamp(vec4(c.rgb * intensity, c.a), 0.0, 1.0);
}
)";

// The texture modulates the vertex colour, then fog (SPEC §8) takes the colour toward the fog
// colour by the range from the eye: synthvis's pixel shading without Phong.
constexpr const char* kFragmentShader = R"(#version 330 core
in vec4 vertexColor;
in vec2 texCoord;
in vec3 eyePosition;
uniform bool textured;
uniform sampler2D tex;
uniform bool fog;
uniform vec3 fogColor;
uniform float fogBeta;
out vec4 fragColor;
void main() {
  vec4 c = textured ? vertexColor * texture(tex, texCoord) : vertexColor;
  if (fog) c.rgb = mix(fogColor, c.rgb, exp2(-fogBeta * length(eyePosition)));
  fragColor = c;
}
)";

// Light points as point sprites (BENCH.md `lights`): each light's splat from synthvis's own laws
// (lights::LightPass, once when the scene is loaded: the sprites are static, which favours GL),
// drawn as a GL point of the kernel's diameter whose fragments add the kernel's weight times the
// light's colour — blended additively in linear light, depth-tested, not writing depth.
constexpr const char* kPointVertexShader = R"(#version 330 core
layout(location = 0) in vec4 ndcSize;  // clip position (w = 1) and the point's diameter
layout(location = 1) in vec3 color;    // a weight-1 fragment's addition, linear
out vec3 vColor;
void main() {
  gl_Position = vec4(ndcSize.xyz, 1.0);
  gl_PointSize = ndcSize.w;
  vColor = color;
}
)";

constexpr const char* kPointFragmentShader = R"(#version 330 core
in vec3 vColor;
out vec4 fragColor;
void main() {
  // synthvis's separable kernel (lights/light_laws.h): (1 − t²/R²)² along each axis.
  vec2 d = gl_PointCoord * 2.0 - 1.0;
  vec2 u = max(1.0 - d * d, 0.0);
  fragColor = vec4(vColor * (u.x * u.x * u.y * u.y), 1.0);
}
)";

std::string glError(const char* what) {
  const GLenum e = glGetError();
  return e == GL_NO_ERROR ? std::string() : fmt::format("{}: OpenGL error 0x{:x}", what, e);
}

struct Mesh {
  GLuint vao = 0, buffers[5] = {};
  GLsizei indexCount = 0;
  GLenum mode = GL_TRIANGLES;  // GL_LINES: the scene's lines
  bool hasNormals = false, hasColors = false, hasUvs = false;
};

struct Draw {
  size_t mesh;
  float mvp[16];
  float modelView[16];
  float normalToWorld[9];
  float baseColor[4];
  float uvScale[2];
  GLuint texture;  // 0: none
  bool lit, cull;
};

}  // namespace

struct GlRenderer::Impl {
  RenderOptions options;
  int msaa = 0;
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  GLuint program = 0;
  GLuint pointProgram = 0, pointVao = 0, pointBuffer = 0;
  GLsizei pointCount = 0;
  float lineWidth = 1;
  GLuint fbo = 0, colorRb = 0, depthRb = 0;  // the render target (multisampled if msaa)
  GLuint resolveFbo = 0, resolveRb = 0;      // single-sampled copy for readback (msaa)
  GLint uMvp = -1, uNormal = -1, uBase = -1, uToLight = -1, uLightColor = -1, uAmbient = -1,
        uLit = -1, uTextured = -1, uUvScale = -1, uModelView = -1, uFog = -1, uFogColor = -1,
        uFogBeta = -1;
  std::vector<Mesh> meshes;
  std::vector<GLuint> textures;  // one per scene texture
  std::vector<Draw> draws;
  float background[3] = {0, 0, 0};
  float toLight[3] = {0, 1, 0}, lightColor[3] = {1, 1, 1}, ambient = 1;
  bool fog = false;
  float fogColor[3] = {0, 0, 0}, fogBeta = 0;
  std::string description;
  bool initialized = false;  // eglInitialize succeeded (counted in displayUsers)

  ~Impl() {
    if (display == EGL_NO_DISPLAY) return;
    if (context != EGL_NO_CONTEXT) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context);
      freeMeshes();
      glDeleteProgram(program);
      glDeleteProgram(pointProgram);
      glDeleteVertexArrays(1, &pointVao);
      glDeleteBuffers(1, &pointBuffer);
      glDeleteFramebuffers(1, &fbo);
      glDeleteFramebuffers(1, &resolveFbo);
      const GLuint rbs[3] = {colorRb, depthRb, resolveRb};
      glDeleteRenderbuffers(3, rbs);
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
    }
    // The surfaceless display is one per process, shared by every renderer: the last one
    // terminates it (terminating it earlier would destroy the others' contexts).
    if (initialized) {
      std::lock_guard<std::mutex> lock(displayMutex());
      if (--displayUsers() == 0) eglTerminate(display);
    }
  }

  static std::mutex& displayMutex() {
    static std::mutex m;
    return m;
  }
  static int& displayUsers() {
    static int users = 0;
    return users;
  }

  void freeMeshes() {
    for (Mesh& m : meshes) {
      glDeleteVertexArrays(1, &m.vao);
      glDeleteBuffers(5, m.buffers);
    }
    meshes.clear();
    glDeleteTextures(GLsizei(textures.size()), textures.data());
    textures.clear();
  }

  Status makeCurrent() {
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
      return Error{"", "", fmt::format("gl: eglMakeCurrent failed (0x{:x})", eglGetError())};
    return {};
  }
};

bool glBuilt() { return true; }

GlRenderer::GlRenderer() : impl_(std::make_unique<Impl>()) {}
GlRenderer::~GlRenderer() = default;
const std::string& GlRenderer::description() const { return impl_->description; }

namespace {

Result<GLuint> compile(GLenum type, const char* source) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    return Error{"", "", fmt::format("gl: shader does not compile: {}", log)};
  }
  return s;
}

}  // namespace

Result<std::unique_ptr<GlRenderer>> GlRenderer::create(const RenderOptions& options, int msaa) {
  if (Status s = validate(options); !s) return s.error();
  if (msaa != 0 && msaa != 2 && msaa != 4 && msaa != 8 && msaa != 16)
    return Error{"", "",
                 fmt::format("gl: {} samples per pixel is not supported (0, 2, 4, 8, 16)", msaa)};
  // llvmpipe reads these when the driver loads; keep a user's own choice.
  const int threads = options.threads > 0 ? options.threads : 0;
  if (threads > 0) setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), 0);
  setenv("GALLIUM_DRIVER", "llvmpipe", 0);

  std::unique_ptr<GlRenderer> r(new GlRenderer());
  Impl& g = *r->impl_;
  g.options = options;
  g.msaa = msaa;
  g.display = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  {
    std::lock_guard<std::mutex> lock(Impl::displayMutex());
    if (g.display == EGL_NO_DISPLAY || !eglInitialize(g.display, &major, &minor))
      return Error{"", "",
                   fmt::format("gl: no EGL surfaceless display (0x{:x}); is Mesa's "
                               "libegl-mesa0 installed?",
                               eglGetError())};
    g.initialized = true;
    ++Impl::displayUsers();
  }
  if (!eglBindAPI(EGL_OPENGL_API)) return Error{"", "", "gl: EGL cannot bind OpenGL"};
  // Surfaceless: no config is needed (EGL_KHR_no_config_context), rendering goes to our own FBO.
  EGLConfig config = EGL_NO_CONFIG_KHR;
  const char* extensions = eglQueryString(g.display, EGL_EXTENSIONS);
  if (!extensions || !std::strstr(extensions, "EGL_KHR_no_config_context")) {
    const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint configs = 0;
    if (!eglChooseConfig(g.display, configAttribs, &config, 1, &configs) || configs < 1)
      return Error{"", "", "gl: no EGL config for desktop OpenGL"};
  }
  const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                   3,
                                   EGL_CONTEXT_MINOR_VERSION,
                                   3,
                                   EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                   EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                   EGL_NONE};
  g.context = eglCreateContext(g.display, config, EGL_NO_CONTEXT, contextAttribs);
  if (g.context == EGL_NO_CONTEXT)
    return Error{
        "", "",
        fmt::format("gl: cannot create an OpenGL 3.3 core context (0x{:x})", eglGetError())};
  if (Status s = g.makeCurrent(); !s) return s.error();
  g.description = reinterpret_cast<const char*>(glGetString(GL_RENDERER));

  // Shaders.
  auto vs = compile(GL_VERTEX_SHADER, kVertexShader);
  if (!vs.ok()) return vs.error();
  auto fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  if (!fs.ok()) return fs.error();
  g.program = glCreateProgram();
  glAttachShader(g.program, vs.value());
  glAttachShader(g.program, fs.value());
  glLinkProgram(g.program);
  glDeleteShader(vs.value());
  glDeleteShader(fs.value());
  GLint linked = 0;
  glGetProgramiv(g.program, GL_LINK_STATUS, &linked);
  if (!linked) return Error{"", "", "gl: shader program does not link"};
  g.uMvp = glGetUniformLocation(g.program, "mvp");
  g.uNormal = glGetUniformLocation(g.program, "normalToWorld");
  g.uBase = glGetUniformLocation(g.program, "baseColor");
  g.uToLight = glGetUniformLocation(g.program, "toLight");
  g.uLightColor = glGetUniformLocation(g.program, "lightColor");
  g.uAmbient = glGetUniformLocation(g.program, "ambient");
  g.uLit = glGetUniformLocation(g.program, "lit");
  g.uTextured = glGetUniformLocation(g.program, "textured");
  g.uUvScale = glGetUniformLocation(g.program, "uvScale");
  g.uModelView = glGetUniformLocation(g.program, "modelView");
  g.uFog = glGetUniformLocation(g.program, "fog");
  g.uFogColor = glGetUniformLocation(g.program, "fogColor");
  g.uFogBeta = glGetUniformLocation(g.program, "fogBeta");
  {
    auto pvs = compile(GL_VERTEX_SHADER, kPointVertexShader);
    if (!pvs) return pvs.error();
    auto pfs = compile(GL_FRAGMENT_SHADER, kPointFragmentShader);
    if (!pfs) return pfs.error();
    g.pointProgram = glCreateProgram();
    glAttachShader(g.pointProgram, pvs.value());
    glAttachShader(g.pointProgram, pfs.value());
    glLinkProgram(g.pointProgram);
    glDeleteShader(pvs.value());
    glDeleteShader(pfs.value());
    GLint pointLinked = 0;
    glGetProgramiv(g.pointProgram, GL_LINK_STATUS, &pointLinked);
    if (!pointLinked) return Error{"", "", "gl: point-sprite program does not link"};
    glGenVertexArrays(1, &g.pointVao);
    glGenBuffers(1, &g.pointBuffer);
  }

  // Render target: sRGB colour and 24-bit depth, multisampled when asked.
  const int w = options.width, h = options.height;
  glGenFramebuffers(1, &g.fbo);
  glGenRenderbuffers(1, &g.colorRb);
  glGenRenderbuffers(1, &g.depthRb);
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  glBindRenderbuffer(GL_RENDERBUFFER, g.colorRb);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, msaa, GL_SRGB8_ALPHA8, w, h);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.colorRb);
  glBindRenderbuffer(GL_RENDERBUFFER, g.depthRb);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, msaa, GL_DEPTH_COMPONENT24, w, h);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g.depthRb);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    return Error{"", "",
                 fmt::format("gl: a {}x{} sRGB framebuffer with {} samples is not "
                             "supported",
                             w, h, msaa)};
  if (msaa) {
    glGenFramebuffers(1, &g.resolveFbo);
    glGenRenderbuffers(1, &g.resolveRb);
    glBindFramebuffer(GL_FRAMEBUFFER, g.resolveFbo);
    glBindRenderbuffer(GL_RENDERBUFFER, g.resolveRb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_SRGB8_ALPHA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.resolveRb);
    glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  }
  glViewport(0, 0, w, h);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glEnable(GL_FRAMEBUFFER_SRGB);
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  if (std::string e = glError("gl: set-up"); !e.empty()) return Error{"", "", e};
  return r;
}

namespace {

// The scene's lines as one mesh of GL lines in world coordinates, each segment's colour on its
// two ends; drawn unlit (GL's own wide lines: not synthvis's strips — the reference).
scene::Mesh linesMesh(const scene::Scene& scene) {
  scene::Mesh lines;
  for (const scene::LineSegment& l : scene.lines) {
    lines.positions.insert(lines.positions.end(), {l.a, l.b});
    const Vec4 c{l.color.x, l.color.y, l.color.z, 1};
    lines.colors.insert(lines.colors.end(), {c, c});
    lines.indices.insert(lines.indices.end(),
                         {uint32_t(lines.indices.size()), uint32_t(lines.indices.size() + 1)});
  }
  return lines;
}

// A mesh's arrays in static buffers under a vertex array of its own, at the vertex shader's
// locations (0 position, 1 normal, 2 colour, 3 uv); the arrays it lacks left disabled.
Mesh uploadMesh(const scene::Mesh& m, GLenum mode) {
  Mesh out;
  out.mode = mode;
  glGenVertexArrays(1, &out.vao);
  glGenBuffers(5, out.buffers);
  glBindVertexArray(out.vao);
  auto upload = [](GLenum target, GLuint buffer, const void* data, size_t bytes) {
    glBindBuffer(target, buffer);
    glBufferData(target, GLsizeiptr(bytes), data, GL_STATIC_DRAW);
  };
  upload(GL_ARRAY_BUFFER, out.buffers[0], m.positions.data(), m.positions.size() * sizeof(Vec3));
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
  glEnableVertexAttribArray(0);
  out.hasNormals = !m.normals.empty();
  if (out.hasNormals) {
    upload(GL_ARRAY_BUFFER, out.buffers[1], m.normals.data(), m.normals.size() * sizeof(Vec3));
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
    glEnableVertexAttribArray(1);
  }
  out.hasColors = !m.colors.empty();
  if (out.hasColors) {
    upload(GL_ARRAY_BUFFER, out.buffers[2], m.colors.data(), m.colors.size() * sizeof(Vec4));
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Vec4), nullptr);
    glEnableVertexAttribArray(2);
  }
  out.hasUvs = !m.uvs.empty();
  if (out.hasUvs) {
    upload(GL_ARRAY_BUFFER, out.buffers[4], m.uvs.data(), m.uvs.size() * sizeof(Vec2));
    glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, sizeof(Vec2), nullptr);
    glEnableVertexAttribArray(3);
  }
  upload(GL_ELEMENT_ARRAY_BUFFER, out.buffers[3], m.indices.data(),
         m.indices.size() * sizeof(uint32_t));
  out.indexCount = GLsizei(m.indices.size());
  return out;
}

// GL's texture filters nearest the frame's texture filter.
struct GlFilters {
  GLint min = GL_LINEAR_MIPMAP_LINEAR, mag = GL_LINEAR;
  float anisotropy = 1;
};
GlFilters glFilters(scene::TextureFilter filter) {
  GlFilters f;
  switch (filter) {
    case scene::TextureFilter::point:
      f.min = GL_NEAREST;
      f.mag = GL_NEAREST;
      break;
    case scene::TextureFilter::nearest:
      f.min = GL_NEAREST_MIPMAP_NEAREST;
      f.mag = GL_NEAREST;
      break;
    case scene::TextureFilter::threePoint:
    case scene::TextureFilter::bilinear:
      f.min = GL_LINEAR_MIPMAP_NEAREST;
      break;
    case scene::TextureFilter::anisotropic:
      f.anisotropy = 16;
      break;
    default:
      break;
  }
  return f;
}

GLint glWrap(texture::Wrap w) {
  return w == texture::Wrap::clamp    ? GL_CLAMP_TO_EDGE
         : w == texture::Wrap::mirror ? GL_MIRRORED_REPEAT
                                      : GL_REPEAT;
}

// A texture as synthvis's own pyramid, level by level, in 8-bit sRGB (GL's usual texture format;
// the sampler decodes to linear), with its wrap modes and `filters`. GL puts the first row
// uploaded at t = 0 and ours is the image's top row, at v = 0 (glTF's convention): (s, t) = (u, v).
GLuint uploadTexture(const texture::Texture& t, const GlFilters& filters) {
  GLuint id = 0;
  glGenTextures(1, &id);
  glBindTexture(GL_TEXTURE_2D, id);
  for (int k = 0; k < t.levelCount(); ++k) {
    const texture::LevelView level = t.level(k);
    // Straight (not premultiplied) colour, sRGB-encoded; alpha linear.
    const std::vector<uint8_t> rgba = texture::toSrgb8(level);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, k, GL_SRGB8_ALPHA8, level.width, level.height, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, rgba.data());
  }
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, t.levelCount() - 1);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filters.min);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filters.mag);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, glWrap(t.wrapX()));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, glWrap(t.wrapY()));
  if (filters.anisotropy > 1)
    glTexParameterf(GL_TEXTURE_2D, 0x84FE /* GL_TEXTURE_MAX_ANISOTROPY */, filters.anisotropy);
  return id;
}

// A draw's matrices as GL's uniforms want them, column by column.
void setMatrices(Draw& d, const Mat4& mvp, const Mat4& modelView) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      d.mvp[c * 4 + r] = mvp.m[c][r];
      d.modelView[c * 4 + r] = modelView.m[c][r];
    }
}

// An instance's draw: its matrices under the view, its material's colour, texture and facing.
Draw instanceDraw(const scene::Scene& scene, const scene::Instance& inst, const Mat4& camera,
                  const Mat4& view, const std::vector<GLuint>& textures, bool cullBackFaces) {
  const scene::Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const scene::Material& mat = scene.materialAt(mesh.material);
  Draw d;
  d.mesh = size_t(inst.mesh);
  setMatrices(d, camera * inst.transform, view * inst.transform);
  const Mat4 n = inst.transform.normalMatrix();
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) d.normalToWorld[c * 3 + r] = n.m[c][r];
  d.baseColor[0] = mat.baseColor.x;
  d.baseColor[1] = mat.baseColor.y;
  d.baseColor[2] = mat.baseColor.z;
  d.baseColor[3] = mat.baseColor.w;
  d.lit = scene.light.enabled && !mat.unlit && !mesh.normals.empty();
  d.texture = mat.texture >= 0 ? textures[size_t(mat.texture)] : 0;
  d.uvScale[0] = mat.uvScale.x;
  d.uvScale[1] = mat.uvScale.y;
  d.cull = cullBackFaces && !mat.doubleSided;
  return d;
}

// The lines' draw (mesh `mesh`): already in the world, white, unlit, untextured, both faces.
Draw linesDraw(size_t mesh, const Mat4& camera, const Mat4& view) {
  Draw d{};
  d.mesh = mesh;
  setMatrices(d, camera, view);
  for (int c = 0; c < 3; ++c) d.normalToWorld[c * 3 + c] = 1;
  for (float& b : d.baseColor) b = 1;
  d.uvScale[0] = d.uvScale[1] = 1;
  return d;
}

}  // namespace

Status GlRenderer::load(const scene::Scene& scene) {
  Impl& g = *impl_;
  if (Status s = scene::validate(scene, ""); !s) return s;
  if (Status s = g.makeCurrent(); !s) return s;
  const Result<Mat4> camera = viewProjection(scene, g.options);
  if (!camera.ok()) return camera.error();
  const Result<Mat4> view = viewMatrix(scene, g.options);
  if (!view.ok()) return view.error();
  g.freeMeshes();
  g.draws.clear();
  // The geometry: the scene's meshes, then its lines as one more.
  for (const scene::Mesh& m : scene.meshes) g.meshes.push_back(uploadMesh(m, GL_TRIANGLES));
  if (!scene.lines.empty()) g.meshes.push_back(uploadMesh(linesMesh(scene), GL_LINES));
  glBindVertexArray(0);
  const GlFilters filters = glFilters(g.options.textureFilter);
  for (const scene::TextureMap& map : scene.textures)
    g.textures.push_back(uploadTexture(*map.texture, filters));
  // The draws: one per instance, then the lines'.
  for (const scene::Instance& inst : scene.instances)
    g.draws.push_back(instanceDraw(scene, inst, camera.value(), view.value(), g.textures,
                                   g.options.cullBackFaces));
  if (!scene.lines.empty()) {
    g.draws.push_back(linesDraw(g.meshes.size() - 1, camera.value(), view.value()));
    g.lineWidth = scene.lineSettings.width;
  }
  // The light, the fog and the background, for every frame's uniforms.
  const Vec3 toLight = normalize(-scene.light.direction);
  g.toLight[0] = toLight.x;
  g.toLight[1] = toLight.y;
  g.toLight[2] = toLight.z;
  g.lightColor[0] = scene.light.color.x;
  g.lightColor[1] = scene.light.color.y;
  g.lightColor[2] = scene.light.color.z;
  g.ambient = scene.light.ambient;
  g.fog = scene.fog.enabled && scene.fog.beta > 0;
  g.fogColor[0] = scene.fog.color.x;
  g.fogColor[1] = scene.fog.color.y;
  g.fogColor[2] = scene.fog.color.z;
  g.fogBeta = scene.fog.beta;
  g.background[0] = scene.background.x;
  g.background[1] = scene.background.y;
  g.background[2] = scene.background.z;
  if (Status s = loadLights(scene); !s) return s;
  if (std::string e = glError("gl: upload"); !e.empty()) return Error{"", "", e};
  return {};
}

// The scene's light points as sprites (kPointVertexShader): position, size and colour of every
// splat synthvis would draw this frame.
Status GlRenderer::loadLights(const scene::Scene& scene) {
  Impl& g = *impl_;
  g.pointCount = 0;
  if (scene.lightPoints.empty() && scene.stars.stars.empty()) return {};
  const Result<render::FrameCamera> cam = render::chooseCamera(scene, g.options);
  if (!cam.ok()) return cam.error();
  const lights::LightInput in = render::lightInput(scene, cam.value());
  lights::LightPass pass;
  pass.setLights(in);
  core::ThreadPool pool(1);
  const int w = g.options.width, h = g.options.height;
  pass.prepare(raster::PassFrame{w, h, 1, nullptr, &pool, nullptr, {}});
  const float m22 = in.projection.m[2][2], m32 = in.projection.m[3][2];
  std::vector<float> data;
  const std::vector<lights::Splat> splats = pass.splats();
  data.reserve(splats.size() * 7);
  for (const lights::Splat& s : splats) {
    // A star lies on the far plane: drawn where nothing else is.
    const float z = s.eyeDepth > 0 ? -m22 + m32 / s.eyeDepth : 1.0f - 1e-6f;
    const float v[7] = {2 * s.x / float(w) - 1, 1 - 2 * s.y / float(h), z, 2 * s.radius,
                        s.rgb[0] / 65535, s.rgb[1] / 65535, s.rgb[2] / 65535};
    data.insert(data.end(), v, v + 7);
  }
  glBindVertexArray(g.pointVao);
  glBindBuffer(GL_ARRAY_BUFFER, g.pointBuffer);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 7 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float),
                        reinterpret_cast<const void*>(4 * sizeof(float)));
  glBindVertexArray(0);
  g.pointCount = GLsizei(splats.size());
  return {};
}

Status GlRenderer::render() {
  Impl& g = *impl_;
  if (Status s = g.makeCurrent(); !s) return s;
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo);
  // The clear colour is linear, like synthvis's; the sRGB buffer encodes it.
  glClearColor(g.background[0], g.background[1], g.background[2], 1);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glUseProgram(g.program);
  glUniform3fv(g.uToLight, 1, g.toLight);
  glUniform3fv(g.uLightColor, 1, g.lightColor);
  glUniform1f(g.uAmbient, g.ambient);
  glUniform1i(g.uFog, g.fog ? 1 : 0);
  glUniform3fv(g.uFogColor, 1, g.fogColor);
  glUniform1f(g.uFogBeta, g.fogBeta);
  for (const Draw& d : g.draws) {
    const Mesh& m = g.meshes[d.mesh];
    if (d.cull)
      glEnable(GL_CULL_FACE);
    else
      glDisable(GL_CULL_FACE);
    glUniformMatrix4fv(g.uMvp, 1, GL_FALSE, d.mvp);
    glUniformMatrix4fv(g.uModelView, 1, GL_FALSE, d.modelView);
    glUniformMatrix3fv(g.uNormal, 1, GL_FALSE, d.normalToWorld);
    glUniform4fv(g.uBase, 1, d.baseColor);
    glUniform1i(g.uLit, d.lit ? 1 : 0);
    glUniform1i(g.uTextured, d.texture ? 1 : 0);
    glUniform2fv(g.uUvScale, 1, d.uvScale);
    if (d.texture) glBindTexture(GL_TEXTURE_2D, d.texture);
    glBindVertexArray(m.vao);
    // Absent attributes read these constants (a disabled array's current value).
    if (!m.hasNormals) glVertexAttrib3f(1, 0, 0, 1);
    if (!m.hasColors) glVertexAttrib4f(2, 1, 1, 1, 1);
    if (!m.hasUvs) glVertexAttrib2f(3, 0, 0);
    if (m.mode == GL_LINES) {
      glLineWidth(g.lineWidth);
      glGetError();  // a width the implementation does not have: its nearest, as GL clamps
    }
    glDrawElements(m.mode, m.indexCount, GL_UNSIGNED_INT, nullptr);
  }
  if (g.pointCount) {
    glUseProgram(g.pointProgram);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glDisable(GL_CULL_FACE);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBindVertexArray(g.pointVao);
    glDrawArrays(GL_POINTS, 0, g.pointCount);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
  }
  glBindVertexArray(0);
  glFinish();
  if (std::string e = glError("gl: draw"); !e.empty()) return Error{"", "", e};
  return {};
}

Status GlRenderer::readImage(Image& image) {
  Impl& g = *impl_;
  if (Status s = g.makeCurrent(); !s) return s;
  const int w = g.options.width, h = g.options.height;
  GLuint source = g.fbo;
  if (g.msaa) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, g.fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g.resolveFbo);
    glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    source = g.resolveFbo;
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, source);
  std::vector<uint8_t> rgba(size_t(w) * h * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  if (std::string e = glError("gl: read-back"); !e.empty()) return Error{"", "", e};
  image.width = w;
  image.height = h;
  image.rgb.resize(size_t(w) * h * 3);
  // GL's rows go bottom-up; the image's top-down.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        image.rgb[(size_t(y) * w + x) * 3 + c] = rgba[(size_t(h - 1 - y) * w + x) * 4 + c];
  return {};
}

#else  // !SV_HAVE_GL

struct GlRenderer::Impl {
  std::string description;
};

bool glBuilt() { return false; }

GlRenderer::GlRenderer() : impl_(std::make_unique<Impl>()) {}
GlRenderer::~GlRenderer() = default;
const std::string& GlRenderer::description() const { return impl_->description; }

Result<std::unique_ptr<GlRenderer>> GlRenderer::create(const RenderOptions&, int) {
  return Error{"", "",
               "the gl renderer is not in this build: install libegl-dev and libgl-dev "
               "(scripts/demo does) and configure again"};
}
Status GlRenderer::load(const scene::Scene&) { return Error{"", "", "gl: not built"}; }
Status GlRenderer::loadLights(const scene::Scene&) { return Error{"", "", "gl: not built"}; }
Status GlRenderer::render() { return Error{"", "", "gl: not built"}; }
Status GlRenderer::readImage(Image&) { return Error{"", "", "gl: not built"}; }

#endif

}  // namespace sv::reference
