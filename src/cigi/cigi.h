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
#pragma once

#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "synthvis/result.h"

namespace sv::cigi {

inline constexpr uint8_t kMajorVersion = 3;
// IG Control's and Start of Frame's minor version for CIGI 3.3.
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

struct IgControl {  // 24 bytes
  int8_t database = 0;  // 0: keep the loaded database
  IgMode mode = IgMode::operate;
  bool timestampValid = false;
  bool extrapolation = false;  // extrapolation/interpolation enable
  uint8_t minorVersion = kMinorVersion;
  uint32_t hostFrame = 0;
  uint32_t timestamp = 0;  // 10 µs ticks
  uint32_t lastIgFrame = 0;
};

enum class EntityState : uint8_t { inactive = 0, active = 1, destroyed = 2 };

struct EntityControl {  // 48 bytes
  uint16_t entity = 0;
  EntityState state = EntityState::active;
  bool attached = false;  // a child of `parent`, placed by offsets in its body frame
  bool collisionDetection = false;
  bool inheritAlpha = false;
  uint8_t groundClamp = 0;  // 0 none, 1 non-conformal, 2 conformal
  uint8_t animationFlags = 0;  // byte 5 as sent: direction, loop mode, state
  bool extrapolation = false;  // linear extrapolation/interpolation enable (byte 5, bit 4)
  uint8_t alpha = 255;
  uint16_t type = 0;  // the model table's key
  uint16_t parent = 0;
  float roll = 0, pitch = 0, yaw = 0;  // degrees
  // Top level: latitude, longitude (degrees), altitude (m); attached: x, y, z offsets (m) in the
  // parent's body frame (x forward, y right, z down).
  double latOrX = 0, lonOrY = 0, altOrZ = 0;
};

// Component Control (32 bytes, six data words) and Short Component Control (16 bytes, two).
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
};

struct RateControl {  // 32 bytes
  uint16_t entity = 0;
  uint8_t part = 0;
  bool applyToPart = false;
  bool worldCoordinates = false;  // coordinate system bit: 0 the parent's/world, 1 the entity's
  float x = 0, y = 0, z = 0;             // m/s
  float roll = 0, pitch = 0, yaw = 0;    // degrees/s
};

struct CelestialSphereControl {  // 16 bytes
  uint8_t hour = 12, minute = 0;
  bool ephemeris = false, sun = true, moon = false, starField = true, dateValid = false;
  uint32_t date = 0;  // MMDDYYYY
  float starIntensity = 100;  // percent
};

struct AtmosphereControl {  // 32 bytes
  bool modelEnabled = false;
  uint8_t humidity = 30;  // percent
  float temperature = 15;  // °C
  float visibility = 1e5f;  // m
  float windHorizontal = 0, windVertical = 0, windDirection = 0;
  float pressure = 1013.25f;  // mbar
};

struct EnvironmentalRegionControl {  // 48 bytes
  uint16_t region = 0;
  uint8_t state = 0;  // 0 inactive, 1 active, 2 destroyed
  uint8_t mergeFlags = 0;  // byte 4's merge bits as sent
  double lat = 0, lon = 0;
  float sizeX = 0, sizeY = 0, cornerRadius = 0, rotation = 0, transition = 0;
};

struct WeatherControl {  // 56 bytes
  uint16_t entityOrRegion = 0;
  uint8_t layer = 0;
  uint8_t humidity = 0;
  bool enabled = false, scud = false, randomWinds = false, randomLightning = false;
  uint8_t cloudType = 0;
  uint8_t scope = 0;  // 0 global, 1 regional, 2 entity
  uint8_t severity = 0;
  float temperature = 15, visibility = 1e5f, scudFrequency = 0, coverage = 0;
  float baseElevation = 0, thickness = 0, transitionBand = 0;
  float windHorizontal = 0, windVertical = 0, windDirection = 0, pressure = 1013.25f,
        aerosol = 0;
};

