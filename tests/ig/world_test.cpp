// The IG's state (ig/world.h): what each host packet does to the next frame's scene, and the
// answers to height and line-of-sight requests against the terrain query and the polygons.
#include "ig/world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "ig/geo.h"
#include "ig/overload.h"
#include "synthvis/ig.h"
#include "synthvis/render.h"
#include "synthvis/terrain.h"

namespace sv::ig {
namespace {

const std::string kConfig = std::string(SV_TEST_DATA_DIR) + "/ig/ig.json";

IgWorld loadWorld() {
  Result<IgConfig> c = loadIgConfig(kConfig);
  EXPECT_TRUE(c.ok()) << c.error().str();
  Result<IgWorld> w = IgWorld::load(c.value());
  EXPECT_TRUE(w.ok()) << w.error().str();
  return std::move(w.value());
}

std::vector<cigi::Packet> apply(IgWorld& w, std::vector<cigi::Packet> packets) {
  cigi::Datagram d;
  d.packets.push_back(cigi::IgControl{});
  d.packets.insert(d.packets.end(), packets.begin(), packets.end());
  std::vector<cigi::Packet> replies;
  w.apply(d, replies);
  return replies;
}

TEST(IgGeo, GeodeticPositionsRoundTripAndHeadingsPointTheWayTheySay) {
  const GeoFrame o(GeoPoint{45, 7, 100});
  const Vec3d w = o.toWorld({45.01, 7.02, 350});
  // North is −z, by WGS 84's meridian radius at 45° (6 367 381.8 m).
  EXPECT_NEAR(-w.z, 0.01 * std::numbers::pi / 180 * 6367381.816, 1e-3);
  EXPECT_GT(w.x, 0);  // east is +x
  EXPECT_DOUBLE_EQ(w.y, 250);
  const GeoPoint g = o.toGeodetic(w);
  EXPECT_NEAR(g.lat, 45.01, 1e-12);
  EXPECT_NEAR(g.lon, 7.02, 1e-12);
  EXPECT_NEAR(g.alt, 350, 1e-9);
  // Heading 90°: forward is east; pitch 90°: forward is up; roll 90° (right wing down): right
  // points down.
  const Frame3 east = eulerFrame(levelFrame(), 90, 0, 0);
  EXPECT_NEAR(east.forward.x, 1, 1e-12);
  EXPECT_NEAR(east.right.z, 1, 1e-12);  // right of east-facing is south (+z)
  EXPECT_NEAR(eulerFrame(levelFrame(), 0, 90, 0).forward.y, 1, 1e-12);
  EXPECT_NEAR(eulerFrame(levelFrame(), 0, 0, 90).right.y, -1, 1e-12);
}

// Each (text, message) case refused by `parse` with an error naming `file` and holding `message`.
template <class Parse>
void expectRefused(Parse parse, const std::vector<std::pair<std::string, std::string>>& cases,
                   const std::string& file) {
  for (const auto& [text, message] : cases) {
    const auto r = parse(text, file);
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.error().str().find(message), std::string::npos) << r.error().str();
    EXPECT_EQ(r.error().file, file);
  }
}

TEST(IgConfig, MalformedConfigurationsGetAClearError) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{", "malformed JSON"},
      {R"({"scene": "db.json"})", "\"synthvis-ig\": 1 expected"},
      {R"({"synthvis-ig": 1})", "\"scene\""},
      {R"({"synthvis-ig": 1, "scene": "a.json", "rate": 1000})", "rate: 1000 is outside"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "models": {"x": "m.json"}})", "not an entity type"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "render": {"aa": 3}})", "render.aa"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "colour": 1})", "unknown field \"colour\""},
      {R"({"synthvis-ig": 1, "scene": "a.json", "display": {}})", "display: either"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "display": {"cylinder": {}, "mpcdi": "r.mpcdi"}})",
       "display: either"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "display": {"cylinder": {"width": 8}}})",
       "display.cylinder.width: 8 is outside"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "display": {"mpcdi": 3}})", "display.mpcdi"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "display": {"cylinder": {}, "correction": "warp"}})",
       "display.correction: subfrusta, bilinear or bicubic"},
      {R"({"synthvis-ig": 1, "scene": "a.json", "channels": {"count": 2},
           "display": {"cylinder": {}}})",
       "not with \"channels\""},
      {R"({"synthvis-ig": 1, "scene": "a.json", "cluster": {"split": [{"channel": 0, "ranks": [0, 1]}]},
           "display": {"cylinder": {}}})",
       "not with cluster.split"},
  };
  expectRefused(parseIgConfig, cases, "ig.json");
}

