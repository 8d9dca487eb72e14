// NIfTI-1 volumes (.nii, .nii.gz; SPEC §11 voxel arrays; docs/scene-format.md "Volumes"): one
// volume, unsigned or signed 8-, 16- or 32-bit, float or double samples, scl_slope and scl_inter
// applied, the voxel sizes as its spacing. Based on: the NIfTI-1 header (nifti1.h, NIfTI DFWG).
#include <cmath>
#include <cstring>

#include "formats/volume_samples.h"

namespace sv::formats::volumes {

VolumeGrid nifti(const std::string& bytes, size_t maxSamples) {
  Source in(bytes, 0, gzipped(bytes));
  unsigned char h[348];
  in.read(h, sizeof h, "the NIfTI-1 header");
  int32_t sizeofHdr;
  std::memcpy(&sizeofHdr, h, 4);
  bool swap = false;
  if (sizeofHdr != 348) {
    if (int32_t(__builtin_bswap32(uint32_t(sizeofHdr))) != 348)
      fail(fmt::format("not a NIfTI-1 file (sizeof_hdr is {}, not 348)", sizeofHdr));
    swap = true;
  }
  auto field = [&]<class T>(T, size_t at) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, h + at, sizeof b);
    if (swap) std::reverse(b, b + sizeof b);
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  };
  if (std::memcmp(h + 344, "n+1\0", 4) != 0) {
    if (std::memcmp(h + 344, "ni1\0", 4) == 0)
      fail("a NIfTI-1 header without its data (.hdr/.img pair): only single files (.nii) are read");
    fail("not a NIfTI-1 file (no 'n+1' magic); NIfTI-2 is not read");
  }
  int64_t dim[8];
  for (int i = 0; i < 8; ++i) dim[i] = field(int16_t{}, 40 + 2 * size_t(i));
  if (dim[0] < 3 || dim[0] > 7)
    fail(fmt::format("dim[0] is {}: a volume has 3 dimensions", dim[0]));
  for (int i = 4; i <= dim[0]; ++i)
    if (dim[i] > 1)
      fail(
          fmt::format("a series of {} volumes (dim[{}]): only single volumes are read", dim[i], i));
  VolumeGrid g = sizedGrid(dim[1], dim[2], dim[3], maxSamples);
  const int16_t datatype = field(int16_t{}, 70);
  Type type;
  switch (datatype) {
    case 2:
      type = Type::u8;
      break;
    case 256:
      type = Type::i8;
      break;
    case 4:
      type = Type::i16;
      break;
    case 512:
      type = Type::u16;
      break;
    case 8:
      type = Type::i32;
      break;
    case 768:
      type = Type::u32;
      break;
    case 16:
      type = Type::f32;
      break;
    case 64:
      type = Type::f64;
      break;
    default:
      fail(fmt::format(
          "NIfTI datatype {} is not read (unsigned/signed 8, 16, 32-bit, float, double)",
          datatype));
  }
  g.spacing = {spacingOf(field(float{}, 80)), spacingOf(field(float{}, 84)),
               spacingOf(field(float{}, 88))};
  const float voxOffset = field(float{}, 108);
  if (!(voxOffset >= 348) || voxOffset > 1e6f)
    fail(fmt::format("vox_offset {} is not within 348 … 10^6", voxOffset));
  in.skip(size_t(voxOffset) - 348, "the header's extensions");
  readSamples(g, in, type, (std::endian::native == std::endian::little) == swap);
  rescale(g, field(float{}, 112), field(float{}, 116));
  return g;
}

}  // namespace sv::formats::volumes