struct ViewControl {  // 32 bytes
  uint16_t view = 0;
  uint8_t group = 0;
  uint8_t enable = 0;  // bits: x, y, z offset, roll, pitch, yaw enable
  uint16_t entity = 0;
  float x = 0, y = 0, z = 0;           // m, in the entity's body frame
  float roll = 0, pitch = 0, yaw = 0;  // degrees
};

struct ViewDefinition {  // 32 bytes
  uint16_t view = 0;
  uint8_t group = 0;
  uint8_t enable = 0;  // bits: near, far, left, right, top, bottom enable
  uint8_t mirror = 0, pixelReplication = 0;
  bool orthographic = false;
  bool reorder = false;
  uint8_t viewType = 0;
  float nearPlane = 0.1f, farPlane = 1e5f;
  float left = -30, right = 30, top = 20, bottom = -20;  // half-angles, degrees
};

enum class HatHotType : uint8_t { hat = 0, hot = 1, extended = 2 };
struct HatHotRequest {  // 32 bytes
  uint16_t id = 0;
  HatHotType type = HatHotType::hat;
  bool entityCoordinates = false;  // offsets from `entity` instead of geodetic
  uint8_t updatePeriod = 0;
  uint16_t entity = 0;
  double latOrX = 0, lonOrY = 0, altOrZ = 0;
};

struct LosSegmentRequest {  // 64 bytes
  uint16_t id = 0;
  bool extended = false;
  bool sourceEntityCoordinates = false, destinationEntityCoordinates = false,
       responseEntityCoordinates = false, destinationEntityValid = false;
  uint8_t alphaThreshold = 0;
  uint16_t sourceEntity = 0;
  double source[3] = {}, destination[3] = {};  // lat, lon, alt or x, y, z
  uint32_t materialMask = 0;
  uint8_t updatePeriod = 0;
  uint16_t destinationEntity = 0;
};

// ---- IG → host -----------------------------------------------------------------------------

struct StartOfFrame {  // 24 bytes
  int8_t database = 0;
  uint8_t igStatus = 0;  // 0: normal
  IgMode mode = IgMode::operate;
  bool timestampValid = false;
  bool earthReferenceModel = false;  // 0: WGS 84
  uint8_t minorVersion = kMinorVersion;
  uint32_t igFrame = 0;
  uint32_t timestamp = 0;  // 10 µs ticks
  uint32_t lastHostFrame = 0;
};

struct HatHotResponse {  // 16 bytes
  uint16_t id = 0;
  bool valid = false;
  bool hot = false;  // the response's type: height of terrain (true) or above it (false)
  uint8_t hostFrameLsn = 0;  // the host frame's four low bits
  double height = 0;
};

struct LosResponse {  // 16 bytes
  uint16_t id = 0;
  bool valid = false, entityValid = false, visible = false;
  uint8_t hostFrameLsn = 0;
  uint8_t count = 1;  // responses to this request
  uint16_t entity = 0;
  double range = 0;  // m
};

using Packet = std::variant<IgControl, EntityControl, ComponentControl, RateControl,
                            CelestialSphereControl, AtmosphereControl,
                            EnvironmentalRegionControl, WeatherControl, ViewControl,
                            ViewDefinition, HatHotRequest, LosSegmentRequest, StartOfFrame,
                            HatHotResponse, LosResponse>;

struct Datagram {
  std::vector<Packet> packets;  // in the order sent
  size_t skipped = 0;           // packets of IDs this codec does not decode, skipped by size
  bool swapped = false;         // sent in the other byte order than this machine's
};

// Decodes one datagram. Errors (Error::position "byte N") say what is malformed.
Result<Datagram> parseDatagram(std::span<const uint8_t> bytes);

// Encodes packets into one datagram in this machine's byte order, or in the other with `swap`.
std::vector<uint8_t> writeDatagram(std::span<const Packet> packets, bool swap = false);

// The packet's ID and its size on the wire.
PacketId packetId(const Packet& packet);
size_t packetSize(PacketId id);

}  // namespace sv::cigi
