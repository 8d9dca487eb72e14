// Fuzz target: the volume readers (parseVolume: NIfTI-1 and NRRD, raw or gzip) on arbitrary bytes,
// as a .nii, a .nii.gz and a .nrrd. Beyond "no crash, no sanitizer report": a read grid keeps the
// promises of synthvis/volumes.h, and a failure carries a message (fuzz_check.h). Inputs that
// begin with OpenVDB's magic are fuzz_vdb's: each forks a process, which would slow this target
// a thousandfold.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_check.h"
#include "synthvis/formats.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size >= 8 && std::memcmp(data, "\x20\x42\x44\x56\0\0\0\0", 8) == 0) return 0;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const char* name :
       {"/nonexistent/fuzz.nii", "/nonexistent/fuzz.nii.gz", "/nonexistent/fuzz.nrrd"})
    sv::formats::fuzz::checkVolume(sv::formats::parseVolume(bytes, name, false),
                                   sv::scene::kMaxVolumeSamples);
  return 0;
}
