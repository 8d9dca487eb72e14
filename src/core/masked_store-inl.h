// A masked store that is cheap on every x86 target (Highway, per target): the tile kernel's
// (raster/kernel_common-inl.h) and the free forms' window rays (freeform/window_rays.cpp).
//
// Per-target include guard (Highway's convention for -inl.h files): included once per SIMD target
// by the files that use it, so that it inlines into their kernels.
#if defined(SV_CORE_MASKED_STORE_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef SV_CORE_MASKED_STORE_INL_H_
#undef SV_CORE_MASKED_STORE_INL_H_
#else
#define SV_CORE_MASKED_STORE_INL_H_
#endif

#include "hwy/highway.h"

HWY_BEFORE_NAMESPACE();
namespace sv::core {
namespace HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// Stores the lanes of `v` where `m` is set; the others keep what `p` holds. Highway's BlendedStore
// writes only those lanes, and below AVX-512 x86 has no cheap way to: AVX2 stores 16-bit lanes one
// by one (ScalarMaskedStore: an extract, a test and a branch per lane) and 32- and 64-bit lanes by
// vmaskmov, which AMD's cores microcode. There the lanes are loaded, blended and stored back: the
// same bytes in memory, three plain instructions. So the caller promises that all of the vector's
// lanes are in its buffer and that no other thread writes them meanwhile: a tile's buffers belong
// to the one thread drawing it.
template <class D, class M>
HWY_INLINE void storeWhere(hn::Vec<D> v, M m, D d, hn::TFromD<D>* HWY_RESTRICT p) {
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_SSSE3
  hn::StoreU(hn::IfThenElse(m, v, hn::LoadU(d, p)), d, p);
#else
  hn::BlendedStore(v, m, d, p);
#endif
}

}  // namespace HWY_NAMESPACE
}  // namespace sv::core
HWY_AFTER_NAMESPACE();

#endif  // SV_CORE_MASKED_STORE_INL_H_
