// The JSON scene format's "channels" section (SPEC §9; docs/scene-format.md, "Channels"): every
// field and the arc form read, each malformed channel refused naming the file and the field.
#include <gtest/gtest.h>

#include <string>

#include "formats/formats_test_util.h"

namespace sv::formats {
namespace {

using testing::contains;

Result<Scene> parseChannels(const std::string& channels) {
  return parseJsonScene(R"({"synthvis": 1, "channels": )" + channels + "}", "t.json");
}

TEST(JsonChannels, ReadsEveryFieldAndTheArcForm) {
  Result<Scene> r = parseChannels(R"([
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

  Result<Scene> arc = parseChannels(R"({"arc": 150, "count": 3, "width": 640, "height": 360})");
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
    Result<Scene> r = parseChannels(row.channels);
    ASSERT_FALSE(r.ok()) << row.channels;
    EXPECT_TRUE(contains(r.error().str(), row.expected))
        << r.error().str() << "\n  expected: " << row.expected;
  }
  std::string many = "[";
  for (int i = 0; i < 17; ++i) many += std::string(i ? "," : "") + R"({"width": 8, "height": 8})";
  Result<Scene> r = parseChannels(many + "]");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().str(), "t.json: channels: 17 channels is more than the 16"));
}

}  // namespace
}  // namespace sv::formats
