// The conformance check (the acceptance): a capture of a test session — every packet
// type, in both byte orders — is decoded by Wireshark's CIGI dissector (tshark) with no malformed
// packet and no expert error, and with the values the test sent.
//
// Known quirks of the dissector (Wireshark 4.0's packet-cigi.c), where it shows a field otherwise
// than the ICD defines it; the test checks the ICD's meaning through what tshark shows:
//  - Component Data 1-6 are shown as raw bytes (FT_BYTES) in wire order, not as 32-bit words: a
//    word 0x11223300 sent little-endian shows as "00332211".
//  - Weather Control's Random Lightning Enable is an integer field, not a boolean (shows "1").
//  - The version-specific decoders are chosen from the minor version of the first IG Control or
//    Start of Frame; 3 picks the 3.3 decoders for Entity and Component Control and the 3.2 ones
//    (whose layouts 3.3 kept) for the rest.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cigi/pcap.h"
#include "cigi/session.h"
#include "support/temp_dir.h"

namespace sv::cigi {
namespace {

// tshark's full path, or "" when it is not on PATH.
std::string findTshark() {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/tshark";
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

// Runs a command, returns its standard output and sets `status` to its exit status.
std::string run(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    status = -1;
    return out;
  }
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
  const int raw = pclose(pipe);
  status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return out;
}

// The dissector on UDP ports 8004 and 8005 (it has no fixed port of its own).
std::string tsharkCommand(const std::string& tshark, const std::string& capture) {
  return "'" + tshark + "' -n -r '" + capture +
         "' -d udp.port==8004,cigi -d udp.port==8005,cigi";
}

// What one frame should show: field → the value as tshark prints it (numbers compared as
// numbers, other text exactly).
using Expected = std::map<std::string, std::string>;

template <class T>
std::string num(T value) {
  std::ostringstream s;
  s.precision(17);
  if constexpr (sizeof(T) == 1) {
    s << int(value);
  } else {
    s << value;
  }
  return s.str();
}

// A 32-bit data word's bytes as tshark prints FT_BYTES: hex, in wire order.
std::string wordBytes(uint32_t word, bool bigEndian) {
  char text[9];
  const uint32_t shown = bigEndian ? word : __builtin_bswap32(word);
  std::snprintf(text, sizeof text, "%08x", shown);
  return text;
}

Expected hostExpectations(bool bigEndian) {
  Expected e;
  const IgControl ig = test::sessionIgControl();
  e["cigi.ig_control.db_number"] = num(ig.database);
  e["cigi.ig_control.ig_mode"] = num(uint8_t(ig.mode));
  e["cigi.ig_control.timestamp_valid"] = num(ig.timestampValid);
  e["cigi.ig_control.extrapolation_enable"] = num(ig.extrapolation);
  e["cigi.ig_control.minor_version"] = num(ig.minorVersion);
  e["cigi.ig_control.host_frame_number"] = num(ig.hostFrame);
  e["cigi.ig_control.timestamp"] = num(ig.timestamp);
  e["cigi.ig_control.last_ig_frame_number"] = num(ig.lastIgFrame);
  e["cigi.byte_swap"] = bigEndian ? "0x8000" : "0x0080";
  const EntityControl ec = test::sessionEntityControl();
  e["cigi.entity_control.entity_id"] = num(ec.entity);
  e["cigi.entity_control.entity_state"] = num(uint8_t(ec.state));
  e["cigi.entity_control.attach_state"] = num(ec.attached);
  e["cigi.entity_control.coll_det_request"] = num(ec.collisionDetection);
  e["cigi.entity_control.inherit_alpha"] = num(ec.inheritAlpha);
  e["cigi.entity_control.ground_ocean_clamp"] = num(ec.groundClamp);
  e["cigi.entity_control.animation_dir"] = num(ec.animationFlags & 1);
  e["cigi.entity_control.animation_loop_mode"] = num(ec.animationFlags >> 1 & 1);
  e["cigi.entity_control.animation_state"] = num(ec.animationFlags >> 2 & 3);
  e["cigi.entity_control.extrapolation_enable"] = num(ec.extrapolation);
  e["cigi.entity_control.alpha"] = num(ec.alpha);
  e["cigi.entity_control.entity_type"] = num(ec.type);
  e["cigi.entity_control.parent_id"] = num(ec.parent);
  e["cigi.entity_control.roll"] = num(ec.roll);
  e["cigi.entity_control.pitch"] = num(ec.pitch);
  e["cigi.entity_control.yaw"] = num(ec.yaw);
  e["cigi.entity_control.lat_xoff"] = num(ec.latOrX);
  e["cigi.entity_control.lon_yoff"] = num(ec.lonOrY);
  e["cigi.entity_control.alt_zoff"] = num(ec.altOrZ);
  for (bool isShort : {false, true}) {
    const ComponentControl c = test::sessionComponentControl(isShort);
    const std::string p = isShort ? "cigi.short_component_control." : "cigi.component_control.";
    e[p + "component_id"] = num(c.component);
    e[p + "instance_id"] = num(c.instance);
    e[p + "component_class"] = num(uint8_t(c.componentClass));
    e[p + "component_state"] = num(c.state);
    for (int i = 0; i < (isShort ? 2 : 6); ++i) {
      e[p + "data_" + std::to_string(i + 1)] = wordBytes(c.data[i], bigEndian);
    }
  }
  const RateControl rc = test::sessionRateControl();
  e["cigi.rate_control.entity_id"] = num(rc.entity);
  e["cigi.rate_control.part_id"] = num(rc.part);
  e["cigi.rate_control.apply_to_part"] = num(rc.applyToPart);
  e["cigi.rate_control.coordinate_system"] = num(!rc.worldCoordinates);  // 1: local
  e["cigi.rate_control.x_rate"] = num(rc.x);
  e["cigi.rate_control.y_rate"] = num(rc.y);
  e["cigi.rate_control.z_rate"] = num(rc.z);
  e["cigi.rate_control.roll_rate"] = num(rc.roll);
  e["cigi.rate_control.pitch_rate"] = num(rc.pitch);
  e["cigi.rate_control.yaw_rate"] = num(rc.yaw);
  const CelestialSphereControl cs = test::sessionCelestial();
  e["cigi.celestial_sphere_control.hour"] = num(cs.hour);
  e["cigi.celestial_sphere_control.minute"] = num(cs.minute);
  e["cigi.celestial_sphere_control.ephemeris_enable"] = num(cs.ephemeris);
  e["cigi.celestial_sphere_control.sun_enable"] = num(cs.sun);
  e["cigi.celestial_sphere_control.moon_enable"] = num(cs.moon);
  e["cigi.celestial_sphere_control.star_enable"] = num(cs.starField);
  e["cigi.celestial_sphere_control.date_time_valid"] = num(cs.dateValid);
  e["cigi.celestial_sphere_control.date"] = num(cs.date);
  e["cigi.celestial_sphere_control.star_intensity"] = num(cs.starIntensity);
  const AtmosphereControl a = test::sessionAtmosphere();
  e["cigi.atmosphere_control.atmospheric_model_enable"] = num(a.modelEnabled);
  e["cigi.atmosphere_control.humidity"] = num(a.humidity);
  e["cigi.atmosphere_control.air_temp"] = num(a.temperature);
  e["cigi.atmosphere_control.visibility_range"] = num(a.visibility);
  e["cigi.atmosphere_control.horiz_wind"] = num(a.windHorizontal);
  e["cigi.atmosphere_control.vert_wind"] = num(a.windVertical);
  e["cigi.atmosphere_control.wind_direction"] = num(a.windDirection);
  e["cigi.atmosphere_control.barometric_pressure"] = num(a.pressure);
  const EnvironmentalRegionControl r = test::sessionRegion();
  e["cigi.env_region_control.region_id"] = num(r.region);
  e["cigi.env_region_control.region_state"] = num(r.state);
  e["cigi.env_region_control.merge_weather"] = num(r.mergeFlags & 1);
  e["cigi.env_region_control.merge_aerosol"] = num(r.mergeFlags >> 1 & 1);
  e["cigi.env_region_control.merge_maritime"] = num(r.mergeFlags >> 2 & 1);
  e["cigi.env_region_control.merge_terrestrial"] = num(r.mergeFlags >> 3 & 1);
  e["cigi.env_region_control.lat"] = num(r.lat);
  e["cigi.env_region_control.lon"] = num(r.lon);
  e["cigi.env_region_control.size_x"] = num(r.sizeX);
  e["cigi.env_region_control.size_y"] = num(r.sizeY);
  e["cigi.env_region_control.corner_radius"] = num(r.cornerRadius);
  e["cigi.env_region_control.rotation"] = num(r.rotation);
  e["cigi.env_region_control.transition_perimeter"] = num(r.transition);
  const WeatherControl w = test::sessionWeather();
  e["cigi.weather_control.entity_region_id"] = num(w.entityOrRegion);
  e["cigi.weather_control.layer_id"] = num(w.layer);
  e["cigi.weather_control.humidity"] = num(w.humidity);
  e["cigi.weather_control.weather_enable"] = num(w.enabled);
  e["cigi.weather_control.scud_enable"] = num(w.scud);
  e["cigi.weather_control.random_winds_enable"] = num(w.randomWinds);
  e["cigi.weather_control.random_lightning_enable"] = num(w.randomLightning);
  e["cigi.weather_control.cloud_type"] = num(w.cloudType);
  e["cigi.weather_control.scope"] = num(w.scope);
  e["cigi.weather_control.severity"] = num(w.severity);
  e["cigi.weather_control.air_temp"] = num(w.temperature);
  e["cigi.weather_control.visibility_range"] = num(w.visibility);
  e["cigi.weather_control.scud_frequency"] = num(w.scudFrequency);
  e["cigi.weather_control.coverage"] = num(w.coverage);
  e["cigi.weather_control.base_elevation"] = num(w.baseElevation);
  e["cigi.weather_control.thickness"] = num(w.thickness);
  e["cigi.weather_control.transition_band"] = num(w.transitionBand);
  e["cigi.weather_control.horiz_wind"] = num(w.windHorizontal);
  e["cigi.weather_control.vert_wind"] = num(w.windVertical);
  e["cigi.weather_control.wind_direction"] = num(w.windDirection);
  e["cigi.weather_control.barometric_pressure"] = num(w.pressure);
  e["cigi.weather_control.aerosol_concentration"] = num(w.aerosol);
  const ViewControl vc = test::sessionViewControl();
  e["cigi.view_control.view_id"] = num(vc.view);
  e["cigi.view_control.group_id"] = num(vc.group);
  const char* viewEnables[] = {"xoff", "yoff", "zoff", "roll", "pitch", "yaw"};
  for (int i = 0; i < 6; ++i) {
    e["cigi.view_control." + std::string(viewEnables[i]) + "_enable"] = num(vc.enable >> i & 1);
  }
  e["cigi.view_control.entity_id"] = num(vc.entity);
  e["cigi.view_control.xoff"] = num(vc.x);
  e["cigi.view_control.yoff"] = num(vc.y);
  e["cigi.view_control.zoff"] = num(vc.z);
  e["cigi.view_control.roll"] = num(vc.roll);
  e["cigi.view_control.pitch"] = num(vc.pitch);
  e["cigi.view_control.yaw"] = num(vc.yaw);
  const ViewDefinition vd = test::sessionViewDefinition();
  e["cigi.view_def.view_id"] = num(vd.view);
  e["cigi.view_def.group_id"] = num(vd.group);
  const char* planeEnables[] = {"near", "far", "left", "right", "top", "bottom"};
  for (int i = 0; i < 6; ++i) {
    e["cigi.view_def." + std::string(planeEnables[i]) + "_enable"] = num(vd.enable >> i & 1);
  }
  e["cigi.view_def.mirror_mode"] = num(vd.mirror);
  e["cigi.view_def.pixel_replication"] = num(vd.pixelReplication);
  e["cigi.view_def.projection_type"] = num(vd.orthographic);
  e["cigi.view_def.reorder"] = num(vd.reorder);
  e["cigi.view_def.view_type"] = num(vd.viewType);
  e["cigi.view_def.near"] = num(vd.nearPlane);
  e["cigi.view_def.far"] = num(vd.farPlane);
  e["cigi.view_def.left"] = num(vd.left);
  e["cigi.view_def.right"] = num(vd.right);
  e["cigi.view_def.top"] = num(vd.top);
  e["cigi.view_def.bottom"] = num(vd.bottom);
  const HatHotRequest hr = test::sessionHatHotRequest();
  e["cigi.hat_hot_request.hat_hot_id"] = num(hr.id);
  e["cigi.hat_hot_request.type"] = num(uint8_t(hr.type));
  e["cigi.hat_hot_request.coordinate_system"] = num(hr.entityCoordinates);
  e["cigi.hat_hot_request.update_period"] = num(hr.updatePeriod);
  e["cigi.hat_hot_request.entity_id"] = num(hr.entity);
  e["cigi.hat_hot_request.lat_xoff"] = num(hr.latOrX);
  e["cigi.hat_hot_request.lon_yoff"] = num(hr.lonOrY);
  e["cigi.hat_hot_request.alt_zoff"] = num(hr.altOrZ);
  const LosSegmentRequest lr = test::sessionLosRequest();
  e["cigi.los_segment_request.los_id"] = num(lr.id);
  e["cigi.los_segment_request.type"] = num(lr.extended);
  e["cigi.los_segment_request.source_coord"] = num(lr.sourceEntityCoordinates);
  e["cigi.los_segment_request.destination_coord"] = num(lr.destinationEntityCoordinates);
  e["cigi.los_segment_request.response_coord"] = num(lr.responseEntityCoordinates);
  e["cigi.los_segment_request.destination_entity_id_valid"] = num(lr.destinationEntityValid);
  e["cigi.los_segment_request.alpha_threshold"] = num(lr.alphaThreshold);
  e["cigi.los_segment_request.entity_id"] = num(lr.sourceEntity);
  e["cigi.los_segment_request.source_lat_xoff"] = num(lr.source[0]);
  e["cigi.los_segment_request.source_lon_yoff"] = num(lr.source[1]);
  e["cigi.los_segment_request.source_alt_zoff"] = num(lr.source[2]);
  e["cigi.los_segment_request.destination_lat_xoff"] = num(lr.destination[0]);
  e["cigi.los_segment_request.destination_lon_yoff"] = num(lr.destination[1]);
  e["cigi.los_segment_request.destination_alt_zoff"] = num(lr.destination[2]);
  e["cigi.los_segment_request.material_mask"] = num(lr.materialMask);
  e["cigi.los_segment_request.update_period"] = num(lr.updatePeriod);
  e["cigi.los_segment_request.destination_entity_id"] = num(lr.destinationEntity);
  e["cigi.packet_id"] = "1,2,4,5,8,9,10,11,12,16,21,24,25";
  return e;
}

Expected igExpectations(bool bigEndian) {
  Expected e;
  const StartOfFrame s = test::sessionStartOfFrame();
  e["cigi.sof.db_number"] = num(s.database);
  e["cigi.sof.ig_status"] = num(s.igStatus);
  e["cigi.sof.ig_mode"] = num(uint8_t(s.mode));
  e["cigi.sof.timestamp_valid"] = num(s.timestampValid);
  e["cigi.sof.earth_reference_model"] = num(s.earthReferenceModel);
  e["cigi.sof.minor_version"] = num(s.minorVersion);
  e["cigi.sof.ig_frame_number"] = num(s.igFrame);
  e["cigi.sof.timestamp"] = num(s.timestamp);
  e["cigi.sof.last_host_frame_number"] = num(s.lastHostFrame);
  e["cigi.byte_swap"] = bigEndian ? "0x8000" : "0x0080";
  const HatHotResponse h = test::sessionHatHotResponse();
  e["cigi.hat_hot_response.hat_hot_id"] = num(h.id);
  e["cigi.hat_hot_response.valid"] = num(h.valid);
  e["cigi.hat_hot_response.type"] = num(h.hot);
  e["cigi.hat_hot_response.host_frame_number_lsn"] = num(h.hostFrameLsn);
  e["cigi.hat_hot_response.height"] = num(h.height);
  const LosResponse l = test::sessionLosResponse();
  e["cigi.los_response.los_id"] = num(l.id);
  e["cigi.los_response.valid"] = num(l.valid);
  e["cigi.los_response.entity_id_valid"] = num(l.entityValid);
  e["cigi.los_response.visible"] = num(l.visible);
  e["cigi.los_response.host_frame_number_lsn"] = num(l.hostFrameLsn);
  e["cigi.los_response.count"] = num(l.count);
  e["cigi.los_response.entity_id"] = num(l.entity);
  e["cigi.los_response.range"] = num(l.range);
  e["cigi.packet_id"] = "101,102,104";
  return e;
}

bool sameValue(const std::string& shown, const std::string& expected) {
  if (shown == expected) return true;
  char* end1 = nullptr;
  char* end2 = nullptr;
  const double a = std::strtod(shown.c_str(), &end1), b = std::strtod(expected.c_str(), &end2);
  return !shown.empty() && *end1 == 0 && *end2 == 0 && a == b;
}

class CigiTshark : public testing::Test {
 protected:
  void SetUp() override {
    tshark_ = findTshark();
    ASSERT_FALSE(tshark_.empty())
        << "tshark (Wireshark's command-line dissector) is not on PATH: the CIGI conformance "
           "check needs it; scripts/lib.sh installs it";
  }
  std::string tshark_;
};

// Frames 1-2: host and IG datagrams in the big-endian order, 3-4 in the little-endian order.
std::vector<CapturedDatagram> conformanceSession() {
  constexpr bool kLittle = std::endian::native == std::endian::little;
  std::vector<CapturedDatagram> c;
  for (bool bigEndian : {true, false}) {
    const double t = bigEndian ? 100.0 : 100.5;
    c.push_back({t, true, writeDatagram(test::hostPackets(), bigEndian == kLittle)});
    c.push_back({t + 0.016, false, writeDatagram(test::igPackets(), bigEndian == kLittle)});
  }
  return c;
}

TEST_F(CigiTshark, ASessionCaptureDecodesWithNoMalformedPacketOrExpertError) {
  const std::string capture = sv::tests::processTemp().path("conformance.pcap");
  ASSERT_TRUE(writePcap(capture, conformanceSession()).ok());
  int status = 0;
  // Every frame must be CIGI; then none may be malformed or carry an error (the IPv4 header
  // checksum is checked too).
  const std::string protocols =
      run(tsharkCommand(tshark_, capture) + " -T fields -e frame.protocols 2>/dev/null", status);
  EXPECT_EQ(status, 0);
  EXPECT_NE(protocols.find("eth:ethertype:ip:udp:cigi\neth:ethertype:ip:udp:cigi\n"
                           "eth:ethertype:ip:udp:cigi\neth:ethertype:ip:udp:cigi\n"),
            std::string::npos)
      << protocols;
  const std::string bad =
      run(tsharkCommand(tshark_, capture) +
              " -o ip.check_checksum:TRUE -Y '_ws.malformed || _ws.expert.severity >= error'"
              " 2>/dev/null",
          status);
  EXPECT_EQ(status, 0);
  EXPECT_EQ(bad, "") << "tshark flags these frames:\n" << bad;
}

TEST_F(CigiTshark, TheMalformedCheckSeesATruncatedPacket) {
  // The check above must be able to fail: a datagram whose last packet is cut short.
  const std::string capture = sv::tests::processTemp().path("truncated.pcap");
  auto bytes = writeDatagram(test::hostPackets());
  bytes.resize(bytes.size() - 8);
  ASSERT_TRUE(writePcap(capture, std::vector<CapturedDatagram>{{1, true, bytes}}).ok());
  int status = 0;
  const std::string bad = run(
      tsharkCommand(tshark_, capture) + " -Y '_ws.malformed || _ws.expert.severity >= error'"
                                        " 2>/dev/null",
      status);
  EXPECT_NE(bad, "");
}

TEST_F(CigiTshark, EveryPacketTypeDecodesToTheFieldsSentInBothByteOrders) {
  const std::string capture = sv::tests::processTemp().path("fields.pcap");
  ASSERT_TRUE(writePcap(capture, conformanceSession()).ok());
  const Expected frames[4] = {hostExpectations(true), igExpectations(true),
                              hostExpectations(false), igExpectations(false)};
  // One tshark run prints every field of both kinds of frame, one line per frame, tab-separated.
  std::vector<std::string> fields;
  for (const Expected& e : {frames[0], frames[1]}) {
    for (const auto& [field, value] : e) {
      if (std::find(fields.begin(), fields.end(), field) == fields.end()) fields.push_back(field);
    }
  }
  std::string command = tsharkCommand(tshark_, capture) + " -T fields -E occurrence=a";
  for (const std::string& f : fields) command += " -e " + f;
  int status = 0;
  const std::string out = run(command + " 2>/dev/null", status);
  ASSERT_EQ(status, 0) << command;
  std::istringstream lines(out);
  std::string line;
  for (int frame = 0; frame < 4; ++frame) {
    ASSERT_TRUE(std::getline(lines, line)) << "tshark printed " << frame << " frames:\n" << out;
    std::vector<std::string> shown;
    std::istringstream columns(line);
    std::string column;
    while (std::getline(columns, column, '\t')) shown.push_back(column);
    shown.resize(fields.size());
    for (size_t i = 0; i < fields.size(); ++i) {
      const auto expected = frames[frame].find(fields[i]);
      if (expected == frames[frame].end()) continue;  // the other direction's field
      EXPECT_TRUE(sameValue(shown[i], expected->second))
          << "frame " << frame + 1 << " (" << (frame < 2 ? "big" : "little") << "-endian) "
          << fields[i] << ": tshark shows '" << shown[i] << "', the test sent '"
          << expected->second << "'";
    }
  }
}

}  // namespace
}  // namespace sv::cigi
