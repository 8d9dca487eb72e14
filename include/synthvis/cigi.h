// CIGI 3.3, the Common Image Generator Interface (SISO-STD-013; the Boeing/SISO interface
// control document), as an image generator speaks it: the packets synthvis reads from a host and
// the ones it answers with, decoded to plain values and encoded back. Packet IDs and sizes are the
// standard's; every multi-byte field is in the sender's byte order, which the receiver learns from
// the byte-swap magic (0x8000) of the datagram's first packet (IG Control from a host, Start of
// Frame from an IG): both orders are read, and a writer chooses one.
//
// A datagram is one frame's packets: it starts with IG Control (host → IG) or Start of Frame
// (IG → host). Packets of other IDs (and the ones this codec does not decode) are skipped by their
// size field and counted; a datagram that is not well formed — shorter than its packets say, a
// packet size of 0 or not a multiple of 8, the wrong first packet or version — is an error, never
// a crash (fuzz/fuzz_cigi.cpp).
//
// Bit fields are numbered from the least significant bit, as the ICD numbers them ("byte 4, bits
// 5-6"); each struct's comments name the byte and bits a field travels in. The layouts were checked
// against Wireshark's CIGI dissector (packet-cigi.c, its cigi3_3_* and cigi3_2_* functions, which
// it applies to minor versions 3 and 2) and tests/cigi/tshark_test.cpp holds it.
#pragma once

#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "synthvis/result.h"

namespace sv::cigi {

inline constexpr uint8_t kMajorVersion = 3;
// IG Control's (byte 4, bits 4-7) and Start of Frame's (byte 5, bits 4-7) minor version for
// CIGI 3.3; Wireshark's dissector reads 3 as 3.3 and 2 as 3.2 (3.0 and 3.1 had no such field).
inline constexpr uint8_t kMinorVersion = 3;
inline constexpr uint16_t kByteSwapMagic = 0x8000;
// The ports hosts and IGs conventionally use (CIGI's reference implementation): the IG listens on
// 8004 and answers to 8005.
inline constexpr uint16_t kIgPort = 8004, kHostPort = 8005;

// Packet IDs (the standard's table of packets).
enum class PacketId : uint8_t {
  igControl = 1,
  entityControl = 2,
  componentControl = 4,
  shortComponentControl = 5,
  rateControl = 8,
  celestialSphereControl = 9,
  atmosphereControl = 10,
  environmentalRegionControl = 11,
  weatherControl = 12,
  viewControl = 16,
  viewDefinition = 21,
  hatHotRequest = 24,
  losSegmentRequest = 25,
  startOfFrame = 101,
  hatHotResponse = 102,
  losResponse = 104,
};

// ---- host → IG -----------------------------------------------------------------------------

enum class IgMode : uint8_t { reset = 0, operate = 1, debug = 2, offlineMaintenance = 3 };

struct IgControl {      // 24 bytes; byte 2 the major version (3), bytes 6-7 the byte-swap magic
  int8_t database = 0;  // byte 3; 0: keep the loaded database
  IgMode mode = IgMode::operate;         // byte 4, bits 0-1
  bool timestampValid = false;           // byte 4, bit 2
  bool extrapolation = false;            // byte 4, bit 3: extrapolation/interpolation enable
  uint8_t minorVersion = kMinorVersion;  // byte 4, bits 4-7
  uint32_t hostFrame = 0;                // bytes 8-11
  uint32_t timestamp = 0;                // bytes 12-15, 10 µs ticks
  uint32_t lastIgFrame = 0;              // bytes 16-19

