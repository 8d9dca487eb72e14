// The JSON scene format's "terrain" section (docs/scene-format.md, "Terrain"): height fields from
// files or a seed, their placement, base, interpolation, draped image or colour ramp; and the
// ground's height under a point, for objects placed "onGround".
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "formats/heights.h"
#include "formats/json/json_reader.h"
#include "formats/ortho_image.h"
#include "terrain/caster.h"
#include "terrain/ground.h"
#include "texture/texture.h"

namespace sv::formats::json {

// "terrain" (docs/scene-format.md, "Terrain"): a height field, its placement, base, filter, image
// or colour ramp, and material.
void SceneReader::readTerrain(const Json& v, const std::string& where) {
  expectKeys(v, where,
             {"name", "heights", "generate", "png", "origin", "base", "interpolation", "material",
              "color", "image", "detail", "ramp", "verticalScale"});
  Terrain t;
  if (const Json* x = find(v, "name")) t.name = string(*x, member(where, "name"));
  HeightField f = readHeights(v, where);
  // A geographic table in the scene's geodetic frame, whose origin is the world origin; any other
  // table centred on it unless the scene says where.
  const bool framed = scene_.geodetic && f.geographic.on;
  if (framed) placeGeographic(f.geographic, scene_.geodetic->frame(), f);
  // Under a geodetic frame a table's heights are altitudes, and the world's y = 0 is the frame
  // origin's altitude: the IG's geodetic positions and the ground then agree (GeoFrame::toWorld).
  if (scene_.geodetic) f.offset -= scene_.geodetic->origin.alt;
  t.origin[0] = framed ? 0 : 0.5 * (f.originU + f.eastU());
  t.origin[1] = framed ? 0 : 0.5 * (f.originV + f.southV());
  if (const Json* x = find(v, "origin")) {
    const auto o = doubles<2>(*x, member(where, "origin"));
    t.origin[0] = o[0], t.origin[1] = o[1];
  }
  // The base: a plane, the Earth (the WGS 84 Gaussian sphere at the geodetic frame's latitude,
  // or at a geographic table's own centre), or a sphere of a given radius; by default the Earth
  // where the scene's frame says the ground curves.
  auto earth = [&](const std::string& w) {
    if (scene_.geodetic) return scene_.geodetic->frame().origin().lat;
    if (f.geographic.on) return ownFrame(f.geographic, f.width, f.height).origin().lat;
    fail(w, "\"earth\" needs a latitude: the scene's \"geodetic\" origin, or a geographic table");
  };
  if (scene_.geodetic && scene_.geodetic->curved)
    t.baseRadius = gaussianRadius(earth(where) * std::numbers::pi / 180);
  if (const Json* x = find(v, "base")) {
    const std::string w = member(where, "base");
    if (x->is_string() && x->get<std::string>() == "plane") {
      t.baseRadius = 0;
    } else if (x->is_string() && x->get<std::string>() == "earth") {
      t.baseRadius = gaussianRadius(earth(w) * std::numbers::pi / 180);
    } else if (x->is_object()) {
      expectKeys(*x, w, {"sphere"});
      const Json* r = find(*x, "sphere");
      if (!r) fail(w, "missing key 'sphere' (the radius, metres)");
      t.baseRadius = inRange(*r, member(w, "sphere"), 1, 1e9f);
    } else {
      fail(w, R"(expected "plane", "earth" or {"sphere": radius})");
    }
  }
  if (const Json* x = find(v, "interpolation")) {
    const Result<terrain::Interpolation> i =
        terrain::parseInterpolation(string(*x, member(where, "interpolation")));
    if (!i) fail(member(where, "interpolation"), i.error().message);
    t.bicubic = i.value() == terrain::Interpolation::bicubic;
  }
  // The pyramid the scene asks for, built now: part of loading, not of the first frame.
  t.heights = terrain::prepareGround(
      std::move(f), t.bicubic ? terrain::Interpolation::bicubic : terrain::Interpolation::bilinear);
  t.material = readObjectMaterial(v, where);
  if (const Json* x = find(v, "image")) {
    const std::string w = member(where, "image");
    expectKeys(*x, w, {"file", "texture", "bands", "bounds"});
    const Json* file = find(*x, "file");
    const Json* tex = find(*x, "texture");
    if (!file == !tex) fail(w, "give either 'file' (a GDAL raster) or 'texture' (a scene texture)");
    const Json* bounds = find(*x, "bounds");
    if (bounds) {
      const auto b = doubles<4>(*bounds, member(w, "bounds"));
      if (!(b[2] > b[0] && b[3] > b[1]))
        fail(member(w, "bounds"),
             "expected [west, south, east, north] with east > west, north > south");
      for (int k = 0; k < 4; ++k) t.imageBounds[k] = b[size_t(k)];
    }
    if (tex) {
      if (!bounds) fail(w, "a texture needs 'bounds' [west, south, east, north] (map metres)");
      t.image = textureRef(*tex, member(w, "texture"));
    } else {
      std::array<int, 3> bands{1, 2, 3};
      if (const Json* b = find(*x, "bands")) {
        const std::string bw = member(w, "bands");
        array(*b, bw);
        if (b->size() != 3 && b->size() != 1) fail(bw, "expected 1 or 3 band numbers");
        for (size_t k = 0; k < 3; ++k)
          bands[k] = int(integer((*b)[b->size() == 1 ? 0 : k], element(bw, k), 1, 65535));
      }
      const std::string ref = string(*file, member(w, "file"));
      if (!context_.options.followReferences)
        fail(member(w, "file"), "referenced files are not read here");
      Result<OrthoImage> img = loadOrthoImage(resolvePath(directoryOf(path_), ref), bands);
      if (!img) fail(member(w, "file"), img.error().str());
      if (scene_.geodetic) placeGeographic(img.value(), scene_.geodetic->frame());
      if (!bounds && !img->georeferenced)
        fail(w, "the image has no georeferencing: give 'bounds' [west, south, east, north]");
      if (!bounds)
        for (int k = 0; k < 4; ++k) t.imageBounds[k] = img->bounds[size_t(k)];
      const uint64_t texels = uint64_t(img->level.width) * uint64_t(img->level.height);
      if (texels > context_.options.maxTexels - std::min(texels_, context_.options.maxTexels))
        fail(w, fmt::format("the scene's textures exceed {} texels", context_.options.maxTexels));
      texels_ += texels;
      TextureMap map;
      map.name = ref;
      map.texture = std::make_shared<texture::Texture>(std::move(img->level), texture::Wrap::clamp,
                                                       texture::Wrap::clamp);
      scene_.textures.push_back(std::move(map));
      t.image = int(scene_.textures.size()) - 1;
    }
  }
  if (const Json* x = find(v, "detail")) {
    const std::string w = member(where, "detail");
    expectKeys(*x, w, {"texture", "size"});
    const Json* tex = find(*x, "texture");
    if (!tex) fail(w, "missing key 'texture'");
    t.detail = textureRef(*tex, member(w, "texture"));
    if (const Json* s = find(*x, "size"))
      t.detailSize = inRange(*s, member(w, "size"), 1e-3f, 1e6f);
  }
  if (const Json* x = find(v, "ramp")) {
    const std::string w = member(where, "ramp");
    array(*x, w);
    if (x->empty() || x->size() > 64) fail(w, "expected 1 … 64 stops [height, [r, g, b]]");
    for (size_t i = 0; i < x->size(); ++i) {
      const std::string sw = element(w, i);
      const Json& stop = (*x)[i];
      if (!stop.is_array() || stop.size() != 2) fail(sw, "expected [height, [r, g, b]]");
      TerrainColorStop c;
      c.height = number(stop[0], element(sw, 0));
      const Vec4 col = color(stop[1], element(sw, 1), false);
      c.color = {col.x, col.y, col.z};
      if (!t.ramp.empty() && !(c.height > t.ramp.back().height))
        fail(sw, "heights must increase from stop to stop");
      t.ramp.push_back(c);
    }
  }
  scene_.terrains.push_back(std::move(t));
}

// The table: "heights" (a file, or an array of files: a mosaic) or "generate" (a fractal).
HeightField SceneReader::readHeights(const Json& v, const std::string& where) {
  const Json* heights = find(v, "heights");
  const Json* generate = find(v, "generate");
  if (!heights == !generate)
    fail(where, "give either 'heights' (a file or a list of tiles) or 'generate' (a fractal)");
  if (!context_.options.followReferences && heights)
    fail(member(where, "heights"), "referenced files are not read here");
  const auto start = std::chrono::steady_clock::now();
  Result<HeightField> field = Error{};
  if (generate) {
    const std::string w = member(where, "generate");
    expectKeys(*generate, w, {"size", "spacing", "relief", "seed"});
    int size = 1025;
    double spacing = 10, relief = 800;
    uint32_t seed = 1;
    if (const Json* x = find(*generate, "size"))
      size = int(integer(*x, member(w, "size"), 2, kMaxHeightSide));
    if (const Json* x = find(*generate, "spacing"))
      spacing = inRange(*x, member(w, "spacing"), 1e-3f, 1e5f);
    if (const Json* x = find(*generate, "relief"))
      relief = inRange(*x, member(w, "relief"), 1e-3f, 1e5f);
    if (const Json* x = find(*generate, "seed"))
      seed = uint32_t(integer(*x, member(w, "seed"), 0, 0xffffffffll));
    // Each generated sample is a texel's worth of memory against the scene's budget.
    if (uint64_t(size) * uint64_t(size) > context_.options.maxTexels)
      fail(member(w, "size"), fmt::format("{0} × {0} heights exceed the scene's budget", size));
    field = generateFractal(size, spacing, relief, seed);
    if (!field) fail(w, field.error().str());
  } else {
    const std::string w = member(where, "heights");
    PngPlacement png;
    if (const Json* x = find(v, "png")) {
      const std::string pw = member(where, "png");
      expectKeys(*x, pw, {"spacing", "origin", "offset", "scale"});
      if (const Json* s = find(*x, "spacing")) {
        const auto k = s->is_number() ? std::array<float, 2>{number(*s, member(pw, "spacing")),
                                                             number(*s, member(pw, "spacing"))}
                                      : numbers<2>(*s, member(pw, "spacing"));
        if (!(k[0] > 0 && k[1] > 0)) fail(member(pw, "spacing"), "spacing must be positive");
        png.spacingU = k[0], png.spacingV = k[1];
      }
      if (const Json* s = find(*x, "origin")) {
        const auto o = doubles<2>(*s, member(pw, "origin"));
        png.originU = o[0], png.originV = o[1];
      }
      if (const Json* s = find(*x, "offset")) png.offset = number(*s, member(pw, "offset"));
      if (const Json* s = find(*x, "scale")) png.scale = positive(*s, member(pw, "scale"));
    }
    std::vector<std::string> files;
    if (heights->is_array()) {
      if (heights->empty() || heights->size() > 256) fail(w, "expected 1 … 256 tiles");
      for (size_t i = 0; i < heights->size(); ++i)
        files.push_back(string((*heights)[i], element(w, i)));
    } else {
      files.push_back(string(*heights, w));
    }
    std::vector<HeightField> tiles;
    for (size_t i = 0; i < files.size(); ++i) {
      Result<HeightField> tile = loadHeights(resolvePath(directoryOf(path_), files[i]), png);
      if (!tile) fail(heights->is_array() ? element(w, i) : w, tile.error().str());
      tiles.push_back(std::move(tile.value()));
    }
    field = tiles.size() == 1 ? Result<HeightField>(std::move(tiles[0])) : mosaic(tiles);
    if (!field) fail(w, field.error().str());
  }
  // Vertical exaggeration, for low ground (a coastal plain's 90 m over 10 km shows little relief).
  if (const Json* x = find(v, "verticalScale")) {
    const double k = inRange(*x, member(where, "verticalScale"), 1e-3f, 1e3f);
    field->scale *= k;
    field->offset *= k;
  }
  field->loadMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return std::move(field.value());
}

double SceneReader::groundHeight(double x, double z, const std::string& where) const {
  double best = std::nan("");
  for (const Terrain& t : scene_.terrains) {
    const terrain::Interpolation interp =
        t.bicubic ? terrain::Interpolation::bicubic : terrain::Interpolation::bilinear;
    const terrain::Caster c(*t.heights, terrain::pyramidOf(*t.heights, interp), interp,
                            terrain::Placement{t.origin[0], t.origin[1], t.baseRadius});
    const terrain::Caster::MapPoint m = c.toMap({x, 0, z});
    const double h = c.surface(m.gx, m.gy);
    if (!std::isnan(h) && !(h <= best)) best = h;
  }
  if (std::isnan(best)) fail(where, fmt::format("no terrain under ({}, {}) to stand on", x, z));
  return best;
}

// "geodetic" (docs/scene-format.md, "Geodetic frame"): {"origin": {"lat", "lon", "alt"},
// "curved"} — where the world origin lies on WGS 84, and whether the ground curves.
void SceneReader::readGeodetic(const Json& v, const std::string& where) {
  expectKeys(v, where, {"origin", "curved"});
  const Json* o = find(v, "origin");
  if (!o) fail(where, "missing key 'origin' ({\"lat\", \"lon\", \"alt\"})");
  const std::string w = member(where, "origin");
  expectKeys(*o, w, {"lat", "lon", "alt"});
  Geodetic g;
  const Json* lat = find(*o, "lat");
  const Json* lon = find(*o, "lon");
  if (!lat || !lon) fail(w, "needs 'lat' and 'lon' (degrees)");
  g.origin.lat = inRange(*lat, member(w, "lat"), -89, 89);
  g.origin.lon = inRange(*lon, member(w, "lon"), -180, 180);
  if (const Json* a = find(*o, "alt")) g.origin.alt = inRange(*a, member(w, "alt"), -1e4f, 1e5f);
  if (const Json* c = find(v, "curved")) g.curved = boolean(*c, member(where, "curved"));
  scene_.geodetic = g;
}

}  // namespace sv::formats::json