TEST(IgHost, MalformedScriptsGetAClearError) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[", "malformed JSON"},
      {R"({"rate": 30})", "\"synthvis-host\": 1 expected"},
      {R"({"synthvis-host": "1"})", "\"synthvis-host\": 1 expected"},
      {R"({"synthvis-host": 2})", "\"synthvis-host\": 1 expected"},
      // A version beyond int's range, which a read as int would convert (fuzz find).
      {R"({"synthvis-host": 1e79})", "\"synthvis-host\": 1 expected"},
      {R"({"synthvis-host": 1, "rate": 0})", "script.rate"},
      {R"({"synthvis-host": 1, "entities": [{"id": 1}]})", "entities[0].path"},
      {R"({"synthvis-host": 1, "entities": [{"path": [{"t": 1}, {"t": 1}]}]})",
       "times must increase"},
      {R"({"synthvis-host": 1, "events": [{"timeOfDay": "25:00"}]})", "\"HH:MM\" expected"},
      {R"({"synthvis-host": 1, "events": [{"timeOfDay": "99999999999:00"}]})",
       "\"HH:MM\" expected"},
      {R"({"synthvis-host": 1, "events": [{"timeOfDay": "6:30pm"}]})", "\"HH:MM\" expected"},
      {R"({"synthvis-host": 1, "events": [{"timeOfDay": "6:5"}]})", "\"HH:MM\" expected"},
  };
  expectRefused(parseHostScript, cases, "host.json");
  Result<HostScript> s = parseHostScript(
      R"({"synthvis-host": 1.0, "rate": 50, "events": [{"t": 1, "timeOfDay": "6:30"}]})",
      "host.json");
  ASSERT_TRUE(s.ok()) << s.error().str();
  EXPECT_EQ(s->rate, 50.0);
  ASSERT_EQ(s->events.size(), 1u);
  ASSERT_EQ(s->events[0].packets.size(), 1u);
  const auto* sky = std::get_if<cigi::CelestialSphereControl>(&s->events[0].packets[0]);
  ASSERT_NE(sky, nullptr);
  EXPECT_EQ(sky->hour, 6);
  EXPECT_EQ(sky->minute, 30);
}

TEST(IgWorld, AnEntityAppearsWithItsModelAtItsPoseAndGoesWhenDestroyed) {
  IgWorld w = loadWorld();
  const size_t base = w.frameScene(0).instances.size();
  cigi::EntityControl e;
  e.entity = 3;
  e.type = 7;
  e.latOrX = 45.001;
  e.lonOrY = 7;
  e.altOrZ = 60;
  e.yaw = 90;
  apply(w, {e});
  const scene::Scene& s = w.frameScene(0);
  ASSERT_EQ(s.instances.size(), base + 1);
  const Mat4& m = s.instances.back().transform;
  const Vec3d at = w.earth().toWorld({45.001, 7, 60});
  EXPECT_NEAR(m.m[3][0], at.x, 1e-3);
  EXPECT_NEAR(m.m[3][1], 60, 1e-3);
  EXPECT_NEAR(m.m[3][2], at.z, 1e-2);
  // The model's front (+z) faces the heading, east.
  EXPECT_NEAR(m.transformDirection({0, 0, 1}).x, 1, 1e-6);
  // An entity attached to it, 10 m ahead in its body axes.
  cigi::EntityControl child;
  child.entity = 4;
  child.type = 7;
  child.attached = true;
  child.parent = 3;
  child.latOrX = 10;
  apply(w, {child});
  EXPECT_NEAR(w.frameScene(0).instances.back().transform.m[3][0], at.x + 10, 1e-3);
  e.state = cigi::EntityState::destroyed;
  apply(w, {e});
  EXPECT_EQ(w.frameScene(0).instances.size(), base);  // the child goes with its parent's pose
  EXPECT_EQ(w.activeEntities(), 1u);
}