  friend bool operator==(const IgControl&, const IgControl&) = default;
};

enum class EntityState : uint8_t { inactive = 0, active = 1, destroyed = 2 };

struct EntityControl {                      // 48 bytes
  uint16_t entity = 0;                      // bytes 2-3
  EntityState state = EntityState::active;  // byte 4, bits 0-1
  bool attached = false;  // byte 4, bit 2: a child of `parent`, placed by offsets in its body frame
  bool collisionDetection = false;  // byte 4, bit 3
  bool inheritAlpha = false;        // byte 4, bit 4
  uint8_t groundClamp = 0;          // byte 4, bits 5-6: 0 none, 1 non-conformal, 2 conformal
  // Byte 5, bits 0-3 as sent: bit 0 animation direction, bit 1 loop mode, bits 2-3 state.
  uint8_t animationFlags = 0;
  bool extrapolation = false;          // linear extrapolation/interpolation enable (byte 5, bit 4)
  uint8_t alpha = 255;                 // byte 6
  uint16_t type = 0;                   // bytes 8-9: the model table's key
  uint16_t parent = 0;                 // bytes 10-11
  float roll = 0, pitch = 0, yaw = 0;  // bytes 12-23, degrees
  // Bytes 24-47. Top level: latitude, longitude (degrees), altitude (m); attached: x, y, z
  // offsets (m) in the parent's body frame (x forward, y right, z down).
  double latOrX = 0, lonOrY = 0, altOrZ = 0;

  friend bool operator==(const EntityControl&, const EntityControl&) = default;
};

// Component Control (32 bytes, six data words) and Short Component Control (16 bytes, two). Both:
// bytes 2-3 component, 4-5 instance, byte 6 bits 0-5 class, byte 7 state, then the data words
// from byte 8 (32-bit words in the sender's byte order, swapped as such).
enum class ComponentClass : uint8_t {
  entity = 0,
  view = 1,
  viewGroup = 2,
  sensor = 3,
  regionalSeaSurface = 4,
  regionalTerrainSurface = 5,
  regionalLayeredWeather = 6,
  globalSeaSurface = 7,
  globalTerrainSurface = 8,
  globalLayeredWeather = 9,
  atmosphere = 10,
  celestialSphere = 11,
  event = 12,
  system = 13,
  symbolSurface = 14,
  symbol = 15,
};
struct ComponentControl {
  bool isShort = false;
  uint16_t component = 0;
  uint16_t instance = 0;
  ComponentClass componentClass = ComponentClass::entity;
  uint8_t state = 0;
  uint32_t data[6] = {};  // a short one carries data[0] and data[1]

  friend bool operator==(const ComponentControl&, const ComponentControl&) = default;
};

struct RateControl {         // 32 bytes
  uint16_t entity = 0;       // bytes 2-3
  uint8_t part = 0;          // byte 4
  bool applyToPart = false;  // byte 5, bit 0
  // Byte 5, bit 1, the coordinate system: 0 world/parent, 1 the entity's body (local). This flag is
  // true when the bit is 0 (the name says what it means; the wire bit is its negation).
  bool worldCoordinates = false;
  float x = 0, y = 0, z = 0;           // bytes 8-19, m/s
  float roll = 0, pitch = 0, yaw = 0;  // bytes 20-31, degrees/s

  friend bool operator==(const RateControl&, const RateControl&) = default;
};

struct CelestialSphereControl {   // 16 bytes
  uint8_t hour = 12, minute = 0;  // bytes 2, 3
  // Byte 4, bits 0-4 in this order.
  bool ephemeris = false, sun = true, moon = false, starField = true, dateValid = false;
  uint32_t date = 0;          // bytes 8-11, MMDDYYYY as a decimal number
  float starIntensity = 100;  // bytes 12-15, percent

  friend bool operator==(const CelestialSphereControl&, const CelestialSphereControl&) = default;
};

struct AtmosphereControl {                                        // 32 bytes
  bool modelEnabled = false;                                      // byte 2, bit 0
  uint8_t humidity = 30;                                          // byte 3, percent
  float temperature = 15;                                         // bytes 4-7, °C
  float visibility = 1e5f;                                        // bytes 8-11, m
  float windHorizontal = 0, windVertical = 0, windDirection = 0;  // bytes 12-23, m/s, m/s, degrees
  float pressure = 1013.25f;                                      // bytes 24-27, mbar

