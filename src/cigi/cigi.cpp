// Based on: CIGI ICD 3.3 (SISO-STD-013-2014, Common Image Generator Interface, the packet
// tables of its §4); Wireshark's packet-cigi.c (its cigi3_3_* and cigi3_2_* dissectors) as the
// cross-check of every byte offset and bit mask. No code is taken from either.
//
// One layout function per packet names each field's byte offset and bits once; it is run by a
// Decoder (wire → struct) or an Encoder (struct → wire), so reading and writing cannot drift
// apart. The hand-built byte arrays of tests/cigi/cigi_test.cpp and the tshark check pin the
// layouts themselves.
#include "synthvis/cigi.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <iterator>
#include <optional>
#include <variant>

namespace sv::cigi {
namespace {

// The byte-swap magic as this machine reads it when the sender used the other byte order.
constexpr uint16_t kSwappedMagic = 0x0080;
// Every CIGI packet starts with its ID (byte 0) and its size in bytes (byte 1).
constexpr size_t kHeaderSize = 2;

// Reads fields from one packet's bytes (already known to be packetSize long).
class Decoder {
 public:
  Decoder(const uint8_t* packet, bool swap) : p_(packet), swap_(swap) {}

  // A whole-byte field (1, 2, 4 or 8 bytes) at byte `at`, in the sender's byte order.
  template <class T>
  void word(size_t at, T& value) const {
    uint8_t b[sizeof(T)];
    std::memcpy(b, p_ + at, sizeof(T));
    if (swap_) std::reverse(b, b + sizeof(T));
    std::memcpy(&value, b, sizeof(T));
  }
  // `count` bits of byte `at` from bit `first` (bit 0 the least significant, as the ICD counts).
  template <class T>
  void bits(size_t at, int first, int count, T& value) const {
    value = static_cast<T>((p_[at] >> first) & ((1u << count) - 1));
  }
  // The version and the magic: checked by parseDatagram before any layout runs.
  void fixed8(size_t, uint8_t) const {}
  void fixed16(size_t, uint16_t) const {}

 private:
  const uint8_t* p_;
  bool swap_;
};

// Writes fields into one packet's bytes, zeroed beforehand (the ICD's reserved bytes are 0).
class Encoder {
 public:
  Encoder(uint8_t* packet, bool swap) : p_(packet), swap_(swap) {}

  template <class T>
  void word(size_t at, const T& value) const {
    uint8_t b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if (swap_) std::reverse(b, b + sizeof(T));
    std::memcpy(p_ + at, b, sizeof(T));
  }
  template <class T>
  void bits(size_t at, int first, int count, const T& value) const {
    const unsigned mask = (1u << count) - 1;
    p_[at] |= static_cast<uint8_t>((static_cast<unsigned>(value) & mask) << first);
  }
  void fixed8(size_t at, uint8_t value) const { word(at, value); }
  void fixed16(size_t at, uint16_t value) const { word(at, value); }

