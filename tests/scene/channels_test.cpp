// Display channels in the scene (SPEC §9): the arc of abutting channels, validation, and the JSON
// "channels" section with its errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "support/expect.h"
#include "synthvis/scene.h"

namespace sv::scene {
namespace {

using sv::tests::contains;

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

}  // namespace
}  // namespace sv::scene
