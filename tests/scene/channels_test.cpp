// Display channels in the scene (SPEC §9): the arc of abutting channels, validation, and the JSON
// "channels" section with its errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "scene/scene_test_util.h"
#include "synthvis/scene.h"

namespace sv::scene {
namespace {

using testing::contains;

TEST(ArcChannels, NeighboursShareAnEdgeAndTheArcIsCentred) {
  const std::vector<Channel> c = arcChannels(3, 150, 640, 360);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_FLOAT_EQ(c[0].yawDegrees + c[0].frustum->leftDegrees, -75);
  EXPECT_FLOAT_EQ(c[2].yawDegrees + c[2].frustum->rightDegrees, 75);
  EXPECT_FLOAT_EQ(c[1].yawDegrees, 0);
  for (size_t i = 0; i + 1 < c.size(); ++i)
    EXPECT_NEAR(c[i].yawDegrees + c[i].frustum->rightDegrees,
                c[i + 1].yawDegrees + c[i + 1].frustum->leftDegrees, 1e-5);
  // vfov 0: square pixels, tan(up) / tan(right) = height / width.
  const double toRadians = std::numbers::pi / 180;
  EXPECT_NEAR(std::tan(c[0].frustum->upDegrees * toRadians) /
                  std::tan(c[0].frustum->rightDegrees * toRadians),
              360.0 / 640.0, 1e-6);
  EXPECT_EQ(c[1].name, "1");
  EXPECT_EQ(c[1].width, 640);
  EXPECT_FLOAT_EQ(arcChannels(2, 90, 64, 64, 40)[0].frustum->upDegrees, 20);
  EXPECT_TRUE(arcChannels(0, 90, 64, 64).empty());
  EXPECT_TRUE(arcChannels(int(kMaxChannels) + 1, 90, 64, 64).empty());
}

Channel named(const std::string& name) {
  Channel c;
  c.name = name;
  return c;
}

TEST(ArcChannels, ValidateRejectsEachBadChannel) {
  struct Row {
    void (*spoil)(Channel&);
    const char* expected;
  };
  const Row rows[] = {
      {[](Channel& c) { c.yawDegrees = std::numeric_limits<float>::quiet_NaN(); },
       "channels[1]: yaw and roll must be"},
      {[](Channel& c) { c.pitchDegrees = 91; }, "pitch −90 … 90"},
      {[](Channel& c) { c.width = 0; }, "channels[1]: 0x480 pixels, each must be 1 … 8192"},
      {[](Channel& c) { c.height = 8193; }, "each must be 1 … 8192"},
      {[](Channel& c) {
         c.frustum = ChannelFrustum{10, -10, -5, 5};
       },
       "channels[1].frustum: left must be less than right"},
      {[](Channel& c) {
         c.frustum = ChannelFrustum{-10, 10, 5, 5};
       },
       "down must be less than up"},
      {[](Channel& c) {
         c.frustum = ChannelFrustum{-90, 10, -5, 5};
       },
       "in (−90, 90) degrees"},
      {[](Channel& c) { c.offset.y = std::numeric_limits<float>::infinity(); },
       "channels[1].offset: not finite"},
  };
  for (const Row& row : rows) {
    Scene s;
    s.channels = {named("a"), Channel{}};
    EXPECT_TRUE(validate(s, "s.json").ok());
    row.spoil(s.channels[1]);
    const Status st = validate(s, "s.json");
    ASSERT_FALSE(st.ok()) << row.expected;
    EXPECT_TRUE(contains(st.error().str(), row.expected)) << st.error().str();
    EXPECT_TRUE(contains(st.error().str(), "s.json")) << st.error().str();
  }
  // Names: they become parts of file names, so one file per channel.
  const std::string badNames[][2] = {{"../x", "channels[1].name: use 1 … 64 letters"},
                                     {"a", "channels[1].name: duplicate channel name 'a'"}};
  for (const auto& [name, expected] : badNames) {
    Scene s;
    s.channels = {named("a"), named(name)};
    const Status st = validate(s, "s.json");
    ASSERT_FALSE(st.ok()) << expected;
    EXPECT_TRUE(contains(st.error().str(), expected)) << st.error().str();
  }
  Scene s;
  s.channels.resize(kMaxChannels + 1);
  EXPECT_TRUE(contains(validate(s, "s.json").error().str(), "17 channels is more than 16"));
}

Result<Scene> parse(const std::string& channels) {
  return parseJsonScene(R"({"synthvis": 1, "channels": )" + channels + "}", "t.json");
}

TEST(JsonChannels, ReadsEveryFieldAndTheArcForm) {
  Result<Scene> r = parse(R"([
      {"name": "left", "yaw": -50, "pitch": 2, "roll": -3, "offset": [-0.5, 0, 0.25],
       "frustum": {"left": -20, "right": 25, "down": -15, "up": 10}, "width": 640, "height": 360},
      {"width": 320, "height": 200}])");
  ASSERT_TRUE(r.ok()) << r.error().str();
  ASSERT_EQ(r->channels.size(), 2u);
  const Channel& c = r->channels[0];
  EXPECT_EQ(c.name, "left");
  EXPECT_EQ(c.yawDegrees, -50);
  EXPECT_EQ(c.pitchDegrees, 2);
  EXPECT_EQ(c.rollDegrees, -3);
  EXPECT_EQ(c.offset, (Vec3{-0.5f, 0, 0.25f}));
  ASSERT_TRUE(c.frustum.has_value());
  EXPECT_EQ(c.frustum->leftDegrees, -20);
  EXPECT_EQ(c.frustum->rightDegrees, 25);
  EXPECT_EQ(c.frustum->downDegrees, -15);
  EXPECT_EQ(c.frustum->upDegrees, 10);
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 360);
  EXPECT_FALSE(r->channels[1].frustum.has_value());
  EXPECT_EQ(r->channels[1].yawDegrees, 0);

