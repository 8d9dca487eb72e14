// One channel shared by several parts (synthvis/tile_share.h, issue 36): the parts run on threads
// of this process and exchange through memory, as the cluster's ranks do over MPI. Part 0's image
// is the unshared image bit for bit — with light points (whose visibility reads depth other parts
// drew), fog, anti-aliasing, the tent filter (which reads across tile borders), supersampling,
// free forms and a debug view — and every part draws only its own tiles.
#include <gtest/gtest.h>

#include <barrier>
#include <string>
#include <thread>
#include <vector>

#include "render/tile_gather.h"
#include "synthvis/formats.h"
#include "synthvis/render.h"
#include "synthvis/scene.h"

namespace sv {
namespace {

// Where the parts meet: each call of the exchange is a rendezvous of all of them.
struct Meeting {
  explicit Meeting(int parts)
      : sync(parts), bytes(size_t(parts)), floats(size_t(parts)), calls(size_t(parts), 0) {}
  std::barrier<> sync;
  std::vector<const std::vector<uint8_t>*> bytes;
  std::vector<std::vector<float>*> floats;
  std::vector<int> calls;  // per part: gathers and maxima, to check every part made the same
};

class MemoryExchange final : public TileExchange {
 public:
  MemoryExchange(Meeting& m, int part) : m_(m), part_(part) {}

  Status gather(const std::vector<uint8_t>& mine,
                std::vector<std::vector<uint8_t>>& all) override {
    ++m_.calls[size_t(part_)];
    m_.bytes[size_t(part_)] = &mine;
    m_.sync.arrive_and_wait();
    if (part_ == 0)
      for (size_t p = 1; p < all.size(); ++p) {
        EXPECT_EQ(all[p].size(), m_.bytes[p]->size()) << "part " << p;
        all[p] = *m_.bytes[p];
      }
    m_.sync.arrive_and_wait();
    return {};
  }

  Status maxAll(std::vector<float>& values) override {
    ++m_.calls[size_t(part_)];
    m_.floats[size_t(part_)] = &values;
    m_.sync.arrive_and_wait();
    std::vector<float> result = values;
    for (const std::vector<float>* other : m_.floats) {
      EXPECT_EQ(other->size(), values.size());
      for (size_t i = 0; i < result.size() && i < other->size(); ++i)
        result[i] = std::max(result[i], (*other)[i]);
    }
    m_.sync.arrive_and_wait();
    values = std::move(result);
    return {};
  }