TEST(IgWorld, RatesMoveAnEntityBetweenHostFramesWhenExtrapolationIsOn) {
  IgWorld w = loadWorld();
  cigi::EntityControl e;
  e.entity = 2;
  e.type = 7;
  e.latOrX = 45;
  e.lonOrY = 7;
  e.altOrZ = 100;
  e.yaw = 90;  // facing east
  cigi::RateControl r;
  r.entity = 2;
  r.x = 10;  // forward, in its own axes: east
  r.z = -2;  // up
  cigi::Datagram d;
  cigi::IgControl on;
  on.extrapolation = true;
  d.packets = {on, e, r};
  std::vector<cigi::Packet> replies;
  w.apply(d, replies);
  for (int f = 0; f < 50; ++f) w.advance(0.02);
  const Mat4& m = w.frameScene(1).instances.back().transform;
  EXPECT_NEAR(m.m[3][0], 10, 1e-3);
  EXPECT_NEAR(m.m[3][1], 102, 1e-3);
  EXPECT_NEAR(m.m[3][2], 0, 1e-3);
  // In world (north, east, down) axes instead: 5 m/s north.
  r.worldCoordinates = true;
  r.x = 5;
  r.z = 0;
  d.packets = {on, e, r};
  w.apply(d, replies);
  w.advance(1);
  EXPECT_NEAR(w.frameScene(2).instances.back().transform.m[3][2], -5, 1e-3);
  // Off: the pose stays as the host sent it.
  d.packets = {cigi::IgControl{}, e, r};
  w.apply(d, replies);
  w.advance(1);
  EXPECT_NEAR(w.frameScene(3).instances.back().transform.m[3][2], 0, 1e-3);
}

TEST(IgWorld, OutOfRangeAndNonFinitePacketsAreRejectedAndChangeNothing) {
  IgWorld w = loadWorld();
  const size_t base = w.frameScene(0).instances.size();
  cigi::EntityControl far;
  far.entity = 60000;  // past maxEntities
  far.type = 7;
  cigi::EntityControl nan;
  nan.entity = 1;
  nan.type = 7;
  nan.latOrX = std::nan("");
  cigi::ViewDefinition badView;
  badView.view = 9;
  cigi::ComponentControl badGroup;
  badGroup.componentClass = cigi::ComponentClass::system;
  badGroup.component = 5;
  apply(w, {far, nan, badView, badGroup});
  EXPECT_EQ(w.counts().rejected, 4u);
  EXPECT_EQ(w.frameScene(0).instances.size(), base);
}

TEST(IgWorld, LightGroupsSwitchAndDimAndVisibilityBecomesFog) {
  IgWorld w = loadWorld();
  ASSERT_EQ(w.frameScene(0).lightGroups.size(), 1u);
  EXPECT_TRUE(w.frameScene(0).lightGroups[0].on);
  cigi::ComponentControl off;
  off.componentClass = cigi::ComponentClass::system;
  off.component = 0;
  off.state = 0;
  apply(w, {off});
  EXPECT_FALSE(w.frameScene(0).lightGroups[0].on);
  cigi::ComponentControl dim = off;
  dim.state = 2;
  const float half = 0.5f;
  std::memcpy(&dim.data[0], &half, sizeof half);
  apply(w, {dim});
  EXPECT_TRUE(w.frameScene(0).lightGroups[0].on);
  EXPECT_FLOAT_EQ(w.frameScene(0).lightGroups[0].dim, 0.5f);

  EXPECT_FALSE(w.frameScene(0).fog.enabled);
  cigi::AtmosphereControl a;
  a.visibility = 2000;
  apply(w, {a});
  const scene::Fog& fog = w.frameScene(0).fog;
  EXPECT_TRUE(fog.enabled);
  // 5 % contrast left at the visibility: 2^(−β·V) = 0.05.
  EXPECT_NEAR(std::exp2(-fog.beta * 2000), 0.05, 1e-6);
  cigi::WeatherControl wc;
  wc.enabled = true;
  wc.visibility = 500;  // the nearer of the two
  apply(w, {wc});
  EXPECT_NEAR(std::exp2(-w.frameScene(0).fog.beta * 500), 0.05, 1e-6);
}

