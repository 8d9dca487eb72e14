// Display channels (SPEC §9): the arc of abutting channels, and the checks of scene::validate.
#include "scene/channels.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <set>

namespace sv::scene {
namespace detail {
namespace {

constexpr int kMaxChannelSize = 8192;  // as the raster (sv::kMaxRasterSize)

bool within(float x, float lo, float hi) { return x >= lo && x <= hi; }  // false for NaN

}  // namespace

bool isChannelName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
          c == '_'))
      return false;
  return true;
}

std::string channelsProblem(const std::vector<Channel>& channels) {
  if (channels.size() > kMaxChannels)
    return fmt::format("channels: {} channels is more than {}", channels.size(), kMaxChannels);
  std::set<std::string> names;
  for (size_t i = 0; i < channels.size(); ++i) {
    const Channel& c = channels[i];
    const std::string at = fmt::format("channels[{}]", i);
    if (!c.name.empty() && !isChannelName(c.name))
      return at + ".name: use 1 … 64 letters, digits, '-' or '_'";
    if (!c.name.empty() && !names.insert(c.name).second)
      return fmt::format("{}.name: duplicate channel name '{}'", at, c.name);
    if (!within(c.yawDegrees, -180, 180) || !within(c.pitchDegrees, -90, 90) ||
        !within(c.rollDegrees, -180, 180))
      return at + ": yaw and roll must be −180 … 180 degrees, pitch −90 … 90";
    if (!isFinite(c.offset)) return at + ".offset: not finite";
    if (c.width < 1 || c.width > kMaxChannelSize || c.height < 1 || c.height > kMaxChannelSize)
      return fmt::format("{}: {}x{} pixels, each must be 1 … {}", at, c.width, c.height,
                         kMaxChannelSize);
    if (c.frustum) {
      const ChannelFrustum& f = *c.frustum;
      for (float a : {f.leftDegrees, f.rightDegrees, f.downDegrees, f.upDegrees})
        if (!(a > -90 && a < 90)) return at + ".frustum: angles must be in (−90, 90) degrees";
      if (!(f.leftDegrees < f.rightDegrees)) return at + ".frustum: left must be less than right";
      if (!(f.downDegrees < f.upDegrees)) return at + ".frustum: down must be less than up";
    }
  }
  return {};
}

}  // namespace detail

std::vector<Channel> arcChannels(int n, float totalHorizontalDegrees, int width, int height,
                                 float verticalFovDegrees) {
  std::vector<Channel> out;
  if (n < 1 || size_t(n) > kMaxChannels) return out;
  // Each channel's share of the arc and its half-angle, in double: channel i's right edge and
  // channel i+1's left edge differ only by the float rounding of their yaws (~1e-5 degrees at
  // 180, far below a pixel), so they abut.
  const double each = double(totalHorizontalDegrees) / n;
  const double half = 0.5 * each;
  double up = 0.5 * verticalFovDegrees;
  if (!(verticalFovDegrees > 0)) {
    const double toRadians = std::numbers::pi / 180;
    up = std::atan(std::tan(half * toRadians) * height / width) / toRadians;
  }
  for (int i = 0; i < n; ++i) {
    Channel c;
    c.name = std::to_string(i);
    c.yawDegrees = float(-0.5 * totalHorizontalDegrees + (i + 0.5) * each);
    c.frustum = ChannelFrustum{float(-half), float(half), float(-up), float(up)};
    c.width = width;
    c.height = height;
    out.push_back(c);
  }
  return out;
}

}  // namespace sv::scene