  friend bool operator==(const AtmosphereControl&, const AtmosphereControl&) = default;
};

struct EnvironmentalRegionControl {  // 48 bytes
  uint16_t region = 0;               // bytes 2-3
  uint8_t state = 0;                 // byte 4, bits 0-1: 0 inactive, 1 active, 2 destroyed
  // Byte 4, bits 2-5, shifted down: bit 0 merge weather, 1 aerosols, 2 maritime, 3 terrestrial
  // surface conditions.
  uint8_t mergeFlags = 0;
  double lat = 0, lon = 0;  // bytes 8-23, degrees
  // Bytes 24-43: m, m, m, degrees, m (the transition perimeter).
  float sizeX = 0, sizeY = 0, cornerRadius = 0, rotation = 0, transition = 0;

  friend bool operator==(const EnvironmentalRegionControl&,
                         const EnvironmentalRegionControl&) = default;
};

struct WeatherControl {         // 56 bytes
  uint16_t entityOrRegion = 0;  // bytes 2-3
  uint8_t layer = 0;            // byte 4
  uint8_t humidity = 0;         // byte 5, percent
  bool enabled = false, scud = false, randomWinds = false, randomLightning = false;  // byte 6, 0-3
  uint8_t cloudType = 0;  // byte 6, bits 4-7
  uint8_t scope = 0;      // byte 7, bits 0-1: 0 global, 1 regional, 2 entity
  uint8_t severity = 0;   // byte 7, bits 2-4
  // Bytes 8-55, in this order: °C, m, %, %, m, m, m, m/s, m/s, degrees, mbar, g/m³.
  float temperature = 15, visibility = 1e5f, scudFrequency = 0, coverage = 0;
  float baseElevation = 0, thickness = 0, transitionBand = 0;
  float windHorizontal = 0, windVertical = 0, windDirection = 0, pressure = 1013.25f, aerosol = 0;

  friend bool operator==(const WeatherControl&, const WeatherControl&) = default;
};

struct ViewControl {                   // 32 bytes
  uint16_t view = 0;                   // bytes 2-3
  uint8_t group = 0;                   // byte 4
  uint8_t enable = 0;                  // byte 5, bits 0-5: x, y, z offset, roll, pitch, yaw enable
  uint16_t entity = 0;                 // bytes 6-7
  float x = 0, y = 0, z = 0;           // bytes 8-19, m, in the entity's body frame
  float roll = 0, pitch = 0, yaw = 0;  // bytes 20-31, degrees

  friend bool operator==(const ViewControl&, const ViewControl&) = default;
};

struct ViewDefinition {          // 32 bytes
  uint16_t view = 0;             // bytes 2-3
  uint8_t group = 0;             // byte 4
  uint8_t enable = 0;            // byte 5, bits 0-5: near, far, left, right, top, bottom enable
  uint8_t mirror = 0;            // byte 5, bits 6-7
  uint8_t pixelReplication = 0;  // byte 6, bits 0-2
  bool orthographic = false;     // byte 6, bit 3: the projection type
  bool reorder = false;          // byte 6, bit 4
  uint8_t viewType = 0;          // byte 6, bits 5-7
  float nearPlane = 0.1f, farPlane = 1e5f;               // bytes 8-15, m
  float left = -30, right = 30, top = 20, bottom = -20;  // bytes 16-31, half-angles, degrees

  friend bool operator==(const ViewDefinition&, const ViewDefinition&) = default;
};

enum class HatHotType : uint8_t { hat = 0, hot = 1, extended = 2 };
struct HatHotRequest {                // 32 bytes
  uint16_t id = 0;                    // bytes 2-3
  HatHotType type = HatHotType::hat;  // byte 4, bits 0-1
  bool entityCoordinates = false;     // byte 4, bit 2: offsets from `entity` instead of geodetic
  uint8_t updatePeriod = 0;           // byte 5
  uint16_t entity = 0;                // bytes 6-7
  double latOrX = 0, lonOrY = 0, altOrZ = 0;  // bytes 8-31