TEST(IgWorld, SwitchedLightsAndTheVisibilityShowInTheRenderedFrame) {
  IgWorld w = loadWorld();
  RenderOptions options;
  options.threads = 2;
  Renderer renderer(options);
  auto frame = [&] {
    std::vector<Image> images;
    EXPECT_TRUE(renderer.renderChannels(w.frameScene(0), images).ok());
    return images.at(0);
  };
  auto sum = [](const Image& image) {
    uint64_t total = 0;
    for (uint8_t v : image.rgb) total += v;
    return total;
  };
  const Image lit = frame();
  cigi::ComponentControl off;
  off.componentClass = cigi::ComponentClass::system;
  off.state = 0;
  apply(w, {off});
  const Image dark = frame();
  EXPECT_LT(sum(dark), sum(lit));  // the runway light is gone, nothing else changed
  cigi::AtmosphereControl haze;
  haze.visibility = 150;
  apply(w, {haze});
  const Image foggy = frame();
  EXPECT_NE(foggy.rgb, dark.rgb);
  // The ground below the eye takes on the fog's colour (the default haze, 0.6, 0.65, 0.7 linear:
  // about 203, 211, 219 in sRGB).
  auto fogDistance = [](const Image& image) {
    const uint8_t* p = image.pixel(image.width / 2, image.height - 1);
    return std::abs(p[0] - 203) + std::abs(p[1] - 211) + std::abs(p[2] - 219);
  };
  EXPECT_LT(fogDistance(foggy), fogDistance(dark));
}

TEST(IgWorld, TheEyeRidesTheOwnshipAndViewsSetTheChannels) {
  IgWorld w = loadWorld();
  cigi::EntityControl own;  // entity 0: the ownship, heading east, 120 m up
  own.entity = 0;
  own.latOrX = 45;
  own.lonOrY = 7;
  own.altOrZ = 120;
  own.yaw = 90;
  cigi::ViewControl vc;
  vc.view = 0;
  vc.enable = 1 | 2 | 32;  // x and y offsets, yaw
  vc.x = 5;                // 5 m forward
  vc.y = -2;               // 2 m left
  vc.yaw = -20;
  cigi::ViewDefinition vd;
  vd.view = 0;
  vd.left = -25;
  vd.right = 35;
  vd.bottom = -10;
  vd.top = 15;
  vd.nearPlane = 0.5f;
  vd.farPlane = 9000;
  apply(w, {own, vc, vd});
  const scene::Scene& s = w.frameScene(0);
  ASSERT_FALSE(s.cameras.empty());
  const scene::Camera& cam = s.cameras[0];
  EXPECT_NEAR(cam.position.y, 120, 1e-3);
  EXPECT_NEAR(cam.target.x - cam.position.x, 100, 1e-3);  // looking east
  EXPECT_NEAR(cam.up.y, 1, 1e-6);
  EXPECT_FLOAT_EQ(cam.znear, 0.5f);
  EXPECT_FLOAT_EQ(cam.zfar, 9000);
  const scene::Channel& ch = s.channels.at(0);
  EXPECT_FLOAT_EQ(ch.offset.z, -5);  // forward is −z in the eye's space
  EXPECT_FLOAT_EQ(ch.offset.x, -2);
  EXPECT_FLOAT_EQ(ch.yawDegrees, -20);
  ASSERT_TRUE(ch.frustum.has_value());
  EXPECT_FLOAT_EQ(ch.frustum->leftDegrees, -25);
  EXPECT_FLOAT_EQ(ch.frustum->upDegrees, 15);
  // A view beyond the channels is rejected.
  vc.view = 5;
  apply(w, {vc});
  EXPECT_EQ(w.counts().rejected, 1u);
}

