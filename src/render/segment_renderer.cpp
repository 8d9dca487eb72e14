// Based on: SPEC §10 (seed 002: segments of each scan line in priority order, a FIFO of segment
// words between the geometry and the sorter, the priority X-sort by overwrite, RUN codes, the line
// repeat of the overload protection, per-pixel interpolation along the run, the gamma tables),
// §5 (the recipient–donor 1×1 filter, the 3×3 triangle filter), §8 (Gouraud colour), §2 (the
// perspective-correct colour as colour/w ÷ 1/w, as the tile kernel computes it), §9 (interlaced
// fields as an option).
#include "render/segment_renderer.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <thread>
#include <type_traits>

#include "core/timing.h"
#include "segments/recipient_donor.h"
#include "segments/run_shading.h"
#include "segments/segments.h"

namespace sv::render {
namespace {

using Word = SegmentRenderer::Word;

// The FIFO between the two stages' threads: a ring of segment words, one writer, one reader. A
// stage that finds it full (or empty) yields its core to the other.
class WordRing {
 public:
  explicit WordRing(size_t capacity) : words_(std::bit_ceil(capacity)), mask_(words_.size() - 1) {}

  void push(const Word* w, size_t n) {
    size_t head = head_.load(std::memory_order_relaxed);
    while (n > 0) {
      const size_t room = words_.size() - (head - tail_.load(std::memory_order_acquire));
      if (room == 0) {
        std::this_thread::yield();
        continue;
      }
      const size_t k = std::min(room, n);
      for (size_t j = 0; j < k; ++j) words_[(head + j) & mask_] = w[j];
      head += k;
      head_.store(head, std::memory_order_release);
      w += k;
      n -= k;
    }
  }
  // Calls fn(word) for each word of the next line, up to and including its end-of-line or repeat
  // word, as they arrive (no copy: the sorter reads the ring).
  template <class Fn>
  void popLine(Fn&& fn) {
    size_t tail = tail_.load(std::memory_order_relaxed);
    for (;;) {
      const size_t head = head_.load(std::memory_order_acquire);
      if (head == tail) {
        std::this_thread::yield();
        continue;
      }
      while (tail != head) {
        const Word w = words_[tail++ & mask_];
        fn(w);
        if (w.segment >= SegmentRenderer::kRepeatLine) {
          tail_.store(tail, std::memory_order_release);
          return;
        }
      }
      tail_.store(tail, std::memory_order_release);
    }
  }