 private:
  uint8_t* p_;
  bool swap_;
};

// ---- The layouts (ICD 3.3 §4.1 host → IG, §4.2 IG → host) ------------------------------------
// Offsets are from the packet's byte 0 (its ID); bytes 0-1 are written by writeDatagram.

// Whole-byte fields that follow one another from byte `at` (each as long as its type: the ICD's
// runs of floats and doubles).
template <class Io, class... T>
void run(const Io& io, size_t at, T&... fields) {
  ((io.word(at, fields), at += sizeof(T)), ...);
}

// IG Control and Start of Frame open a datagram alike: the major version at byte 2, the database
// at 3, a flags byte (bits 0-1 the IG mode, bit 2 timestamp valid, bit 3 a flag of the packet's
// own, bits 4-7 the minor version), the byte-swap magic at 6-7, and three 32-bit words from byte 8
// (the sender's frame, the timestamp, the last frame it received).
template <class Io, class P>
void datagramHead(const Io& io, size_t flags, P& p, bool& bit3, uint32_t& frame,
                  uint32_t& lastFrame) {
  io.fixed8(2, kMajorVersion);
  io.word(3, p.database);
  io.bits(flags, 0, 2, p.mode);
  io.bits(flags, 2, 1, p.timestampValid);
  io.bits(flags, 3, 1, bit3);
  io.bits(flags, 4, 4, p.minorVersion);
  io.fixed16(6, kByteSwapMagic);
  run(io, 8, frame, p.timestamp, lastFrame);
}

template <class Io>
void layout(const Io& io, IgControl& p) {
  datagramHead(io, 4, p, p.extrapolation, p.hostFrame, p.lastIgFrame);
}

template <class Io>
void layout(const Io& io, EntityControl& p) {
  io.word(2, p.entity);
  io.bits(4, 0, 2, p.state);
  io.bits(4, 2, 1, p.attached);
  io.bits(4, 3, 1, p.collisionDetection);
  io.bits(4, 4, 1, p.inheritAlpha);
  io.bits(4, 5, 2, p.groundClamp);
  io.bits(5, 0, 4, p.animationFlags);
  io.bits(5, 4, 1, p.extrapolation);
  io.word(6, p.alpha);
  run(io, 8, p.type, p.parent, p.roll, p.pitch, p.yaw, p.latOrX, p.lonOrY, p.altOrZ);
}

// Component Control and Short Component Control: the same head, six or two data words.
template <class Io>
void layout(const Io& io, ComponentControl& p) {
  run(io, 2, p.component, p.instance);
  io.bits(6, 0, 6, p.componentClass);
  io.word(7, p.state);
  const int words = p.isShort ? 2 : 6;
  for (int i = 0; i < words; ++i) io.word(8 + 4 * size_t(i), p.data[i]);
}

template <class Io>
void layout(const Io& io, RateControl& p) {
  io.word(2, p.entity);
  io.word(4, p.part);
  io.bits(5, 0, 1, p.applyToPart);
  // The wire bit says "local" (1) or "world/parent" (0); the struct's flag is its negation.
  bool local = !p.worldCoordinates;
  io.bits(5, 1, 1, local);
  p.worldCoordinates = !local;
  run(io, 8, p.x, p.y, p.z, p.roll, p.pitch, p.yaw);
}

template <class Io>
void layout(const Io& io, CelestialSphereControl& p) {
  run(io, 2, p.hour, p.minute);
  io.bits(4, 0, 1, p.ephemeris);
  io.bits(4, 1, 1, p.sun);
  io.bits(4, 2, 1, p.moon);
  io.bits(4, 3, 1, p.starField);
  io.bits(4, 4, 1, p.dateValid);
  run(io, 8, p.date, p.starIntensity);
}

template <class Io>
void layout(const Io& io, AtmosphereControl& p) {
  io.bits(2, 0, 1, p.modelEnabled);
  run(io, 3, p.humidity, p.temperature, p.visibility, p.windHorizontal, p.windVertical,
      p.windDirection, p.pressure);
}

template <class Io>
void layout(const Io& io, EnvironmentalRegionControl& p) {
  io.word(2, p.region);
  io.bits(4, 0, 2, p.state);
  io.bits(4, 2, 4, p.mergeFlags);
  run(io, 8, p.lat, p.lon, p.sizeX, p.sizeY, p.cornerRadius, p.rotation, p.transition);
}

template <class Io>
void layout(const Io& io, WeatherControl& p) {
  run(io, 2, p.entityOrRegion, p.layer, p.humidity);
  io.bits(6, 0, 1, p.enabled);
  io.bits(6, 1, 1, p.scud);
  io.bits(6, 2, 1, p.randomWinds);
  io.bits(6, 3, 1, p.randomLightning);
  io.bits(6, 4, 4, p.cloudType);
  io.bits(7, 0, 2, p.scope);
  io.bits(7, 2, 3, p.severity);
  run(io, 8, p.temperature, p.visibility, p.scudFrequency, p.coverage, p.baseElevation,
      p.thickness, p.transitionBand, p.windHorizontal, p.windVertical, p.windDirection,
      p.pressure, p.aerosol);
}

template <class Io>
void layout(const Io& io, ViewControl& p) {
  run(io, 2, p.view, p.group);
  io.bits(5, 0, 6, p.enable);
  run(io, 6, p.entity, p.x, p.y, p.z, p.roll, p.pitch, p.yaw);
}

template <class Io>
void layout(const Io& io, ViewDefinition& p) {
  run(io, 2, p.view, p.group);
  io.bits(5, 0, 6, p.enable);
  io.bits(5, 6, 2, p.mirror);
  io.bits(6, 0, 3, p.pixelReplication);
  io.bits(6, 3, 1, p.orthographic);
  io.bits(6, 4, 1, p.reorder);
  io.bits(6, 5, 3, p.viewType);
  run(io, 8, p.nearPlane, p.farPlane, p.left, p.right, p.top, p.bottom);
}

template <class Io>
void layout(const Io& io, HatHotRequest& p) {
  io.word(2, p.id);
  io.bits(4, 0, 2, p.type);
  io.bits(4, 2, 1, p.entityCoordinates);
  run(io, 5, p.updatePeriod, p.entity, p.latOrX, p.lonOrY, p.altOrZ);
}

template <class Io>
void layout(const Io& io, LosSegmentRequest& p) {
  io.word(2, p.id);
  io.bits(4, 0, 1, p.extended);
  io.bits(4, 1, 1, p.sourceEntityCoordinates);
  io.bits(4, 2, 1, p.destinationEntityCoordinates);
  io.bits(4, 3, 1, p.responseEntityCoordinates);
  io.bits(4, 4, 1, p.destinationEntityValid);
  run(io, 5, p.alphaThreshold, p.sourceEntity);
  run(io, 8, p.source[0], p.source[1], p.source[2], p.destination[0], p.destination[1],
      p.destination[2], p.materialMask, p.updatePeriod);
  io.word(62, p.destinationEntity);
}

template <class Io>
void layout(const Io& io, StartOfFrame& p) {
  datagramHead(io, 5, p, p.earthReferenceModel, p.igFrame, p.lastHostFrame);
  io.word(4, p.igStatus);
}

template <class Io>
void layout(const Io& io, HatHotResponse& p) {
  io.word(2, p.id);
  io.bits(4, 0, 1, p.valid);
  io.bits(4, 1, 1, p.hot);
  io.bits(4, 4, 4, p.hostFrameLsn);
  io.word(8, p.height);
}

template <class Io>
void layout(const Io& io, LosResponse& p) {
  io.word(2, p.id);
  io.bits(4, 0, 1, p.valid);
  io.bits(4, 1, 1, p.entityValid);
  io.bits(4, 2, 1, p.visible);
  io.bits(4, 4, 4, p.hostFrameLsn);
  run(io, 5, p.count, p.entity, p.range);
}

template <class P>
Packet decodeAs(const uint8_t* packet, bool swap, P p = {}) {
  layout(Decoder(packet, swap), p);
  return p;
}

// The decoded packet of a known ID (the size already checked), or nothing for other IDs.
std::optional<Packet> decode(PacketId id, const uint8_t* packet, bool swap) {
  switch (id) {
    case PacketId::igControl: return decodeAs<IgControl>(packet, swap);
    case PacketId::entityControl: return decodeAs<EntityControl>(packet, swap);
    case PacketId::componentControl: return decodeAs<ComponentControl>(packet, swap);
    case PacketId::shortComponentControl:
      return decodeAs(packet, swap, ComponentControl{.isShort = true});
    case PacketId::rateControl: return decodeAs<RateControl>(packet, swap);
    case PacketId::celestialSphereControl: return decodeAs<CelestialSphereControl>(packet, swap);
    case PacketId::atmosphereControl: return decodeAs<AtmosphereControl>(packet, swap);
    case PacketId::environmentalRegionControl:
      return decodeAs<EnvironmentalRegionControl>(packet, swap);
    case PacketId::weatherControl: return decodeAs<WeatherControl>(packet, swap);
    case PacketId::viewControl: return decodeAs<ViewControl>(packet, swap);
    case PacketId::viewDefinition: return decodeAs<ViewDefinition>(packet, swap);
    case PacketId::hatHotRequest: return decodeAs<HatHotRequest>(packet, swap);
    case PacketId::losSegmentRequest: return decodeAs<LosSegmentRequest>(packet, swap);
    case PacketId::startOfFrame: return decodeAs<StartOfFrame>(packet, swap);
    case PacketId::hatHotResponse: return decodeAs<HatHotResponse>(packet, swap);
    case PacketId::losResponse: return decodeAs<LosResponse>(packet, swap);
  }
  return std::nullopt;
}

Error errorAt(size_t byte, std::string message) {
  return Error{"", fmt::format("byte {}", byte), std::move(message)};
}

}  // namespace

size_t packetSize(PacketId id) {
  switch (id) {
    case PacketId::igControl: return 24;
    case PacketId::entityControl: return 48;
    case PacketId::componentControl: return 32;
    case PacketId::shortComponentControl: return 16;
    case PacketId::rateControl: return 32;
    case PacketId::celestialSphereControl: return 16;
    case PacketId::atmosphereControl: return 32;
    case PacketId::environmentalRegionControl: return 48;
    case PacketId::weatherControl: return 56;
    case PacketId::viewControl: return 32;
    case PacketId::viewDefinition: return 32;
    case PacketId::hatHotRequest: return 32;
    case PacketId::losSegmentRequest: return 64;
    case PacketId::startOfFrame: return 24;
    case PacketId::hatHotResponse: return 16;
    case PacketId::losResponse: return 16;
  }
  return 0;
}

PacketId packetId(const Packet& packet) {
  // The variant's alternatives in order; Component Control's size depends on the packet.
  static constexpr PacketId kIds[] = {
      PacketId::igControl,         PacketId::entityControl,
      PacketId::componentControl,  PacketId::rateControl,
      PacketId::celestialSphereControl, PacketId::atmosphereControl,
      PacketId::environmentalRegionControl, PacketId::weatherControl,
      PacketId::viewControl,       PacketId::viewDefinition,
      PacketId::hatHotRequest,     PacketId::losSegmentRequest,
      PacketId::startOfFrame,      PacketId::hatHotResponse,
      PacketId::losResponse};
  static_assert(std::size(kIds) == std::variant_size_v<Packet>);
  if (const auto* c = std::get_if<ComponentControl>(&packet); c && c->isShort) {
    return PacketId::shortComponentControl;
  }
  return kIds[packet.index()];
}

std::vector<uint8_t> writeDatagram(std::span<const Packet> packets, bool swap) {
  std::vector<uint8_t> out;
  for (const Packet& packet : packets) {
    const PacketId id = packetId(packet);
    const size_t size = packetSize(id);
    const size_t at = out.size();
    out.resize(at + size, 0);
    out[at] = static_cast<uint8_t>(id);
    out[at + 1] = static_cast<uint8_t>(size);
    // A copy, since a layout takes its struct by non-const reference (the Decoder writes it).
    std::visit([&](auto p) { layout(Encoder(out.data() + at, swap), p); }, packet);
  }
  return out;
}

Result<Datagram> parseDatagram(std::span<const uint8_t> bytes) {
  if (bytes.size() < kHeaderSize) {
    return errorAt(0, fmt::format("{} bytes: fewer than a packet header", bytes.size()));
  }
  Datagram datagram;
  // A packet is at least 8 bytes: this bounds what the vector can grow to (≤ 8 K for 64 KiB).
  datagram.packets.reserve(bytes.size() / 8);
  size_t at = 0;
  while (at < bytes.size()) {
    // Step 1: the packet's header, its size, and that it fits.
    if (bytes.size() - at < kHeaderSize) {
      return errorAt(at, fmt::format("{} bytes left: fewer than a packet header",
                                     bytes.size() - at));
    }
    const uint8_t id = bytes[at], size = bytes[at + 1];
    if (size == 0 || size % 8 != 0) {
      return errorAt(at + 1, fmt::format("packet {} has size {}, not a positive multiple of 8",
                                         id, size));
    }
    if (size > bytes.size() - at) {
      return errorAt(at + 1, fmt::format("packet {} of {} bytes runs past the datagram's end "
                                         "({} bytes left)", id, size, bytes.size() - at));
    }
    const uint8_t* packet = bytes.data() + at;
    // Step 2: the first packet says who sent the datagram, which version, and the byte order.
    if (at == 0) {
      if (id != uint8_t(PacketId::igControl) && id != uint8_t(PacketId::startOfFrame)) {
        return errorAt(0, fmt::format("first packet has ID {}, not IG Control (1) or Start of "
                                      "Frame (101)", id));
      }
      if (size != packetSize(PacketId(id))) {
        return errorAt(1, fmt::format("{} of {} bytes, CIGI 3.3 says {}",
                                      id == 1 ? "IG Control" : "Start of Frame", size,
                                      packetSize(PacketId(id))));
      }
      if (packet[2] != kMajorVersion) {
        return errorAt(2, fmt::format("CIGI major version {}, not {}", packet[2], kMajorVersion));
      }
      uint16_t magic;
      std::memcpy(&magic, packet + 6, 2);
      if (magic != kByteSwapMagic && magic != kSwappedMagic) {
        return errorAt(6, fmt::format("byte-swap magic {:#06x} (bytes {:#04x} {:#04x}), not "
                                      "0x8000 in either byte order", magic, packet[6], packet[7]));
      }
      datagram.swapped = magic == kSwappedMagic;
    }
    // Step 3: a known packet of its standard size is decoded; other IDs are skipped by size.
    const size_t expected = packetSize(PacketId(id));
    if (expected == 0) {
      ++datagram.skipped;
    } else if (size != expected) {
      return errorAt(at + 1, fmt::format("packet {} of {} bytes, CIGI 3.3 says {}", id, size,
                                         expected));
    } else {
      datagram.packets.push_back(*decode(PacketId(id), packet, datagram.swapped));
    }
    at += size;
  }
  return datagram;
}

}  // namespace sv::cigi
