// A test session: every packet the codec decodes, each field set to a value no other field has
// (and no default), so that a field written to the wrong place or not at all shows. Floating-point
// values are exact in binary and short in decimal, so that tshark prints them exactly.
#pragma once

#include <vector>

#include "synthvis/cigi.h"

namespace sv::cigi::test {

inline IgControl sessionIgControl() {
  return IgControl{.database = -7, .mode = IgMode::debug, .timestampValid = true,
                   .extrapolation = true, .minorVersion = kMinorVersion, .hostFrame = 123456,
                   .timestamp = 987654, .lastIgFrame = 123400};
}

inline EntityControl sessionEntityControl() {
  return EntityControl{.entity = 4242, .state = EntityState::destroyed, .attached = true,
                       .collisionDetection = true, .inheritAlpha = true, .groundClamp = 2,
                       .animationFlags = 0x0d, .extrapolation = true, .alpha = 77, .type = 3131,
                       .parent = 17, .roll = -12.5f, .pitch = 3.25f, .yaw = 271.75f,
                       .latOrX = 37.625, .lonOrY = -122.375, .altOrZ = 1234.5};
}

inline ComponentControl sessionComponentControl(bool isShort) {
  ComponentControl c{.isShort = isShort, .component = uint16_t(isShort ? 901 : 900),
                     .instance = uint16_t(isShort ? 51 : 50),
                     .componentClass = isShort ? ComponentClass::regionalLayeredWeather
                                               : ComponentClass::symbol,
                     .state = uint8_t(isShort ? 6 : 5)};
  for (int i = 0; i < (isShort ? 2 : 6); ++i) c.data[i] = 0x11223300u + uint32_t(i);
  return c;
}

inline RateControl sessionRateControl() {
  return RateControl{.entity = 4243, .part = 9, .applyToPart = true, .worldCoordinates = false,
                     .x = 1.5f, .y = -2.5f, .z = 3.5f, .roll = 10.25f, .pitch = -20.25f,
                     .yaw = 30.25f};
}

inline CelestialSphereControl sessionCelestial() {
  return CelestialSphereControl{.hour = 19, .minute = 41, .ephemeris = true, .sun = false,
                                .moon = true, .starField = false, .dateValid = true,
                                .date = 6152024, .starIntensity = 62.5f};
}

inline AtmosphereControl sessionAtmosphere() {
  return AtmosphereControl{.modelEnabled = true, .humidity = 64, .temperature = -3.5f,
                           .visibility = 8250.5f, .windHorizontal = 12.5f,
                           .windVertical = -0.75f, .windDirection = 245.5f,
                           .pressure = 1001.5f};
}

inline EnvironmentalRegionControl sessionRegion() {
  return EnvironmentalRegionControl{.region = 606, .state = 1, .mergeFlags = 0x0b, .lat = 47.25,
                                    .lon = 8.5, .sizeX = 5000.5f, .sizeY = 3000.25f,
                                    .cornerRadius = 250.5f, .rotation = 33.5f,
                                    .transition = 125.25f};
}

inline WeatherControl sessionWeather() {
  return WeatherControl{.entityOrRegion = 606, .layer = 3, .humidity = 88, .enabled = true,
                        .scud = false, .randomWinds = true, .randomLightning = true,
                        .cloudType = 9, .scope = 1, .severity = 4, .temperature = 2.5f,
                        .visibility = 1500.5f, .scudFrequency = 20.5f, .coverage = 75.25f,
                        .baseElevation = 900.5f, .thickness = 450.25f, .transitionBand = 50.5f,
                        .windHorizontal = 7.5f, .windVertical = 1.25f, .windDirection = 190.5f,
                        .pressure = 990.5f, .aerosol = 0.125f};
}

inline ViewControl sessionViewControl() {
  return ViewControl{.view = 12, .group = 4, .enable = 0x2d, .entity = 4242, .x = 0.5f,
                     .y = -1.25f, .z = -2.75f, .roll = 1.5f, .pitch = -4.5f, .yaw = 15.5f};
}

inline ViewDefinition sessionViewDefinition() {
  return ViewDefinition{.view = 12, .group = 4, .enable = 0x33, .mirror = 2,
                        .pixelReplication = 5, .orthographic = true, .reorder = true,
                        .viewType = 6, .nearPlane = 0.25f, .farPlane = 40000.5f, .left = -35.5f,
                        .right = 36.5f, .top = 21.25f, .bottom = -22.25f};
}

inline HatHotRequest sessionHatHotRequest() {
  return HatHotRequest{.id = 777, .type = HatHotType::extended, .entityCoordinates = true,
                       .updatePeriod = 3, .entity = 4242, .latOrX = 12.5, .lonOrY = -6.25,
                       .altOrZ = 100.75};
}

inline LosSegmentRequest sessionLosRequest() {
  return LosSegmentRequest{.id = 888, .extended = true, .sourceEntityCoordinates = false,
                           .destinationEntityCoordinates = true,
                           .responseEntityCoordinates = false, .destinationEntityValid = true,
                           .alphaThreshold = 128, .sourceEntity = 4242,
                           .source = {37.5, -122.25, 500.5},
                           .destination = {10.5, 20.25, -30.75}, .materialMask = 0xa5a5f00f,
                           .updatePeriod = 2, .destinationEntity = 4243};
}

inline StartOfFrame sessionStartOfFrame() {
  return StartOfFrame{.database = 5, .igStatus = 2, .mode = IgMode::operate,
                      .timestampValid = true, .earthReferenceModel = true,
                      .minorVersion = kMinorVersion, .igFrame = 654321, .timestamp = 4444,
                      .lastHostFrame = 123456};
}

inline HatHotResponse sessionHatHotResponse() {
  return HatHotResponse{.id = 777, .valid = true, .hot = true, .hostFrameLsn = 0x0a,
                        .height = 432.125};
}

inline LosResponse sessionLosResponse() {
  return LosResponse{.id = 888, .valid = true, .entityValid = true, .visible = false,
                     .hostFrameLsn = 0x06, .count = 3, .entity = 4243, .range = 2718.25};
}

// A host datagram with every host → IG packet the codec decodes, IG Control first.
inline std::vector<Packet> hostPackets() {
  return {sessionIgControl(),       sessionEntityControl(),   sessionComponentControl(false),
          sessionComponentControl(true), sessionRateControl(), sessionCelestial(),
          sessionAtmosphere(),      sessionRegion(),          sessionWeather(),
          sessionViewControl(),     sessionViewDefinition(),  sessionHatHotRequest(),
          sessionLosRequest()};
}

// An IG datagram: Start of Frame and the two responses.
inline std::vector<Packet> igPackets() {
  return {sessionStartOfFrame(), sessionHatHotResponse(), sessionLosResponse()};
}

}  // namespace sv::cigi::test
