// The overload protection's model clock (segments/channel_clock.h): a geometry stage that keeps up
// never repeats a line; a throttled one repeats lines, as many as its rate falls short, never the
// same way twice for different segments nor differently for the same ones; a line larger than the
// FIFO is always repeated.
#include "segments/channel_clock.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace sv {
namespace {

// The lines the clock repeats for a field whose line j has words[j] words (end of line included).
std::vector<bool> repeated(const segments::ChannelTiming& timing, const std::vector<int>& words) {
  segments::ChannelClock clock(timing, int(words.size()));
  std::vector<bool> out;
  for (int j = 0; j < int(words.size()); ++j)
    out.push_back(!clock.startLine(j) || !clock.finishLine(j, words[size_t(j)]));
  return out;
}

int count(const std::vector<bool>& v) { return int(std::count(v.begin(), v.end(), true)); }

TEST(ChannelClock, RepeatsLinesOnlyWhenTheGeometryStageFallsBehind) {
  std::mt19937 rng(5);
  std::vector<int> words(1080);
  for (int& w : words) w = 1 + int(rng() % 400);  // 200 words a line on average
  segments::ChannelTiming t;
  EXPECT_EQ(count(repeated(t, words)), 0);  // unlimited
  t.wordsPerLine = 401;                     // faster than any line
  EXPECT_EQ(count(repeated(t, words)), 0);
  // Slower than the mean: the shortfall is made up by repeated lines, at least 1 − rate/mean of
  // them (more: a line begun that comes late is work lost), and fewer the larger the rate.
  int last = int(words.size());
  for (int rate : {50, 100, 150, 190}) {
    t.wordsPerLine = rate;
    const std::vector<bool> r = repeated(t, words);
    EXPECT_EQ(r, repeated(t, words));  // deterministic
    const double share = count(r) / double(words.size());
    EXPECT_GT(share, 0.0) << rate;
    EXPECT_LT(count(r), last) << rate;
    EXPECT_GT(share, 1.0 - rate / 200.5 - 0.03) << rate;
    last = count(r);
  }
  // A burst of heavy lines amid light ones: the FIFO's lead carries the first of them.
  std::vector<int> burst(200, 10);
  for (int j = 100; j < 140; ++j) burst[size_t(j)] = 400;
  t.wordsPerLine = 100;
  t.fifoWords = 4096;
  const std::vector<bool> b = repeated(t, burst);
  EXPECT_EQ(count(std::vector<bool>(b.begin(), b.begin() + 100)), 0);
  EXPECT_FALSE(b[100]);
  EXPECT_GT(count(b), 0);
  EXPECT_EQ(count(std::vector<bool>(b.begin() + 150, b.end())), 0);  // recovered
}

TEST(ChannelClock, ALineLargerThanTheFifoIsRepeated) {
  segments::ChannelTiming t;
  t.wordsPerLine = 1000000;
  t.fifoWords = 64;
  t.criticalLines = 1;
  const std::vector<bool> r = repeated(t, {10, 65, 64, 10});
  EXPECT_EQ(r, (std::vector<bool>{false, true, false, false}));
}

}  // namespace
}  // namespace sv