  friend bool operator==(const HatHotRequest&, const HatHotRequest&) = default;
};

struct LosSegmentRequest {  // 64 bytes
  uint16_t id = 0;          // bytes 2-3
  bool extended = false;    // byte 4, bit 0: the request type (basic 0, extended 1)
  // Byte 4, bits 1-4 in this order.
  bool sourceEntityCoordinates = false, destinationEntityCoordinates = false,
       responseEntityCoordinates = false, destinationEntityValid = false;
  uint8_t alphaThreshold = 0;                  // byte 5
  uint16_t sourceEntity = 0;                   // bytes 6-7
  double source[3] = {}, destination[3] = {};  // bytes 8-55: lat, lon, alt or x, y, z
  uint32_t materialMask = 0;                   // bytes 56-59
  uint8_t updatePeriod = 0;                    // byte 60
  uint16_t destinationEntity = 0;              // bytes 62-63

  friend bool operator==(const LosSegmentRequest&, const LosSegmentRequest&) = default;
};

// ---- IG → host -----------------------------------------------------------------------------

struct StartOfFrame {    // 24 bytes; byte 2 the major version (3), bytes 6-7 the byte-swap magic
  int8_t database = 0;   // byte 3
  uint8_t igStatus = 0;  // byte 4; 0: normal
  IgMode mode = IgMode::operate;         // byte 5, bits 0-1
  bool timestampValid = false;           // byte 5, bit 2
  bool earthReferenceModel = false;      // byte 5, bit 3; 0: WGS 84
  uint8_t minorVersion = kMinorVersion;  // byte 5, bits 4-7
  uint32_t igFrame = 0;                  // bytes 8-11
  uint32_t timestamp = 0;                // bytes 12-15, 10 µs ticks
  uint32_t lastHostFrame = 0;            // bytes 16-19

  friend bool operator==(const StartOfFrame&, const StartOfFrame&) = default;
};

struct HatHotResponse {  // 16 bytes
  uint16_t id = 0;       // bytes 2-3
  bool valid = false;    // byte 4, bit 0
  bool hot = false;      // byte 4, bit 1, the type: height of terrain (true) or above it (false)
  uint8_t hostFrameLsn = 0;  // byte 4, bits 4-7: the host frame's four low bits
  double height = 0;         // bytes 8-15, m

  friend bool operator==(const HatHotResponse&, const HatHotResponse&) = default;
};

struct LosResponse {                                         // 16 bytes
  uint16_t id = 0;                                           // bytes 2-3
  bool valid = false, entityValid = false, visible = false;  // byte 4, bits 0-2
  uint8_t hostFrameLsn = 0;                                  // byte 4, bits 4-7
  uint8_t count = 1;                                         // byte 5: responses to this request
  uint16_t entity = 0;                                       // bytes 6-7
  double range = 0;                                          // bytes 8-15, m

  friend bool operator==(const LosResponse&, const LosResponse&) = default;
};

using Packet = std::variant<IgControl, EntityControl, ComponentControl, RateControl,
                            CelestialSphereControl, AtmosphereControl, EnvironmentalRegionControl,
                            WeatherControl, ViewControl, ViewDefinition, HatHotRequest,
                            LosSegmentRequest, StartOfFrame, HatHotResponse, LosResponse>;

// Every struct compares field by field (operator==), as the round-trip tests do.
struct Datagram {
  std::vector<Packet> packets;  // in the order sent
  size_t skipped = 0;           // packets of IDs this codec does not decode, skipped by size
  bool swapped = false;         // sent in the other byte order than this machine's
};

// Decodes one datagram. Errors (Error::position "byte N", the offset of the offending byte; the
// file is left empty for the caller) say what is malformed. Fields are decoded as sent, without
// range checks (an enum may hold a value the ICD leaves undefined); reserved bytes are ignored.
Result<Datagram> parseDatagram(std::span<const uint8_t> bytes);

// Encodes packets into one datagram in this machine's byte order, or in the other with `swap`.
// IG Control and Start of Frame get the major version and the byte-swap magic; bits beyond a
// field's width are dropped; reserved bytes are zero. The caller puts IG Control (or Start of
// Frame) first.
std::vector<uint8_t> writeDatagram(std::span<const Packet> packets, bool swap = false);

// The packet's ID and its size on the wire (0 for an ID this codec does not decode).
PacketId packetId(const Packet& packet);
size_t packetSize(PacketId id);

}  // namespace sv::cigi
