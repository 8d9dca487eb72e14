// The scripted host (docs/ig.md, "The scripted host").
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "ig/geo.h"
#include "ig/json_input.h"
#include "ig/udp.h"
#include "synthvis/ig.h"

namespace sv::ig {
namespace {

using Json = nlohmann::json;

[[noreturn]] void bad(const std::string& m) { badField(m); }

double num(const Json& o, const char* key, const std::string& where, double lo, double hi,
           double fallback) {
  if (!o.contains(key)) return fallback;
  const Json& v = o[key];
  if (!v.is_number()) bad(fmt::format("{}.{}: expected a number", where, key));
  const double x = v.get<double>();
  if (!std::isfinite(x) || x < lo || x > hi)
    bad(fmt::format("{}.{}: {} is outside [{}, {}]", where, key, x, lo, hi));
  return x;
}

// "HH:MM" (or "H:MM"): one or two digits of hour and two of minute, and nothing else. So "6:5"
// (6:05 or 6:50?) is refused, and no field is read beyond int's range (which sscanf's %d leaves
// undefined).
bool clockTime(const std::string& s, int& h, int& m) {
  auto digits = [&s](size_t from, size_t to, size_t least, int& v) {
    if (to < from + least || to - from > 2) return false;
    v = 0;
    for (size_t i = from; i < to; ++i) {
      if (s[i] < '0' || s[i] > '9') return false;
      v = v * 10 + (s[i] - '0');
    }
    return true;
  };
  const size_t colon = s.find(':');
  return colon != std::string::npos && digits(0, colon, 1, h) && digits(colon + 1, s.size(), 2, m);
}

// A position: lat/lon/alt, or east/north/up from the script's origin.
void position(const Json& o, const std::string& where, const GeoPoint& origin, double& lat,
              double& lon, double& alt) {
  if (!o.is_object()) bad(fmt::format("{}: expected an object", where));
  if (o.contains("east") || o.contains("north") || o.contains("up")) {
    const GeoPoint g = GeoFrame(origin).toGeodetic({num(o, "east", where, -1e6, 1e6, 0),
                                                    num(o, "up", where, -1e4, 1e6, 0),
                                                    -num(o, "north", where, -1e6, 1e6, 0)});
    lat = g.lat;
    lon = g.lon;
    alt = g.alt;
  } else {
    lat = num(o, "lat", where, -90, 90, origin.lat);
    lon = num(o, "lon", where, -180, 180, origin.lon);
    alt = num(o, "alt", where, -1e4, 1e6, origin.alt);
  }
}

HostScript read(const Json& root) {
  // Compared as JSON, not read as an int: a version of 1e79 or "1" is refused, not converted.
  if (!root.is_object() || !root.contains("synthvis-host") || root["synthvis-host"] != 1)
    bad("\"synthvis-host\": 1 expected (the script format's version)");
  HostScript s;
  GeoPoint origin;
  if (root.contains("origin")) {
    origin.lat = num(root["origin"], "lat", "origin", -89, 89, 0);
    origin.lon = num(root["origin"], "lon", "origin", -180, 180, 0);
    origin.alt = num(root["origin"], "alt", "origin", -1e4, 1e5, 0);
  }
  if (root.contains("ig")) {
    const Json& ig = root["ig"];
    if (ig.contains("address")) {
      if (!ig["address"].is_string()) bad("ig.address: expected a dotted IPv4 address");
      s.igAddress = ig["address"].get<std::string>();
    }
    s.igPort = uint16_t(num(ig, "port", "ig", 1, 65535, s.igPort));
  }
  s.port = uint16_t(num(root, "port", "script", 0, 65535, s.port));
  s.rate = num(root, "rate", "script", 1, 240, s.rate);
  s.frames = uint64_t(num(root, "frames", "script", 1, 1e8, double(s.frames)));
  if (root.contains("entities")) {
    if (!root["entities"].is_array()) bad("entities: expected a list");
    for (size_t i = 0; i < root["entities"].size(); ++i) {
      const Json& e = root["entities"][i];
      const std::string where = fmt::format("entities[{}]", i);
      ScriptEntity se;
      se.id = uint16_t(num(e, "id", where, 0, 65535, 0));
      se.type = uint16_t(num(e, "type", where, 0, 65535, 0));
      if (!e.contains("path") || !e["path"].is_array() || e["path"].empty())
        bad(where + ".path: a list of timed poses expected");
      for (size_t k = 0; k < e["path"].size(); ++k) {
        const Json& p = e["path"][k];
        const std::string at = fmt::format("{}.path[{}]", where, k);
        PathPoint pp;
        pp.t = num(p, "t", at, 0, 1e7, 0);
        position(p, at, origin, pp.lat, pp.lon, pp.alt);
        pp.yaw = num(p, "yaw", at, -360, 360, 0);
        pp.pitch = num(p, "pitch", at, -90, 90, 0);
        pp.roll = num(p, "roll", at, -180, 180, 0);
        if (!se.path.empty() && pp.t <= se.path.back().t)
          bad(at + ".t: times must increase along a path");
        se.path.push_back(pp);
      }
      s.entities.push_back(std::move(se));
    }
  }
  if (root.contains("events")) {
    if (!root["events"].is_array()) bad("events: expected a list");
    for (size_t i = 0; i < root["events"].size(); ++i) {
      const Json& e = root["events"][i];
      const std::string where = fmt::format("events[{}]", i);
      ScriptEvent ev;
      ev.t = num(e, "t", where, 0, 1e7, 0);
      if (e.contains("lights")) {
        const Json& l = e["lights"];
        cigi::ComponentControl c;
        c.componentClass = cigi::ComponentClass::system;
        c.component = uint16_t(num(l, "group", where + ".lights", 0, 65535, 0));
        const bool on = l.value("on", true);
        const float dim = float(num(l, "dim", where + ".lights", 0, 1, 1));
        c.state = !on ? 0 : dim < 1 ? 2 : 1;
        std::memcpy(&c.data[0], &dim, sizeof dim);
        ev.packets.push_back(c);
      }
      if (e.contains("visibility")) {
        cigi::AtmosphereControl a;
        a.modelEnabled = true;
        a.visibility = float(num(e, "visibility", where, 1, 1e6, 1e5));
        ev.packets.push_back(a);
      }
      if (e.contains("timeOfDay")) {
        const Json& t = e["timeOfDay"];
        int h = -1, m = -1;
        if (!t.is_string() || !clockTime(t.get<std::string>(), h, m) || h > 23 || m > 59)
          bad(where + ".timeOfDay: \"HH:MM\" expected");
        cigi::CelestialSphereControl c;
        c.hour = uint8_t(h);
        c.minute = uint8_t(m);
        ev.packets.push_back(c);
      }
      if (e.contains("hat") || e.contains("hot")) {
        const bool hot = e.contains("hot");
        const Json& q = hot ? e["hot"] : e["hat"];
        cigi::HatHotRequest r;
        r.id = uint16_t(num(q, "id", where, 0, 65535, 0));
        r.type = hot ? cigi::HatHotType::hot : cigi::HatHotType::hat;
        position(q, where + (hot ? ".hot" : ".hat"), origin, r.latOrX, r.lonOrY, r.altOrZ);
        ev.packets.push_back(r);
      }
      if (e.contains("los")) {
        const Json& q = e["los"];
        cigi::LosSegmentRequest r;
        r.id = uint16_t(num(q, "id", where, 0, 65535, 0));
        if (!q.contains("from") || !q.contains("to"))
          bad(where + ".los: \"from\" and \"to\" expected");
        position(q["from"], where + ".los.from", origin, r.source[0], r.source[1], r.source[2]);
        position(q["to"], where + ".los.to", origin, r.destination[0], r.destination[1],
                 r.destination[2]);
        ev.packets.push_back(r);
      }
      if (e.contains("create")) {
        const Json& c = e["create"];
        const std::string at = where + ".create";
        cigi::EntityControl ec;
        ec.entity = uint16_t(num(c, "id", at, 0, 65535, 0));
        ec.type = uint16_t(num(c, "type", at, 0, 65535, 0));
        position(c, at, origin, ec.latOrX, ec.lonOrY, ec.altOrZ);
        ec.yaw = float(num(c, "yaw", at, -360, 360, 0));
        ec.pitch = float(num(c, "pitch", at, -90, 90, 0));
        ec.roll = float(num(c, "roll", at, -180, 180, 0));
        ev.packets.push_back(ec);
      }
      if (e.contains("destroy")) {
        cigi::EntityControl c;
        c.entity = uint16_t(num(e, "destroy", where, 0, 65535, 0));
        c.state = cigi::EntityState::destroyed;
        ev.packets.push_back(c);
      }
      if (ev.packets.empty())
        bad(where +
            ": nothing to do (lights, visibility, timeOfDay, hat, hot, los, create or destroy)");
      s.events.push_back(std::move(ev));
    }
    std::stable_sort(s.events.begin(), s.events.end(),
                     [](const ScriptEvent& a, const ScriptEvent& b) { return a.t < b.t; });
  }
  return s;
}

// The pose at time t: the path's first point before it starts, its last after it ends, linear
// in between (headings along the shorter way round).
PathPoint poseAt(const std::vector<PathPoint>& path, double t) {
  if (t <= path.front().t) return path.front();
  if (t >= path.back().t) return path.back();
  size_t k = 1;
  while (path[k].t < t) ++k;
  const PathPoint &a = path[k - 1], &b = path[k];
  const double f = (t - a.t) / (b.t - a.t);
  auto mix = [f](double x, double y) { return x + (y - x) * f; };
  PathPoint p;
  p.t = t;
  p.lat = mix(a.lat, b.lat);
  p.lon = mix(a.lon, b.lon);
  p.alt = mix(a.alt, b.alt);
  p.yaw = a.yaw + std::remainder(b.yaw - a.yaw, 360.0) * f;
  p.pitch = mix(a.pitch, b.pitch);
  p.roll = mix(a.roll, b.roll);
  return p;
}

}  // namespace

Result<HostScript> parseHostScript(const std::string& text, const std::string& path) {
  return parseJsonInput<HostScript>(text, path, [](const Json& root) { return read(root); });
}

Result<HostScript> loadHostScript(const std::string& path) {
  Result<std::string> text = readJsonInput(path);
  if (!text) return text.error();
  return parseHostScript(text.value(), path);
}

std::vector<cigi::Packet> hostFrame(const HostScript& script, uint64_t frame,
                                    uint32_t lastIgFrame) {
  std::vector<cigi::Packet> out;
  cigi::IgControl c;
  c.hostFrame = uint32_t(frame);
  c.lastIgFrame = lastIgFrame;
  out.push_back(c);
  const double t = double(frame) / script.rate, before = (double(frame) - 1) / script.rate;
  for (const ScriptEntity& e : script.entities) {
    const PathPoint p = poseAt(e.path, t);
    cigi::EntityControl ec;
    ec.entity = e.id;
    ec.type = e.type;
    ec.latOrX = p.lat;
    ec.lonOrY = p.lon;
    ec.altOrZ = p.alt;
    ec.yaw = float(p.yaw);
    ec.pitch = float(p.pitch);
    ec.roll = float(p.roll);
    out.push_back(ec);
  }
  for (const ScriptEvent& ev : script.events)
    if (ev.t <= t && (frame == 0 || ev.t > before))
      out.insert(out.end(), ev.packets.begin(), ev.packets.end());
  return out;
}

Result<HostLog> runHost(const HostScript& script, int timeoutMs, int startMs) {
  UdpSocket socket;
  if (Status s = socket.open(script.port); !s) return s.error();
  Result<sockaddr_in> address = udpAddress(script.igAddress, script.igPort);
  if (!address) return address.error();
  const sockaddr_in ig = address.value();
  HostLog log;
  std::vector<uint8_t> bytes;
  // The IG sends Start of Frame every frame to the host it knows; one configured to answer
  // whoever drives it learns the host from its first datagram: announce the host with an IG
  // Control now, and again while no Start of Frame has come.
  cigi::IgControl announce;
  const std::vector<uint8_t> hello = cigi::writeDatagram(std::vector<cigi::Packet>{announce});
  auto send = [&](const std::vector<uint8_t>& out) { socket.send(out, ig); };
  send(hello);
  // Waits for the next Start of Frame, collecting the answers that come with it.
  auto nextStartOfFrame = [&]() -> Status {
    for (int waitedMs = 0;;) {
      sockaddr_in from{};
      if (!socket.receive(bytes, from, 100)) {
        waitedMs += 100;
        const int limit = log.startOfFrames == 0 ? startMs : timeoutMs;
        if (waitedMs >= limit)
          return Error{"", "",
                       fmt::format("no Start of Frame from the IG at {}:{} for {} ms",
                                   script.igAddress, script.igPort, limit)};
        if (log.startOfFrames == 0) send(hello);
        continue;
      }
      Result<cigi::Datagram> d = cigi::parseDatagram(bytes);
      if (!d) continue;
      bool sof = false;
      for (const cigi::Packet& packet : d->packets) {
        if (const auto* s = std::get_if<cigi::StartOfFrame>(&packet)) {
          sof = true;
          log.lastIgFrame = s->igFrame;
          ++log.startOfFrames;
        } else if (const auto* h = std::get_if<cigi::HatHotResponse>(&packet)) {
          log.heights.push_back(*h);
        } else if (const auto* l = std::get_if<cigi::LosResponse>(&packet)) {
          log.linesOfSight.push_back(*l);
        }
      }
      if (sof) return {};
    }
  };
  while (log.framesSent < script.frames) {
    if (Status s = nextStartOfFrame(); !s) return s.error();
    send(cigi::writeDatagram(hostFrame(script, log.framesSent, log.lastIgFrame)));
    ++log.framesSent;
  }
  // The answers to the last frame's requests come with the Start of Frame after it.
  if (Status s = nextStartOfFrame(); !s) return s.error();
  return log;
}

}  // namespace sv::ig