  Result<Scene> arc = parse(R"({"arc": 150, "count": 3, "width": 640, "height": 360})");
  ASSERT_TRUE(arc.ok()) << arc.error().str();
  ASSERT_EQ(arc->channels.size(), 3u);
  EXPECT_FLOAT_EQ(arc->channels[0].yawDegrees, -50);
  EXPECT_FLOAT_EQ(arc->channels[2].frustum->rightDegrees, 25);
}

TEST(JsonChannels, RejectsEachMalformedChannelNamingTheFileAndTheField) {
  struct Row {
    const char* channels;
    const char* expected;
  };
  const Row rows[] = {
      {"3", "t.json: channels: expected an array, got an integer"},
      {R"({"width": 64, "height": 64})", "t.json: channels: missing key 'arc'"},
      {R"([{"height": 64}])", "t.json: channels[0]: missing key 'width'"},
      {R"([{"width": 0, "height": 64}])", "t.json: channels[0].width: 0 is out of range 1..8192"},
      {R"([{"width": 64, "height": 9000}])", "channels[0].height: 9000 is out of range 1..8192"},
      {R"([{"width": 64.5, "height": 64}])", "channels[0].width: expected an integer"},
      {R"([{"width": 64, "height": 64, "yaw": 181}])", "channels[0].yaw: 181 is out of range"},
      {R"([{"width": 64, "height": 64, "pitch": -95}])", "channels[0].pitch: -95 is out of range"},
      {R"([{"width": 64, "height": 64, "yaw": "left"}])",
       "channels[0].yaw: expected a number, got a string"},
      {R"([{"width": 64, "height": 64, "offset": [0, 1]}])",
       "channels[0].offset: expected an array of 3 numbers"},
      {R"([{"width": 64, "height": 64, "frustum": {"left": 10, "right": 5, "down": -5, "up": 5}}])",
       "t.json: channels[0].frustum: left (10) must be less than right (5)"},
      {R"([{"width": 64, "height": 64, "frustum": {"left": -5, "right": 5, "down": 5, "up": 5}}])",
       "channels[0].frustum: down (5) must be less than up (5)"},
      {R"([{"width": 64, "height": 64, "frustum": {"left": -90, "right": 5, "down": -5, "up": 5}}])",
       "channels[0].frustum.left: -90 is out of range (-90, 90) degrees"},
      {R"([{"width": 64, "height": 64, "frustum": {"left": -5, "right": 5, "down": -5}}])",
       "channels[0].frustum: missing key 'up'"},
      {R"([{"width": 64, "height": 64, "yawn": 3}])", "channels[0]: unknown key 'yawn'"},
      {R"([{"name": "a b", "width": 64, "height": 64}])", "channels[0].name: use 1 … 64 letters"},
      {R"([{"name": "a", "width": 64, "height": 64}, {"name": "a", "width": 64, "height": 64}])",
       "channels[1].name: duplicate channel name 'a'"},
      {R"({"arc": 150, "count": 17, "width": 64, "height": 64})",
       "channels.count: 17 is out of range 1..16"},
      {R"({"arc": 400, "count": 2, "width": 64, "height": 64})",
       "channels.arc: 400 is out of range (0, 360) degrees"},
      {R"({"arc": 150, "count": 3, "width": 64})", "channels: missing key 'height'"},
  };
  for (const Row& row : rows) {
    Result<Scene> r = parse(row.channels);
    ASSERT_FALSE(r.ok()) << row.channels;
    EXPECT_TRUE(contains(r.error().str(), row.expected))
        << r.error().str() << "\n  expected: " << row.expected;
  }
  std::string many = "[";
  for (int i = 0; i < 17; ++i) many += std::string(i ? "," : "") + R"({"width": 8, "height": 8})";
  Result<Scene> r = parse(many + "]");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().str(), "t.json: channels: 17 channels is more than the 16"));
}

}  // namespace
}  // namespace sv::scene