TEST(IgWorld, TheTimeOfDayMovesTheSunAndFadesTheStars) {
  IgWorld w = loadWorld();
  cigi::CelestialSphereControl noon;
  noon.hour = 12;
  apply(w, {noon});
  const scene::Scene& day = w.frameScene(0);
  EXPECT_LT(day.light.direction.y, -0.8f);  // the sun high, shining down
  EXPECT_LT(day.light.direction.z, 0);      // from the south (+z), travelling north (−z)
  EXPECT_GT(day.background.z, 0.5f);        // a blue sky
  EXPECT_FLOAT_EQ(day.stars.brightness, 0);
  cigi::CelestialSphereControl night = noon;
  night.hour = 23;
  apply(w, {night});
  const scene::Scene& dark = w.frameScene(0);
  EXPECT_GT(dark.light.direction.y, 0);  // below the horizon
  EXPECT_LT(dark.background.z, 0.1f);
  cigi::CelestialSphereControl bad;
  bad.hour = 24;
  apply(w, {bad});
  EXPECT_EQ(w.counts().rejected, 1u);
}

TEST(IgWorld, HeightsAnswerFromTheTerrainQueryAndThePolygons) {
  IgWorld w = loadWorld();
  const GeoFrame& o = w.earth();
  // Over open ground: the terrain query's own answer.
  const Vec3d p{30, 100, -150};
  const std::optional<TerrainHeight> t = terrainHeight(w.database(), p.x, p.y, p.z);
  ASSERT_TRUE(t.has_value());
  const GeoPoint g = o.toGeodetic(p);
  cigi::HatHotRequest hat;
  hat.id = 11;
  hat.latOrX = g.lat;
  hat.lonOrY = g.lon;
  hat.altOrZ = g.alt;
  cigi::HatHotRequest hot = hat;
  hot.id = 12;
  hot.type = cigi::HatHotType::hot;
  // On the tower (80 m tall at x −40, z −250): its roof.
  const GeoPoint roof = o.toGeodetic({-40, 100, -250});
  cigi::HatHotRequest tower = hat;
  tower.id = 13;
  tower.latOrX = roof.lat;
  tower.lonOrY = roof.lon;
  // Off the database: no ground.
  cigi::HatHotRequest off = hat;
  off.id = 14;
  off.latOrX = 46;
  const std::vector<cigi::Packet> r = apply(w, {hat, hot, tower, off});
  ASSERT_EQ(r.size(), 4u);
  const auto& a = std::get<cigi::HatHotResponse>(r[0]);
  EXPECT_EQ(a.id, 11);
  EXPECT_TRUE(a.valid);
  EXPECT_FALSE(a.hot);
  EXPECT_NEAR(a.height, t->above, 1e-6);
  const auto& b = std::get<cigi::HatHotResponse>(r[1]);
  EXPECT_TRUE(b.hot);
  EXPECT_NEAR(b.height, p.y - t->above + o.origin().alt, 1e-6);
  EXPECT_NEAR(std::get<cigi::HatHotResponse>(r[2]).height, 100 - 80, 1e-3);
  EXPECT_FALSE(std::get<cigi::HatHotResponse>(r[3]).valid);
}

