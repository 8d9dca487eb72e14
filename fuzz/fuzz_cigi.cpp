// Fuzz target: the CIGI 3.3 codec (parseDatagram) and the capture reader (parsePcap, on a file in
// memory). The first byte chooses: even → the rest is one datagram, odd → the rest is a pcap file.
// Beyond "no crash, no sanitizer report": a decoded datagram holds at most one packet per 8 bytes;
// re-encoding what was decoded is a fixed point (encode ∘ parse ∘ encode = encode, compared as
// bytes so that NaNs compare); errors carry a message and a "byte N" position.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

#include "cigi/pcap.h"
#include "synthvis/cigi.h"

namespace {

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_cigi: %s\n", what);
  std::abort();
}

void checkDatagram(std::span<const uint8_t> bytes) {
  const auto parsed = sv::cigi::parseDatagram(bytes);
  if (!parsed.ok()) {
    if (parsed.error().message.empty()) fail("an error without a message");
    if (parsed.error().position.rfind("byte ", 0) != 0) fail("an error without a byte position");
    return;
  }
  if (parsed->packets.size() + parsed->skipped > bytes.size() / 8) fail("more packets than bytes");
  if (parsed->packets.empty()) return;  // only skipped packets: nothing to re-encode
  const auto once = sv::cigi::writeDatagram(parsed->packets, parsed->swapped);
  const auto again = sv::cigi::parseDatagram(once);
  if (!again.ok()) fail("a re-encoded datagram does not parse");
  if (again->swapped != parsed->swapped) fail("re-encoding changed the byte order");
  if (sv::cigi::writeDatagram(again->packets, again->swapped) != once) {
    fail("re-encoding is not a fixed point");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::span<const uint8_t> rest(data + 1, size - 1);
  if (data[0] % 2 == 0) {
    checkDatagram(rest);
    return 0;
  }
  const auto capture = sv::cigi::parsePcap(rest, "fuzz.pcap");
  if (!capture.ok()) {
    if (capture.error().message.empty() || capture.error().file != "fuzz.pcap") {
      fail("a capture error without a message or the file's name");
    }
    return 0;
  }
  for (const sv::cigi::CapturedDatagram& d : capture.value()) {
    if (d.bytes.size() > 256 * 1024) fail("a datagram longer than a record may be");
    checkDatagram(d.bytes);
  }
  return 0;
}
