// The JSON scene format's "textures", "colorTable" and "materials" sections, and an object's
// material (docs/scene-format.md, "Materials" and "Textures").
#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "formats/json/json_reader.h"
#include "texture/texture.h"

namespace sv::formats::json {

namespace {

texture::Wrap wrapMode(const Json& v, const std::string& where) {
  const std::string name = string(v, where);
  if (name == "repeat") return texture::Wrap::repeat;
  if (name == "clamp") return texture::Wrap::clamp;
  if (name == "mirror") return texture::Wrap::mirror;
  fail(where, fmt::format("unknown wrap mode '{}' (repeat, clamp or mirror)", name));
}

}  // namespace

// A texture by name or index.
int SceneReader::textureRef(const Json& x, const std::string& w) const {
  if (x.is_string()) {
    auto it = textureByName_.find(x.get<std::string>());
    if (it == textureByName_.end())
      fail(w, fmt::format("no texture named '{}'", x.get<std::string>()));
    return it->second;
  }
  if (scene_.textures.empty()) fail(w, "there are no textures to refer to");
  return int(integer(x, w, 0, int64_t(scene_.textures.size()) - 1));
}

void SceneReader::readColorTable(const Json& v, const std::string& where) {
  array(v, where);
  if (v.size() > 256)
    fail(where, fmt::format("{} entries is more than 256 (an 8-bit code)", v.size()));
  for (size_t i = 0; i < v.size(); ++i) {
    Vec4 c = color(v[i], element(where, i), false);
    colorTable_.push_back({c.x, c.y, c.z});
  }
}

void SceneReader::readTextures(const Json& v, const std::string& where) {
  array(v, where);
  for (size_t i = 0; i < v.size(); ++i) {
    std::string w = element(where, i);
    expectKeys(v[i], w, {"name", "file", "generate", "size", "colors", "seed", "wrap"});
    TextureMap map;
    if (const Json* x = find(v[i], "name")) map.name = string(*x, member(w, "name"));
    const Json* file = find(v[i], "file");
    const Json* generate = find(v[i], "generate");
    if (!file == !generate) fail(w, "give either 'file' (a PNG, JPEG or SGI image) or 'generate' (a pattern)");
    texture::Wrap wrap[2] = {texture::Wrap::repeat, texture::Wrap::repeat};
    if (const Json* x = find(v[i], "wrap")) {
      std::string ww = member(w, "wrap");
      if (x->is_array()) {
        if (x->size() != 2) fail(ww, "expected a wrap mode or an array of 2 ([u, v])");
        for (size_t a = 0; a < 2; ++a) wrap[a] = wrapMode((*x)[a], element(ww, a));
      } else {
        wrap[0] = wrap[1] = wrapMode(*x, ww);
      }
    }
    texture::Level level;
    // The texel budget (LoadOptions::maxTexels), before anything is decoded or generated.
    auto charge = [&](uint64_t texels) {
      texels_ += texels;
      if (texels_ > context_.options.maxTexels)
        fail(w, fmt::format("the scene's textures exceed {} texels", context_.options.maxTexels));
    };
    if (file) {
      for (const char* key : {"size", "colors", "seed"})
        if (find(v[i], key)) fail(member(w, key), "only for generated textures");
      const std::string ref = string(*file, member(w, "file"));
      if (!context_.options.followReferences)
        fail(member(w, "file"),
             fmt::format("cannot open '{}' (references to other files are disabled)", ref));
      Result<texture::Level> read = texture::readTextureImage(resolvePath(directoryOf(path_), ref));
      if (!read) fail(member(w, "file"), read.error().str());
      level = std::move(read.value());
      charge(uint64_t(level.width) * uint64_t(level.height));
      if (map.name.empty()) map.name = ref;
    } else {
      const std::string gw = member(w, "generate");
      const std::string pattern = string(*generate, gw);
      texture::Pattern p;
      if (pattern == "noise")
        p = texture::Pattern::noise;
      else if (pattern == "squares")
        p = texture::Pattern::squares;
      else if (pattern == "checker")
        p = texture::Pattern::checker;
      else
        fail(gw, fmt::format("unknown pattern '{}' (noise, squares or checker)", pattern));
      int size = 256;
      if (const Json* x = find(v[i], "size"))
        size = int(integer(*x, member(w, "size"), 1, texture::kMaxGeneratedSide));
      charge(uint64_t(size) * uint64_t(size));
      texture::Color4 c[2] = {{0, 0, 0, 1}, {1, 1, 1, 1}};
      if (const Json* x = find(v[i], "colors")) {
        std::string cw = member(w, "colors");
        if (!x->is_array() || x->size() != 2) fail(cw, "expected an array of 2 colours");
        for (size_t k = 0; k < 2; ++k) {
          Vec4 col = color((*x)[k], element(cw, k), false);
          c[k] = {col.x, col.y, col.z, 1};
        }
      }
      uint32_t seed = 1;
      if (const Json* x = find(v[i], "seed"))
        seed = uint32_t(integer(*x, member(w, "seed"), 0, 0xFFFFFFFF));
      level = texture::generateTexture(p, size, c[0], c[1], seed);
      if (map.name.empty()) map.name = pattern;
    }
    map.texture = std::make_shared<texture::Texture>(std::move(level), wrap[0], wrap[1]);
    if (find(v[i], "name"))
      if (!textureByName_.emplace(map.name, int(i)).second)
        fail(member(w, "name"), fmt::format("duplicate texture name '{}'", map.name));
    scene_.textures.push_back(std::move(map));
  }
}

void SceneReader::readMaterials(const Json& v, const std::string& where) {
  array(v, where);
  for (size_t i = 0; i < v.size(); ++i) {
    std::string w = element(where, i);
    expectKeys(v[i], w,
               {"name", "color", "colorCode", "doubleSided", "unlit", "texture", "textureFilter",
                "textureScale", "phong", "specular", "shininess", "opacity", "alphaCutoff"});
    Material m;
    if (const Json* x = find(v[i], "name")) {
      m.name = string(*x, member(w, "name"));
      if (!m.name.empty() && !materialByName_.emplace(m.name, int(i)).second)
        fail(member(w, "name"), fmt::format("duplicate material name '{}'", m.name));
    }
    if (const Json* x = find(v[i], "color")) m.baseColor = color(*x, member(w, "color"), true);
    if (const Json* x = find(v[i], "colorCode")) {
      // SPEC §8 (seed 002): an 8-bit code selects an R:G:B ratio from the table; intensity (the
      // light) multiplies it as it multiplies any base colour.
      std::string cw = member(w, "colorCode");
      if (find(v[i], "color")) fail(cw, "give either 'color' or 'colorCode', not both");
      if (colorTable_.empty()) fail(cw, "the scene has no 'colorTable'");
      const Vec3 c = colorTable_[size_t(integer(*x, cw, 0, int64_t(colorTable_.size()) - 1))];
      m.baseColor = {c.x, c.y, c.z, 1};
    }
    if (const Json* x = find(v[i], "doubleSided"))
      m.doubleSided = boolean(*x, member(w, "doubleSided"));
    if (const Json* x = find(v[i], "unlit")) m.unlit = boolean(*x, member(w, "unlit"));
    if (const Json* x = find(v[i], "texture")) {
      std::string tw = member(w, "texture");
      if (x->is_string()) {
        auto it = textureByName_.find(x->get<std::string>());
        if (it == textureByName_.end())
          fail(tw, fmt::format("no texture named '{}'", x->get<std::string>()));
        m.texture = it->second;
      } else {
        if (scene_.textures.empty()) fail(tw, "there are no textures to refer to");
        m.texture = int(integer(*x, tw, 0, int64_t(scene_.textures.size()) - 1));
      }
    }
    if (const Json* x = find(v[i], "textureFilter")) {
      Result<TextureFilter> f = parseTextureFilter(string(*x, member(w, "textureFilter")));
      if (!f) fail(member(w, "textureFilter"), f.error().message);
      m.textureFilter = f.value();
    }
    if (const Json* x = find(v[i], "textureScale")) {
      const std::string sw = member(w, "textureScale");
      const auto k = x->is_number() ? std::array<float, 2>{number(*x, sw), number(*x, sw)}
                                    : numbers<2>(*x, sw);
      m.uvScale = {k[0], k[1]};
    }
    if (const Json* x = find(v[i], "phong")) m.phong = boolean(*x, member(w, "phong"));
    if (const Json* x = find(v[i], "specular"))
      m.specular = inRange(*x, member(w, "specular"), 0, 1e6f);
    if (const Json* x = find(v[i], "shininess"))
      m.shininess = inRange(*x, member(w, "shininess"), 0, 1e6f);
    if (const Json* x = find(v[i], "opacity")) {
      m.baseColor.w = inRange(*x, member(w, "opacity"), 0, 1);
      m.alphaMode = AlphaMode::blend;
    }
    if (const Json* x = find(v[i], "alphaCutoff")) {
      if (find(v[i], "opacity"))
        fail(member(w, "alphaCutoff"), "give either 'opacity' or 'alphaCutoff'");
      m.alphaCutoff = inRange(*x, member(w, "alphaCutoff"), 0, 1);
      m.alphaMode = AlphaMode::mask;
    }
    // A colour's alpha below 1 is translucency, as 'opacity' is (and as OBJ's d and glTF's
    // BLEND are): a "glass" of alpha 0.5 must not draw opaque.
    if (m.alphaMode == AlphaMode::opaque && m.baseColor.w < 1) m.alphaMode = AlphaMode::blend;
    scene_.materials.push_back(std::move(m));
  }
}

int SceneReader::readObjectMaterial(const Json& object, const std::string& where) {
  int material = -1;
  if (const Json* x = find(object, "material")) {
    std::string w = member(where, "material");
    if (x->is_string()) {
      std::string name = x->get<std::string>();
      auto it = materialByName_.find(name);
      if (it == materialByName_.end()) {
        std::string hint;
        for (const auto& [known, index] : materialByName_)
          if (editDistance(name, known) <= 2) hint = fmt::format(" (did you mean '{}'?)", known);
        fail(w, fmt::format("no material named '{}'{}", name, hint));
      }
      material = it->second;
    } else if (x->is_number_integer()) {
      int64_t count = int64_t(scene_.materials.size());
      if (count == 0) fail(w, "there are no materials to refer to");
      material = int(integer(*x, w, 0, count - 1));
    } else {
      fail(w, fmt::format("expected a material name or index, got {}", typeName(*x)));
    }
  }
  if (const Json* x = find(object, "color")) {
    Vec4 c = color(*x, member(where, "color"), true);
    auto key = std::make_pair(material, std::array<float, 4>{c.x, c.y, c.z, c.w});
    auto it = colorMaterials_.find(key);
    if (it != colorMaterials_.end()) return it->second;
    // A copy of the named material (or of the default one) with the colour replaced.
    Material m = material >= 0 ? scene_.materials[size_t(material)] : Material{};
    m.name = m.name.empty() ? std::string("color") : m.name + "+color";
    m.baseColor = c;
    if (m.alphaMode == AlphaMode::opaque && c.w < 1) m.alphaMode = AlphaMode::blend;  // as above
    scene_.materials.push_back(std::move(m));
    material = int(scene_.materials.size() - 1);
    colorMaterials_.emplace(key, material);
  }
  return material;
}

}  // namespace sv::formats::json
