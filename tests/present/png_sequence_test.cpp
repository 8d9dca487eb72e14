// The PNG sequence: file names, files read back equal; the writer thread's queue and errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <future>

#include "present/async_writer.h"
#include "present/present.h"
#include "present/test_patterns.h"
#include "support/temp_dir.h"

namespace sv::present {
namespace {

TEST(PresentPngSequence, FileNamesCarryFrameAndChannel) {
  EXPECT_EQ(pngFrameName(123, "left", 0), "frame-000123-left.png");
  EXPECT_EQ(pngFrameName(1234567, "left", 0), "frame-1234567-left.png");
  EXPECT_EQ(pngFrameName(5, "front/up 2", 1), "frame-000005-front_up_2.png");
  EXPECT_EQ(pngFrameName(5, "", 2), "frame-000005-channel2.png");
}

TEST(PresentPngSequence, WrittenFilesReadBackEqual) {
  const auto dir = sv::tests::processTemp().dir() / "png" / "nested";
  std::filesystem::remove_all(dir.parent_path());
  auto presenter = makePresenter("png:" + dir.string(), 60);
  ASSERT_TRUE(presenter.ok()) << presenter.error().str();
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  const Image channels[2] = {testPattern(TestPattern::grid, 70, 40, "left"),
                             testPattern(TestPattern::wedges, 50, 40, "right")};
  const std::string names[2] = {"left", "right"};
  ASSERT_TRUE(presenter.value()->present({42, channels, names}).ok());
  ASSERT_TRUE(presenter.value()->flush().ok());
  for (int i = 0; i < 2; ++i) {
    auto back = readPng((dir / pngFrameName(42, names[i], i)).string());
    ASSERT_TRUE(back.ok()) << back.error().str();
    EXPECT_EQ(back->width, channels[i].width);
    EXPECT_EQ(back->height, channels[i].height);
    EXPECT_EQ(back->rgb, channels[i].rgb);
  }
  std::filesystem::remove_all(dir.parent_path());
}

TEST(PresentPngSequence, FullQueueDropsFramesInsteadOfWaiting) {
  // The sink is held until released: at most one frame in it and kDepth waiting, so of
  // kDepth + 3 submitted at least two are dropped, and submit never waits.
  constexpr size_t kDepth = 2;
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  int written = 0;
  detail::AsyncWriter writer(
      [&](const detail::OwnedFrame&) {
        released.wait();
        ++written;
        return Status();
      },
      kDepth);
  const Image image = testPattern(TestPattern::grid, 8, 8, "");
  const std::string name = "c";
  for (uint64_t i = 0; i < kDepth + 3; ++i) EXPECT_TRUE(writer.submit({i, {&image, 1}, {&name, 1}}).ok());
  EXPECT_GE(writer.dropped(), 2u);
  release.set_value();
  EXPECT_TRUE(writer.flush().ok());
  EXPECT_EQ(uint64_t(written) + writer.dropped(), kDepth + 3);
}

TEST(PresentPngSequence, WriterErrorIsReturnedByTheNextCall) {
  detail::AsyncWriter writer([](const detail::OwnedFrame&) { return Status(Error{"x.png", "", "disk full"}); },
                             2);
  const Image image = testPattern(TestPattern::grid, 8, 8, "");
  const std::string name = "c";
  EXPECT_TRUE(writer.submit({0, {&image, 1}, {&name, 1}}).ok());
  const Status s = writer.flush();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().str(), "x.png: disk full");
  EXPECT_TRUE(writer.flush().ok());  // reported once
}

}  // namespace
}  // namespace sv::present