 private:
  std::vector<Word> words_;
  size_t mask_;
  alignas(64) std::atomic<size_t> head_{0};  // words written
  alignas(64) std::atomic<size_t> tail_{0};  // words read
};

// The ring holds the channel's FIFO, at least 1024 words (fewer only cost the threads more waits).
constexpr size_t kMinRing = 1024;

}  // namespace

struct SegmentRenderer::Field {
  const SegmentSettings* s;
  int first, step, lines;  // line i is row first + i·step
  bool linear;             // drawn into linear_ (for the filters), not straight into the image
  uint32_t background;     // the sorter's background segment: no drawn triangle's number
  segments::ChannelClock* clock;
  int row(int i) const { return first + i * step; }
};

void SegmentRenderer::produceLine(const Field& f, int line, std::vector<Word>& words) {
  words.clear();
  const int y = f.row(line);
  // The triangles starting in rows (mergedRow_, y] join the active list, in priority order; those
  // that end above y leave it.
  incoming_.clear();
  for (int r = mergedRow_ + 1; r <= y; ++r)
    for (uint32_t i = firstRow_[size_t(r)]; i < firstRow_[size_t(r) + 1]; ++i) {
      const uint32_t k = byRow_[i];
      if (setups_[k].maxY >= y) incoming_.push_back({k, setups_[k].maxY});
    }
  mergedRow_ = std::max(mergedRow_, y);
  const auto byNumber = [](const Active& a, const Active& b) { return a.number < b.number; };
  std::sort(incoming_.begin(), incoming_.end(), byNumber);
  merged_.clear();
  std::merge(active_.begin(), active_.end(), incoming_.begin(), incoming_.end(),
             std::back_inserter(merged_), byNumber);
  active_.clear();
  for (const Active& a : merged_)
    if (a.lastRow >= y) active_.push_back(a);
  const bool repeat = !f.clock->startLine(line);
  if (repeat) {
    words.push_back({kRepeatLine, y, y});
    return;
  }
  // Increasing priority: the last triangle first, so the first one's segment is written last.
  for (auto it = active_.rbegin(); it != active_.rend(); ++it) {
    const segments::Segment seg = segments::segmentOf(setups_[it->number], y, f.s->width);
    if (!seg.empty()) words.push_back({it->number, seg.xl, seg.xr});
  }
  words.push_back({kEndOfLine, y, y});
  if (!f.clock->finishLine(line, int64_t(words.size()))) {
    words.clear();
    words.push_back({kRepeatLine, y, y});
  }
}

void SegmentRenderer::finishLine(int y, const segments::XSorter& sorter,
                                 std::vector<segments::Run>& runs, FrameStats& stats) {
  sorter.runs(runs);
  stats.segmentRuns += runs.size();
  rowRuns_[size_t(y)] = {uint32_t(runStore_.size()), uint32_t(runStore_.size() + runs.size())};
  runStore_.insert(runStore_.end(), runs.begin(), runs.end());
}

void SegmentRenderer::shadeRow(const SegmentSettings& s, bool linear, uint32_t background, int y,
                               std::vector<uint16_t>& buffer) {
  const int width = s.width;
  const segments::Run* runs = runStore_.data() + rowRuns_[size_t(y)].begin;
  const size_t n = rowRuns_[size_t(y)].end - rowRuns_[size_t(y)].begin;
  // Linear codes into the frame (for the filters) or a row buffer (then the gamma table).
  buffer.resize(size_t(width) * 3);
  uint16_t* codes = linear ? &linear_.rgb[size_t(y) * size_t(width) * 3] : buffer.data();
  uint32_t* visible = s.donor ? &visible_[size_t(y) * size_t(width)] : nullptr;
  for (size_t r = 0; r < n; ++r) {
    const int xa = runs[r].x, xb = r + 1 < n ? runs[r + 1].x : width;
    if (visible) std::fill(visible + xa, visible + xb, runs[r].segment);
    if (runs[r].segment == background) {
      for (int x = xa; x < xb; ++x) std::copy_n(clear_, 3, codes + 3 * x);
      continue;
    }
    const geometry::TriangleSetup& t = setups_[runs[r].segment];
    segments::shadeRun(t, y, xa, xb, codes + 3 * xa);
    if (s.fog) {
      const double ry = s.tanTop - (s.tanTop - s.tanBottom) * (y + 0.5) / s.height;
      for (int x = xa; x < xb; ++x) {
        const double rx = s.tanLeft + (s.tanRight - s.tanLeft) * (x + 0.5) / s.width;
        const double w = 1.0 / double(geometry::planeAtPixel(t.invW, x, y, t.minX, t.minY));
        const float f = std::exp2(-s.fogBeta * float(w * std::sqrt(rx * rx + ry * ry + 1)));
        for (int c = 0; c < 3; ++c) {
          const float v = float(codes[3 * x + c]) * f + s.fogColor[c] * 65535.0f * (1 - f);
          codes[3 * x + c] = uint16_t(std::clamp(v, 0.0f, 65535.0f) + 0.5f);
        }
      }
    }
  }
  if (!linear) {
    uint8_t* bytes = image_->pixel(0, y);
    for (size_t i = 0; i < size_t(width) * 3; ++i) bytes[i] = gamma_->table[codes[i]];
  }
}

void SegmentRenderer::repeatLine(const Field& f, int y) {
  // Progressive, and the first field: the line above in the field (the seed's line repeat); the
  // second field: the mean of its neighbours in the first. The top line has none: background.
  const int width = f.s->width, h = f.s->height;
  const bool second = f.step == 2 && f.first == 1;
  const int a = second ? y - 1 : y - f.step, below = second && y + 1 < h ? y + 1 : -1;
  const size_t n = size_t(width) * 3;
  const auto blend = [&](auto row, auto clearOf) {
    using T = std::remove_pointer_t<decltype(row(0))>;
    T* dst = row(y);
    if (a < 0) {
      for (size_t i = 0; i < n; ++i) dst[i] = clearOf(i % 3);
    } else if (below < 0) {
      std::copy(row(a), row(a) + n, dst);
    } else {
      const T *p = row(a), *q = row(below);
      for (size_t i = 0; i < n; ++i) dst[i] = T((uint32_t(p[i]) + q[i] + 1) / 2);
    }
  };
  if (f.linear) {
    blend([&](int r) { return &linear_.rgb[size_t(r) * n]; }, [&](size_t c) { return clear_[c]; });
    if (f.s->donor) std::fill_n(&visible_[size_t(y) * size_t(width)], width, f.background + 1);
  } else {
    blend([&](int r) { return image_->pixel(0, r); },
          [&](size_t c) { return gamma_->table[clear_[c]]; });
  }
}

void SegmentRenderer::runField(const Field& f, core::ThreadPool& pool, FrameStats& stats) {
  active_.clear();
  mergedRow_ = -1;
  // The sorter stage, word by word: a line's segments into the sorter, its end into RUN codes.
  struct Sorting {
    segments::XSorter sorter;
    std::vector<segments::Run> runs;
    bool started = false;
  };
  const auto sortWord = [&](int line, const Word& w, Sorting& st) {
    if (!st.started) st.sorter.clear(f.background), st.started = true;
    if (w.segment < kRepeatLine) {
      st.sorter.add(w.segment, w.xl, w.xr);
      ++stats.segments;
      return;
    }
    const int y = f.row(line);
    st.started = false;
    if (w.segment == kRepeatLine) {
      rowRuns_[size_t(y)] = {kRepeated, kRepeated};
      ++stats.repeatedLines;
    } else {
      finishLine(y, st.sorter, st.runs, stats);
    }
  };
  if (pool.threadCount() < 2 || f.lines < 2) {
    // One thread: a line through both stages at a time.
    Sorting st{segments::XSorter(f.s->width), {}, false};
    std::vector<Word> words;
    for (int i = 0; i < f.lines; ++i) {
      produceLine(f, i, words);
      for (const Word& w : words) sortWord(i, w, st);
    }
    return;
  }
  // Two threads: the geometry stage writes each line's words into the ring, the sorter stage reads
  // them line by line (parallelFor's two items run on two workers: neither waits for the other to
  // finish, only for words or room).
  WordRing ring(std::max<size_t>(kMinRing, size_t(f.s->timing.fifoWords)));
  pool.parallelFor(2, [&](size_t stage, int) {
    std::vector<Word> words;
    if (stage == 0) {
      for (int i = 0; i < f.lines; ++i) {
        produceLine(f, i, words);
        ring.push(words.data(), words.size());
      }
      return;
    }
    Sorting st{segments::XSorter(f.s->width), {}, false};
    for (int i = 0; i < f.lines; ++i) ring.popLine([&](const Word& w) { sortWord(i, w, st); });
  });
}

void SegmentRenderer::render(const DrawPackets& packets, const SegmentSettings& s,
                             const output::GammaTable& gamma, core::ThreadPool& pool, Image& image,
                             FrameStats& stats) {
  const auto t0 = core::Clock::now();
  output::prepareImage(s.width, s.height, image);
  image_ = &image;
  gamma_ = &gamma;
  geometry::Viewport vp;
  vp.width = s.width;
  vp.height = s.height;
  // Setup, in parallel chunks, every triangle with its call's culling: the tile pipeline's records.
  const size_t n = packets.indices.size() / 3;
  all_.resize(n);
  outcome_.resize(n);
  constexpr size_t kChunk = 4096;
  pool.parallelFor((n + kChunk - 1) / kChunk, [&](size_t c, int) {
    const size_t end = std::min(n, (c + 1) * kChunk);
    size_t call = 0;
    for (size_t tri = c * kChunk; tri < end; ++tri) {
      while (call < packets.calls.size() &&
             tri >= size_t(packets.calls[call].firstTriangle) + packets.calls[call].triangleCount)
        ++call;
      const geometry::CullMode cull =
          call < packets.calls.size() ? packets.calls[call].cull : geometry::CullMode::none;
      const uint32_t* i = &packets.indices[tri * 3];
      outcome_[tri] =
          uint8_t(geometry::setupTriangle(packets.vertices[i[0]], packets.vertices[i[1]],
                                          packets.vertices[i[2]], vp, cull, all_[tri]));
    }
  });
  setups_.clear();
  uint64_t counts[5] = {};
  for (size_t tri = 0; tri < n; ++tri) {
    ++counts[outcome_[tri]];
    if (outcome_[tri] == uint8_t(geometry::SetupOutcome::drawn)) setups_.push_back(all_[tri]);
  }
  stats.trianglesIn += n;
  stats.drawn += counts[int(geometry::SetupOutcome::drawn)];
  stats.culledFacing += counts[int(geometry::SetupOutcome::culledFacing)];
  stats.culledOutside += counts[int(geometry::SetupOutcome::culledOutside)];
  stats.culledDegenerate += counts[int(geometry::SetupOutcome::culledDegenerate)];
  stats.culledInvalid += counts[int(geometry::SetupOutcome::culledInvalid)];
  // The drawn triangles bucketed by their first row, priority order kept within a row.
  const size_t m = setups_.size();
  firstRow_.assign(size_t(s.height) + 1, 0);
  for (size_t k = 0; k < m; ++k) ++firstRow_[size_t(setups_[k].minY) + 1];
  for (int y = 0; y < s.height; ++y) firstRow_[size_t(y) + 1] += firstRow_[size_t(y)];
  byRow_.resize(m);
  {
    std::vector<uint32_t> next(firstRow_.begin(), firstRow_.end() - 1);
    for (uint32_t k = 0; k < m; ++k) byRow_[next[size_t(setups_[k].minY)]++] = k;
  }
  stats.setupMs += core::msSince(t0);

  const auto t1 = core::Clock::now();
  for (int c = 0; c < 3; ++c)
    clear_[c] = uint16_t(std::lround(std::clamp(s.clearColor[c], 0.0f, 1.0f) * 65535.0f));
  const bool linear = s.donor || s.tent;
  if (linear) linear_.resize(s.width, s.height);
  if (s.donor) {
    visible_.resize(size_t(s.width) * size_t(s.height));
  }
  const int fields = s.interlaced ? 2 : 1;
  rowRuns_.assign(size_t(s.height), {});
  runStore_.clear();
  std::vector<Field> fieldsOf;
  for (int field = 0; field < fields; ++field) {
    Field f{&s, field, fields, (s.height - field + fields - 1) / fields, linear, uint32_t(m),
            nullptr};
    segments::ChannelClock clock(s.timing, f.lines);
    f.clock = &clock;
    runField(f, pool, stats);
    f.clock = nullptr;
    fieldsOf.push_back(f);
  }
  // The pixels of every sorted line, in bands of rows on the pool's threads; then the repeated
  // lines, field by field from the top, each from lines already there.
  constexpr int kRows = 16;
  const size_t bands = size_t((s.height + kRows - 1) / kRows);
  rowBuffers_.resize(size_t(pool.threadCount()));
  pool.parallelFor(bands, [&](size_t band, int worker) {
    const int y0 = int(band) * kRows, y1 = std::min(s.height, y0 + kRows);
    for (int y = y0; y < y1; ++y)
      if (rowRuns_[size_t(y)].begin != kRepeated)
        shadeRow(s, linear, uint32_t(m), y, rowBuffers_[size_t(worker)]);
  });
  for (const Field& f : fieldsOf)
    for (int i = 0; i < f.lines; ++i)
      if (rowRuns_[size_t(f.row(i))].begin == kRepeated) repeatLine(f, f.row(i));
  if (linear) {
    // The recipient–donor filter (segments/recipient_donor.h) over the colours and visible
    // triangles the sorter left, then the tent filter or the gamma table alone.
    const output::LinearImage* source = &linear_;
    if (s.donor) {
      filtered_.resize(s.width, s.height);
      segments::SortedFrame sorted;
      sorted.width = s.width;
      sorted.height = s.height;
      sorted.visible = visible_.data();
      sorted.background = uint32_t(m);
      sorted.unsorted = uint32_t(m) + 1;
      sorted.setups = setups_.data();
      sorted.rgb = linear_.rgb.data();
      pool.parallelFor(bands, [&](size_t band, int) {
        const int y0 = int(band) * kRows, y1 = std::min(s.height, y0 + kRows);
        segments::recipientDonorRows(sorted, y0, y1, filtered_.rgb.data());
      });
      source = &filtered_;
    }
    pool.parallelFor(bands, [&](size_t band, int) {
      const int y0 = int(band) * kRows, y1 = std::min(s.height, y0 + kRows);
      if (s.tent)
        output::tentFilterRows(*source, gamma, y0, y1, image);
      else
        output::encodeRows(*source, gamma, y0, y1, image);
    });
  }
  stats.rasterMs += core::msSince(t1);
}

}  // namespace sv::render
