// A scripted CIGI host (docs/ig.md, "The scripted host"): what tests, demos and users without a
// simulator drive the IG with. A script (JSON) flies the ownship and other entities along timed
// paths and, at given times, switches light groups, sets the visibility and the time of day, and
// asks for heights and lines of sight. The host answers each Start of Frame with its next frame
// (CIGI's synchronous mode): IG Control, the entities' poses at the host frame's time, and the
// events that fall due — so the IG draws host frame k at IG frame k + 1.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cigi/cigi.h"
#include "synthvis/result.h"

namespace sv::ig {

struct PathPoint {
  double t = 0;                       // seconds
  double lat = 0, lon = 0, alt = 0;   // degrees, degrees, metres
  double yaw = 0, pitch = 0, roll = 0;  // degrees
};

struct ScriptEntity {
  uint16_t id = 0;
  uint16_t type = 0;
  std::vector<PathPoint> path;  // by time; the pose between two points is interpolated
};

struct ScriptEvent {
  double t = 0;
  std::vector<cigi::Packet> packets;  // sent in the host frame whose time first reaches t
};

struct HostScript {
  std::string igAddress = "127.0.0.1";
  uint16_t igPort = cigi::kIgPort;
  uint16_t port = cigi::kHostPort;  // the host's own (0: any)
  double rate = 60;                 // host frames a second (the IG's rate)
  uint64_t frames = 600;
  std::vector<ScriptEntity> entities;  // entity 0 is the ownship
  std::vector<ScriptEvent> events;     // by time
};

// Reads a script; positions are "lat"/"lon"/"alt" or "east"/"north"/"up" metres from the
// script's "origin" (docs/ig.md). Errors name the file and the field.
Result<HostScript> loadHostScript(const std::string& path);
Result<HostScript> parseHostScript(const std::string& text, const std::string& path);

// The packets of host frame `frame` (time frame / rate): IG Control, every entity's pose, the
// events due since the previous frame.
std::vector<cigi::Packet> hostFrame(const HostScript& script, uint64_t frame, uint32_t lastIgFrame);

// What the IG answered.
struct HostLog {
  uint64_t framesSent = 0;
  uint64_t startOfFrames = 0;
  uint32_t lastIgFrame = 0;
  std::vector<cigi::HatHotResponse> heights;
  std::vector<cigi::LosResponse> linesOfSight;
};

// Runs the script against an IG over UDP until its frames are sent (and the IG's answers to the
// last of them have come, or `timeoutMs` passed without a Start of Frame: an error naming the IG's
// address).
Result<HostLog> runHost(const HostScript& script, int timeoutMs = 2000);

}  // namespace sv::ig
