// The CIGI 3.3 codec: round trips of every packet in both byte orders, hand-built datagrams
// checked byte by byte against the ICD's layout (so that a bug shared by the encoder and the
// decoder cannot hide behind a round trip), skipped IDs, and malformed datagrams.
#include "synthvis/cigi.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <numeric>

#include "cigi/session.h"

namespace sv::cigi {
namespace {

using test::hostPackets;
using test::igPackets;

constexpr bool kLittleEndianMachine = std::endian::native == std::endian::little;

size_t wireSize(const std::vector<Packet>& packets) {
  size_t n = 0;
  for (const Packet& p : packets) n += packetSize(packetId(p));
  return n;
}

TEST(CigiCodec, EveryPacketRoundTripsInBothByteOrders) {
  for (const auto& packets : {hostPackets(), igPackets()}) {
    for (bool swap : {false, true}) {
      SCOPED_TRACE(swap ? "swapped" : "this machine's order");
      const std::vector<uint8_t> bytes = writeDatagram(packets, swap);
      EXPECT_EQ(bytes.size(), wireSize(packets));
      const auto parsed = parseDatagram(bytes);
      ASSERT_TRUE(parsed.ok()) << parsed.error().position << ": " << parsed.error().message;
      EXPECT_EQ(parsed->swapped, swap);
      EXPECT_EQ(parsed->skipped, 0u);
      ASSERT_EQ(parsed->packets.size(), packets.size());
      for (size_t i = 0; i < packets.size(); ++i) {
        EXPECT_TRUE(parsed->packets[i] == packets[i]) << "packet " << i << ", ID "
                                                      << int(packetId(packets[i]));
      }
    }
  }
}

TEST(CigiCodec, TheTwoByteOrdersAreEachOthersMirrorFieldByField) {
  // Bytes 6-7 (the magic) of IG Control: 0x80 0x00 in big-endian, 0x00 0x80 in little-endian.
  const std::vector<Packet> one = {test::sessionIgControl()};
  const auto native = writeDatagram(one, false), swapped = writeDatagram(one, true);
  const auto& big = kLittleEndianMachine ? swapped : native;
  const auto& little = kLittleEndianMachine ? native : swapped;
  EXPECT_EQ(big[6], 0x80);
  EXPECT_EQ(big[7], 0x00);
  EXPECT_EQ(little[6], 0x00);
  EXPECT_EQ(little[7], 0x80);
}

TEST(CigiCodec, PacketIdsAndSizesAreTheStandards) {
  // ICD 3.3's table of packets: (ID, size in bytes).
  const std::pair<PacketId, size_t> table[] = {
      {PacketId::igControl, 24},          {PacketId::entityControl, 48},
      {PacketId::componentControl, 32},   {PacketId::shortComponentControl, 16},
      {PacketId::rateControl, 32},        {PacketId::celestialSphereControl, 16},
      {PacketId::atmosphereControl, 32},  {PacketId::environmentalRegionControl, 48},
      {PacketId::weatherControl, 56},     {PacketId::viewControl, 32},
      {PacketId::viewDefinition, 32},     {PacketId::hatHotRequest, 32},
      {PacketId::losSegmentRequest, 64},  {PacketId::startOfFrame, 24},
      {PacketId::hatHotResponse, 16},     {PacketId::losResponse, 16}};
  for (auto [id, size] : table) EXPECT_EQ(packetSize(id), size) << int(id);
  EXPECT_EQ(int(PacketId::startOfFrame), 101);
  EXPECT_EQ(packetSize(PacketId(3)), 0u);  // Conformal Clamped Entity Control: not decoded
  EXPECT_EQ(packetId(test::sessionComponentControl(true)), PacketId::shortComponentControl);
  EXPECT_EQ(packetId(test::sessionComponentControl(false)), PacketId::componentControl);
}

// ---- The ICD's layouts, byte by byte -------------------------------------------------------

// IG Control of test::sessionIgControl(), big-endian, as the ICD lays it out.
const std::vector<uint8_t> kIgControlBigEndian = {
    1, 24,       // packet ID, size
    3,           // major version
    0xf9,        // database -7
    0x3e,        // bits 0-1 mode 2 (debug), bit 2 timestamp valid, bit 3 extrapolation, 4-7 minor 3
    0,           // reserved
    0x80, 0x00,  // byte-swap magic
    0x00, 0x01, 0xe2, 0x40,  // host frame 123456
    0x00, 0x0f, 0x12, 0x06,  // timestamp 987654
    0x00, 0x01, 0xe2, 0x08,  // last IG frame 123400
    0, 0, 0, 0};             // reserved

// Entity Control of test::sessionEntityControl(), big-endian.
const std::vector<uint8_t> kEntityControlBigEndian = {
    2, 48,        // packet ID, size
    0x10, 0x92,   // entity 4242
    0x5e,  // bits 0-1 state 2 (destroyed), 2 attached, 3 collision, 4 inherit alpha, 5-6 clamp 2
    0x1d,  // bits 0-3 animation flags 0xd, bit 4 extrapolation
    77,    // alpha
    0,     // reserved
    0x0c, 0x3b,  // entity type 3131
    0x00, 0x11,  // parent 17
    0xc1, 0x48, 0x00, 0x00,  // roll -12.5
    0x40, 0x50, 0x00, 0x00,  // pitch 3.25
    0x43, 0x87, 0xe0, 0x00,  // yaw 271.75
    0x40, 0x42, 0xd0, 0, 0, 0, 0, 0,  // latitude 37.625
    0xc0, 0x5e, 0x98, 0, 0, 0, 0, 0,  // longitude -122.375
    0x40, 0x93, 0x4a, 0, 0, 0, 0, 0};  // altitude 1234.5

// The same packets little-endian: each multi-byte field reversed in place.
std::vector<uint8_t> littleEndian(std::vector<uint8_t> bytes,
                                  std::initializer_list<std::pair<size_t, size_t>> fields) {
  for (auto [at, size] : fields) std::reverse(bytes.begin() + at, bytes.begin() + at + size);
  return bytes;
}
const auto kIgControlFields = {std::pair<size_t, size_t>{6, 2}, {8, 4}, {12, 4}, {16, 4}};
const auto kEntityControlFields = {std::pair<size_t, size_t>{2, 2}, {8, 2}, {10, 2}, {12, 4},
                                   {16, 4}, {20, 4}, {24, 8}, {32, 8}, {40, 8}};

std::vector<uint8_t> concat(std::vector<uint8_t> a, const std::vector<uint8_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

TEST(CigiCodec, IgControlAndEntityControlAreWrittenAsTheIcdLaysThemOut) {
  const std::vector<Packet> packets = {test::sessionIgControl(), test::sessionEntityControl()};
  const auto big = concat(kIgControlBigEndian, kEntityControlBigEndian);
  const auto little = concat(littleEndian(kIgControlBigEndian, kIgControlFields),
                             littleEndian(kEntityControlBigEndian, kEntityControlFields));
  EXPECT_EQ(writeDatagram(packets, kLittleEndianMachine), big);
  EXPECT_EQ(writeDatagram(packets, !kLittleEndianMachine), little);
}

TEST(CigiCodec, HandBuiltIgControlAndEntityControlAreReadInEitherByteOrder) {
  const auto big = concat(kIgControlBigEndian, kEntityControlBigEndian);
  const auto little = concat(littleEndian(kIgControlBigEndian, kIgControlFields),
                             littleEndian(kEntityControlBigEndian, kEntityControlFields));
  for (const auto* bytes : {&big, &little}) {
    const auto parsed = parseDatagram(*bytes);
    ASSERT_TRUE(parsed.ok()) << parsed.error().message;
    EXPECT_EQ(parsed->swapped, (bytes == &big) == kLittleEndianMachine);
    ASSERT_EQ(parsed->packets.size(), 2u);
    const auto& ig = std::get<IgControl>(parsed->packets[0]);
    EXPECT_EQ(ig.database, -7);
    EXPECT_EQ(ig.mode, IgMode::debug);
    EXPECT_TRUE(ig.timestampValid);
    EXPECT_TRUE(ig.extrapolation);
    EXPECT_EQ(ig.minorVersion, 3);
    EXPECT_EQ(ig.hostFrame, 123456u);
    EXPECT_EQ(ig.timestamp, 987654u);
    EXPECT_EQ(ig.lastIgFrame, 123400u);
    const auto& e = std::get<EntityControl>(parsed->packets[1]);
    EXPECT_EQ(e.entity, 4242);
    EXPECT_EQ(e.state, EntityState::destroyed);
    EXPECT_TRUE(e.attached && e.collisionDetection && e.inheritAlpha && e.extrapolation);
    EXPECT_EQ(e.groundClamp, 2);
    EXPECT_EQ(e.animationFlags, 0xd);
    EXPECT_EQ(e.alpha, 77);
    EXPECT_EQ(e.type, 3131);
    EXPECT_EQ(e.parent, 17);
    EXPECT_EQ(e.roll, -12.5f);
    EXPECT_EQ(e.pitch, 3.25f);
    EXPECT_EQ(e.yaw, 271.75f);
    EXPECT_EQ(e.latOrX, 37.625);
    EXPECT_EQ(e.lonOrY, -122.375);
    EXPECT_EQ(e.altOrZ, 1234.5);
  }
}

TEST(CigiCodec, EachEntityControlBitLandsWhereTheIcdNumbersIt) {
  // One flag at a time, so that two swapped bits cannot pass together.
  struct Case {
    void (*set)(EntityControl&);
    uint8_t byte4, byte5;
  };
  const Case cases[] = {
      {[](EntityControl& e) { e.state = EntityState::active; }, 0x01, 0},
      {[](EntityControl& e) { e.attached = true; }, 0x04, 0},
      {[](EntityControl& e) { e.collisionDetection = true; }, 0x08, 0},
      {[](EntityControl& e) { e.inheritAlpha = true; }, 0x10, 0},
      {[](EntityControl& e) { e.groundClamp = 1; }, 0x20, 0},
      {[](EntityControl& e) { e.animationFlags = 1; }, 0, 0x01},
      {[](EntityControl& e) { e.extrapolation = true; }, 0, 0x10},
  };
  for (const Case& c : cases) {
    EntityControl e{.state = EntityState::inactive};
    c.set(e);
    const std::vector<Packet> packets = {IgControl{}, e};
    const auto bytes = writeDatagram(packets);
    EXPECT_EQ(bytes[24 + 4], c.byte4);
    EXPECT_EQ(bytes[24 + 5], c.byte5);
  }
}

TEST(CigiCodec, RateControlsWorldCoordinatesClearTheLocalBit) {
  // ICD 3.3 Rate Control byte 5 bit 1: 0 world/parent, 1 local (the entity's body).
  const std::vector<Packet> world = {IgControl{}, RateControl{.worldCoordinates = true}};
  const std::vector<Packet> local = {IgControl{}, RateControl{.worldCoordinates = false}};
  EXPECT_EQ(writeDatagram(world)[24 + 5], 0x00);
  EXPECT_EQ(writeDatagram(local)[24 + 5], 0x02);
}

// ---- Skipped and malformed datagrams -------------------------------------------------------

// A packet of `id` and `size` bytes (size in byte 1), its body filled with `fill`.
std::vector<uint8_t> rawPacket(uint8_t id, size_t size, uint8_t fill = 0x5a) {
  std::vector<uint8_t> p(size, fill);
  p[0] = id;
  p[1] = uint8_t(size);
  return p;
}

TEST(CigiCodec, UnknownAndUndecodedIdsAreSkippedBySizeAndCounted) {
  std::vector<uint8_t> bytes = writeDatagram(std::vector<Packet>{test::sessionIgControl()});
  bytes = concat(bytes, rawPacket(3, 24));    // Conformal Clamped Entity Control
  bytes = concat(bytes, writeDatagram(std::vector<Packet>{test::sessionEntityControl()}));
  bytes = concat(bytes, rawPacket(6, 32));    // Articulated Part Control
  bytes = concat(bytes, rawPacket(201, 248));  // user-defined, the largest size
  bytes = concat(bytes, rawPacket(99, 8));    // no such packet
  const auto parsed = parseDatagram(bytes);
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  EXPECT_EQ(parsed->skipped, 4u);
  ASSERT_EQ(parsed->packets.size(), 2u);
  EXPECT_TRUE(parsed->packets[1] == Packet(test::sessionEntityControl()));
}

struct Malformed {
  const char* why;
  std::vector<uint8_t> bytes;
  const char* position;
};

std::vector<Malformed> malformedDatagrams() {
  const auto ig = writeDatagram(std::vector<Packet>{test::sessionIgControl()});
  const auto entity = writeDatagram(std::vector<Packet>{test::sessionEntityControl()});
  auto setByte = [](std::vector<uint8_t> b, size_t at, uint8_t v) {
    b[at] = v;
    return b;
  };
  auto wrongSizeEntity = rawPacket(2, 56);
  return {
      {"empty", {}, "byte 0"},
      {"one byte: fewer than a packet header", {1}, "byte 0"},
      {"a lone byte after IG Control", concat(ig, {2}), "byte 24"},
      {"size 0", concat(ig, {2, 0, 0, 0, 0, 0, 0, 0}), "byte 25"},
      {"size not a multiple of 8", concat(ig, rawPacket(2, 12)), "byte 25"},
      {"first packet's size 0", setByte(ig, 1, 0), "byte 1"},
      {"packet runs past the end", concat(ig, std::vector<uint8_t>(entity.begin(),
                                                                   entity.end() - 8)),
       "byte 25"},
      {"first packet is Entity Control", entity, "byte 0"},
      {"first packet is an unknown ID", rawPacket(200, 24), "byte 0"},
      {"major version 2", setByte(ig, 2, 2), "byte 2"},
      {"major version 4", setByte(ig, 2, 4), "byte 2"},
      {"bad magic", setByte(ig, 6, 0x81), "byte 6"},
      {"zero magic", setByte(setByte(ig, 6, 0), 7, 0), "byte 6"},
      {"IG Control of 32 bytes", concat(setByte(ig, 1, 32), std::vector<uint8_t>(8, 0)),
       "byte 1"},
      {"Entity Control of 56 bytes", concat(ig, wrongSizeEntity), "byte 25"},
      {"LOS Response of 8 bytes after Start of Frame",
       concat(writeDatagram(std::vector<Packet>{StartOfFrame{}}), rawPacket(104, 8)), "byte 25"},
  };
}

TEST(CigiCodec, EachMalformedDatagramIsAnErrorAtItsByte) {
  for (const Malformed& m : malformedDatagrams()) {
    const auto parsed = parseDatagram(m.bytes);
    ASSERT_FALSE(parsed.ok()) << m.why;
    EXPECT_EQ(parsed.error().position, m.position) << m.why << ": " << parsed.error().message;
    EXPECT_FALSE(parsed.error().message.empty()) << m.why;
    EXPECT_EQ(parsed.error().message.find('\n'), std::string::npos) << m.why;
  }
}

TEST(CigiCodec, EveryTruncationIsAnErrorOrAPrefixOfThePackets) {
  for (bool swap : {false, true}) {
    const auto packets = hostPackets();
    const auto bytes = writeDatagram(packets, swap);
    // The packet boundaries: a datagram cut there is a valid, shorter one.
    std::vector<size_t> ends;
    size_t end = 0;
    for (const Packet& p : packets) ends.push_back(end += packetSize(packetId(p)));
    for (size_t n = 0; n < bytes.size(); ++n) {
      const auto parsed = parseDatagram(std::span(bytes).first(n));
      const auto boundary = std::find(ends.begin(), ends.end(), n);
      if (boundary == ends.end()) {
        EXPECT_FALSE(parsed.ok()) << "cut at " << n;
        continue;
      }
      ASSERT_TRUE(parsed.ok()) << "cut at " << n;
      const size_t count = size_t(boundary - ends.begin()) + 1;
      ASSERT_EQ(parsed->packets.size(), count);
      for (size_t i = 0; i < count; ++i) EXPECT_TRUE(parsed->packets[i] == packets[i]);
    }
  }
}

TEST(CigiCodec, OverwritingAnyByteNeverCrashes) {
  // A small deterministic cousin of fuzz/fuzz_cigi.cpp: each byte of both datagrams set to a few
  // telling values; whatever is decoded stays within the datagram's bounds.
  for (const auto& packets : {hostPackets(), igPackets()}) {
    const auto bytes = writeDatagram(packets);
    for (size_t at = 0; at < bytes.size(); ++at) {
      for (uint8_t v : {0x00, 0x01, 0x07, 0x08, 0x80, 0xf8, 0xff}) {
        auto mutated = bytes;
        mutated[at] = v;
        const auto parsed = parseDatagram(mutated);
        if (parsed.ok()) {
          EXPECT_LE(parsed->packets.size() + parsed->skipped, mutated.size() / 8);
        }
      }
    }
  }
}

}  // namespace
}  // namespace sv::cigi