 private:
  Meeting& m_;
  int part_;
};

scene::Scene load(const std::string& file, int width, int height) {
  Result<scene::Scene> s = formats::loadScene(std::string(SV_SOURCE_DIR) + "/scenes/" + file);
  EXPECT_TRUE(s.ok()) << s.error().str();
  scene::Scene scene = std::move(s.value());
  scene::Channel c;
  c.width = width;
  c.height = height;
  scene.channels = {c};
  return scene;
}

// The scene's one channel drawn whole, and by `parts` parts on as many threads: part 0's image.
struct Shared {
  Image whole, assembled;
  std::vector<Image> parts;
  std::vector<FrameStats> stats;
  std::vector<int> calls;
};
Shared drawShared(const scene::Scene& scene, RenderOptions o, int parts) {
  o.threads = 1;
  Shared out;
  std::vector<Image> images;
  EXPECT_TRUE(Renderer(o).renderChannels(scene, images).ok());
  out.whole = images[0];
  Meeting meeting(parts);
  std::vector<MemoryExchange> exchanges;
  for (int p = 0; p < parts; ++p) exchanges.emplace_back(meeting, p);
  out.parts.resize(size_t(parts));
  out.stats.resize(size_t(parts));
  std::vector<std::thread> threads;
  for (int p = 0; p < parts; ++p)
    threads.emplace_back([&, p] {
      Renderer r(o);
      const std::vector<ChannelShare> mine = {{0, TileShare{parts, p, &exchanges[size_t(p)]}}};
      std::vector<Image> im;
      std::vector<FrameStats> st;
      const Status s = r.renderChannels(scene, im, &st, &mine);
      EXPECT_TRUE(s.ok()) << s.error().str();
      if (s.ok()) out.parts[size_t(p)] = im[0], out.stats[size_t(p)] = st[0];
    });
  for (std::thread& t : threads) t.join();
  out.assembled = out.parts[0];
  out.calls = meeting.calls;
  return out;
}

// Pixels of `a` and `b` that differ in the tiles `share` owns (side: a tile's pixels).
int differencesIn(const Image& a, const Image& b, const TileShare& share, int side) {
  int n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (share.owns(x / side, y / side))
        n += a.pixel(x, y)[0] != b.pixel(x, y)[0] || a.pixel(x, y)[1] != b.pixel(x, y)[1] ||
             a.pixel(x, y)[2] != b.pixel(x, y)[2];
  return n;
}

void expectAssembled(const scene::Scene& scene, const RenderOptions& o, int parts,
                     const char* what) {
  const Shared s = drawShared(scene, o, parts);
  EXPECT_EQ(s.assembled.rgb, s.whole.rgb) << what << ", " << parts << " parts";
  for (int p = 1; p < parts; ++p) EXPECT_EQ(s.calls[size_t(p)], s.calls[0]) << what;
  // Every part drew its own tiles as the whole frame has them (a tent filter reads across tile
  // borders: only part 0, which filters the assembled frame, has them).
  if (o.filter != RenderOptions::Filter::box) return;
  for (int p = 1; p < parts; ++p) {
    EXPECT_EQ(differencesIn(s.parts[size_t(p)], s.whole, TileShare{parts, p, nullptr},
                            64 / o.supersample),
              0)
        << what << ", part " << p;
  }
}

TEST(SharedChannel, LightPointsAntiAliasedAndFoggedAssembleToTheUnsharedImage) {
  const scene::Scene airport = load("airport.json", 300, 200);
  RenderOptions o;
  o.samples = 4;
  for (int parts : {2, 3}) expectAssembled(airport, o, parts, "airport, 4 samples");
  o.samples = 1;
  expectAssembled(airport, o, 2, "airport, 1 sample");
  // The lights' depth probes crossed between the parts.
  const Shared s = drawShared(airport, o, 2);
  EXPECT_GT(s.stats[0].shareBytes, 0u);
  EXPECT_GT(s.stats[1].shareBytes, 0u);
  EXPECT_GT(s.stats[0].lightsDrawn, 0u);
}

TEST(SharedChannel, TheTentFilterSupersamplingAndADebugViewAssembleToo) {
  const scene::Scene airport = load("airport.json", 260, 150);
  RenderOptions o;
  o.filter = RenderOptions::Filter::tent3;
  expectAssembled(airport, o, 2, "tent filter");
  o.filter = RenderOptions::Filter::box;
  o.supersample = 2;
  expectAssembled(airport, o, 3, "supersampled");
  o.supersample = 1;
  o.debugView = RenderOptions::DebugView::levels;
  expectAssembled(airport, o, 2, "levels view");
}

TEST(SharedChannel, FreeFormsAndMaskingAssembleToo) {
  const scene::Scene forms = load("freeform-mixed.json", 200, 140);
  RenderOptions o;
  o.samples = 4;
  expectAssembled(forms, o, 2, "free forms");
  const scene::Scene town = load("town.json", 220, 160);
  o.hsr = RenderOptions::Hsr::hybrid;
  expectAssembled(town, o, 3, "town, hybrid masking");
}

TEST(SharedChannel, PartsPackTheirTilesAndTogetherCoverTheImageOnce) {
  // A 150 × 100 image of 32-pixel tiles (supersampling 2): 5 × 4 tiles, the last row and column
  // partial, dealt over 3 parts.
  Image image;
  image.width = 150;
  image.height = 100;
  image.rgb.resize(size_t(150 * 100 * 3));
  for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = uint8_t(i * 7 + 3);
  const render::SharedPixels pixels{image.rgb.data(), 150, 100, 3, 32};
  size_t total = 0;
  Image copy = image;
  std::fill(copy.rgb.begin(), copy.rgb.end(), 0);
  const render::SharedPixels into{copy.rgb.data(), 150, 100, 3, 32};
  for (int p = 0; p < 3; ++p) {
    std::vector<uint8_t> bytes;
    render::packShare(pixels, TileShare{3, p, nullptr}, p, bytes);
    EXPECT_EQ(bytes.size(), render::sharedBytes(pixels, TileShare{3, p, nullptr}, p));
    total += bytes.size();
    render::unpackShare(into, TileShare{3, p, nullptr}, p, bytes);
  }
  EXPECT_EQ(total, image.rgb.size());
  EXPECT_EQ(copy.rgb, image.rgb);
}

TEST(SharedChannel, TheSegmentPipelineAndAChannellessSceneAreRefused) {
  scene::Scene s = load("aa-edges.json", 64, 64);
  RenderOptions o;
  o.pipeline = RenderOptions::Pipeline::segments;
  class Never final : public TileExchange {
    Status gather(const std::vector<uint8_t>&, std::vector<std::vector<uint8_t>>&) override {
      return {};
    }
    Status maxAll(std::vector<float>&) override { return {}; }
  } never;
  const std::vector<ChannelShare> mine = {{0, TileShare{2, 0, &never}}};
  std::vector<Image> images;
  Status st = Renderer(o).renderChannels(s, images, nullptr, &mine);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("not shared"), std::string::npos) << st.error().message;
  s.channels.clear();
  st = Renderer(RenderOptions{}).renderChannels(s, images, nullptr, &mine);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("display channels"), std::string::npos);
}

}  // namespace
}  // namespace sv