TEST(IgWorld, LinesOfSightStopAtTheTowerAndTheGround) {
  IgWorld w = loadWorld();
  auto geo = [&](Vec3d p) { return w.earth().toGeodetic(p); };
  cigi::LosSegmentRequest through;
  through.id = 5;
  const GeoPoint a = geo({-40, 50, -150}), b = geo({-40, 50, -350});  // through the tower
  std::memcpy(through.source, &a, sizeof through.source);
  std::memcpy(through.destination, &b, sizeof through.destination);
  cigi::LosSegmentRequest clear = through;
  clear.id = 6;
  const GeoPoint c = geo({40, 200, -150}), d = geo({40, 200, -350});  // above everything
  std::memcpy(clear.source, &c, sizeof clear.source);
  std::memcpy(clear.destination, &d, sizeof clear.destination);
  const std::vector<cigi::Packet> r = apply(w, {through, clear});
  ASSERT_EQ(r.size(), 2u);
  const auto& blocked = std::get<cigi::LosResponse>(r[0]);
  EXPECT_TRUE(blocked.valid);
  EXPECT_FALSE(blocked.visible);
  EXPECT_NEAR(blocked.range, 95, 0.05);  // the tower's near face at z −245
  const auto& open = std::get<cigi::LosResponse>(r[1]);
  EXPECT_FALSE(open.valid);
  EXPECT_TRUE(open.visible);
}

TEST(IgOverload, StepsDownWhenOverrunAndBackUpWithHysteresis) {
  RenderOptions full;
  full.samples = 16;
  const std::vector<QualityLevel> levels = qualityLevels(full);
  // aa 8, aa 4, aa 1, bilinear textures, no stars, half resolution (no terrain: none of its).
  ASSERT_EQ(levels.size(), 7u);
  EXPECT_EQ(levels[6].replication, 2);
  EXPECT_EQ(levels[1].options.samples, 8);
  EXPECT_EQ(levels[3].options.samples, 1);
  EXPECT_FALSE(levels[5].stars);
  // A database with levels of detail gives up geometry before resolution.
  const std::vector<QualityLevel> withLod = qualityLevels(full, true);
  ASSERT_EQ(withLod.size(), 8u);
  EXPECT_EQ(withLod[6].change, "coarser levels of detail");
  EXPECT_EQ(withLod[6].options.lodScale, 2);
  EXPECT_EQ(withLod[6].replication, 1);
  EXPECT_EQ(withLod[7].options.lodScale, 2);
  EXPECT_EQ(withLod[7].replication, 2);
  OverloadGovernor g(levels, 10.0, 5);
  // The frame's cost: 24 ms at full quality, halving with each anti-aliasing step.
  auto cost = [&](int level) { return 24.0 / (1 << std::min(level, 3)); };
  EXPECT_EQ(g.choose(FrameWork{1000}), 0);  // nothing measured yet
  g.record(0, FrameWork{1000}, {cost(0)});  // overran: down at once
  EXPECT_GE(g.level(), 1);
  int level = 0;
  for (int f = 0; f < 20; ++f) {
    level = g.choose(FrameWork{1000});
    g.record(level, FrameWork{1000}, {cost(level)});
    EXPECT_LE(level, 3);
  }
  EXPECT_EQ(level, 2);  // the first that fits 10 ms: aa 4's 6 ms (aa 8 takes 12)
  // The load falls to 30 % (the work a frame draws): back up, one level per hold, to full
  // quality (7.2 ms, within three quarters of the budget).
  std::vector<int> seen;
  for (int f = 0; f < 40; ++f) {
    level = g.choose(FrameWork{300});
    g.record(level, FrameWork{300}, {cost(level) * 0.3});
    if (seen.empty() || seen.back() != level) seen.push_back(level);
  }
  EXPECT_EQ(seen, (std::vector<int>{2, 1, 0}));
}

TEST(IgOverload, OnePassingOverloadDoesNotKeepTheQualityDown) {
  RenderOptions full;
  full.samples = 16;
  OverloadGovernor g(qualityLevels(full), 10.0, 5);
  auto cost = [](int level) { return 4.0 / (1 << std::min(level, 3)); };  // fits at full quality
  for (int f = 0; f < 10; ++f)
    g.record(g.choose(FrameWork{1000}), FrameWork{1000}, {cost(g.level())});
  ASSERT_EQ(g.level(), 0);
  g.record(g.choose(FrameWork{1000}), FrameWork{1000}, {100});  // one frame the machine was busy
  ASSERT_GE(g.level(), 1);
  int frames = 0;
  while (g.level() > 0 && frames < 200) {
    const int level = g.choose(FrameWork{1000});
    g.record(level, FrameWork{1000}, {cost(level)});
    ++frames;
  }
  EXPECT_EQ(g.level(), 0);
  EXPECT_LT(frames, 80);
}

