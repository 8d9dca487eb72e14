// Copies into large buffers that are read again only after the current pass, with streaming
// (non-temporal) stores: they write whole lines to memory without first reading them into the
// cache (the read a normal store of a line not in cache costs) and without evicting the pass's own
// working set. Binning's record copies (raster/binner.cpp, render/frame_renderer.cpp): 16 MB a
// frame at tris 100k × 10 px (docs/performance.md, "Setup and binning").
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace sv::core {

// dst[k] = src[order[k]] for k < n — or only the first `prefix` bytes of each (a multiple of 16
// up to sizeof(T); the rest of dst[k] is left as it was). Streaming where the target has SSE2, T
// is a whole number of 16-byte units and dst is 16-byte aligned; a plain copy otherwise. Ends with
// a store fence, so that the stores are ordered before whatever hands the buffer to another
// thread.
template <class T>
void gatherStreaming(T* dst, const T* src, const uint32_t* order, size_t n,
                     size_t prefix = sizeof(T)) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (prefix >= sizeof(T) || prefix % 16 != 0) prefix = sizeof(T);
#if defined(__SSE2__)
  if constexpr (sizeof(T) % 16 == 0) {
    if ((reinterpret_cast<uintptr_t>(dst) & 15) == 0) {
      for (size_t k = 0; k < n; ++k) {
        const auto* from = reinterpret_cast<const __m128i*>(src + order[k]);
        auto* to = reinterpret_cast<__m128i*>(dst + k);
        for (size_t i = 0; i < prefix / 16; ++i)
          _mm_stream_si128(to + i, _mm_loadu_si128(from + i));
      }
      _mm_sfence();
      return;
    }
  }
#endif
  if (prefix == sizeof(T)) {
    for (size_t k = 0; k < n; ++k) dst[k] = src[order[k]];
    return;
  }
  for (size_t k = 0; k < n; ++k)
    std::memcpy(static_cast<void*>(dst + k), static_cast<const void*>(src + order[k]), prefix);
}

}  // namespace sv::core