TEST(IgOverload, TerrainLevelsComeInTheOrderOfTheirGain) {
  RenderOptions full;
  const std::vector<QualityLevel> bicubic = qualityLevels(full, false, {true, true});
  // bilinear textures, no stars, bilinear terrain, coarser terrain, half resolution.
  ASSERT_EQ(bicubic.size(), 6u);
  EXPECT_EQ(bicubic[3].change, "bilinear terrain");
  EXPECT_EQ(bicubic[3].options.terrainFilter, RenderOptions::TerrainFilter::bilinear);
  EXPECT_EQ(bicubic[4].change, "coarser terrain");
  EXPECT_EQ(bicubic[4].options.terrainLodBias, 1);
  EXPECT_EQ(bicubic[4].options.terrainFilter, RenderOptions::TerrainFilter::bilinear);
  // Bilinear terrain only: nothing to gain from "bilinear terrain".
  const std::vector<QualityLevel> bilinear = qualityLevels(full, false, {true, false});
  ASSERT_EQ(bilinear.size(), 5u);
  EXPECT_EQ(bilinear[3].change, "coarser terrain");
}

TEST(IgOverload, VolumesWidenTheirScreenWindowsBeforeTheTerrainsLevels) {
  RenderOptions full;
  // Exact volumes (the default, 0): windows blended at 0.05; a database at 0.05 already: 0.1.
  for (const float own : {0.0f, 0.05f}) {
    const std::vector<QualityLevel> levels = qualityLevels(full, false, {true, false, true, own});
    // bilinear textures, no stars, coarser volume windows, coarser terrain, half resolution.
    ASSERT_EQ(levels.size(), 6u);
    EXPECT_EQ(levels[0].options.volumeWindowTolerance, -1.0f);  // the scene's own
    EXPECT_EQ(levels[3].change, "coarser volume windows");
    EXPECT_EQ(levels[3].options.volumeWindowTolerance, own > 0 ? 0.1f : 0.05f);
    EXPECT_EQ(levels[4].change, "coarser terrain");
    EXPECT_EQ(levels[5].options.volumeWindowTolerance, levels[3].options.volumeWindowTolerance);
  }
  // An explicit tolerance at full quality is the one doubled.
  full.volumeWindowTolerance = 0.2f;
  EXPECT_EQ(qualityLevels(full, false, {false, false, true, 0})[3].options.volumeWindowTolerance,
            0.4f);
}

TEST(IgOverload, TheTerrainsCostIsPredictedFromTheGroundsShare) {
  // A frame of 2 ms of polygons and a terrain pass of 40 ms per unit of ground share; the budget
  // 12 ms. Flown at a fifth of the picture ground (10 ms) it holds full quality; when the ground
  // fills half of it (22 ms) the governor steps down before the frame, not after an overrun — a
  // prediction from triangles alone would still say 10 ms.
  RenderOptions full;
  OverloadGovernor g(qualityLevels(full, false, {true, false}), 12.0, 5);
  auto cost = [](int level, double ground) {
    const double terrain = 40 * ground / (level >= 3 ? 2.0 : 1.0);  // coarser terrain: half
    return FrameCost{2 + terrain, terrain};
  };
  for (int f = 0; f < 10; ++f) {
    const FrameWork w{1000, 0.2};
    const int level = g.choose(w);
    g.record(level, w, cost(level, 0.2));
  }
  ASSERT_EQ(g.level(), 0);
  EXPECT_NEAR(g.predict(0, FrameWork{1000, 0.5}), 22, 1e-6);
  EXPECT_GE(g.choose(FrameWork{1000, 0.5}), 1);
}

}  // namespace
}  // namespace sv::ig
