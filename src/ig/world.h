// The image generator's state between frames (docs/ig.md, "What the host controls"): the
// database, the entities the host created with their models, the views, the environment, the
// light groups and the time of day — changed only by the host's packets, applied between frames,
// so that a frame is a function of the packets before it (a recorded session replays exactly).
// Each frame the state becomes one scene (frameScene) that the renderer draws.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ig/geo.h"
#include "synthvis/cigi.h"
#include "synthvis/ig.h"
#include "synthvis/scene.h"

namespace sv::ig {

// What the host's traffic did, since the start (the status stream's counts).
struct TrafficCounts {
  uint64_t datagrams = 0, packets = 0, skipped = 0, malformed = 0, rejected = 0;
  uint64_t hatRequests = 0, losRequests = 0;
};

class IgWorld {
 public:
  // Loads the database and every model of the table; errors name the file.
  static Result<IgWorld> load(const IgConfig& config);

  // Applies one host datagram's packets in order; HAT/HOT and line-of-sight requests are answered
  // into `replies`. A packet naming an entity or view out of range, or a non-finite value, is
  // counted as rejected and ignored.
  void apply(const cigi::Datagram& datagram, std::vector<cigi::Packet>& replies);
  // The IG's frame counter and the host frame it last heard of (for Start of Frame and replies).
  void setFrame(uint32_t igFrame) { igFrame_ = igFrame; }
  uint32_t lastHostFrame() const { return lastHostFrame_; }
  cigi::IgMode mode() const { return mode_; }
  // Moves entities with rates (Rate Control) on by dt seconds, as the host would between its
  // frames (extrapolation), when the host enabled it.
  void advance(double dt);
  // The scene of this instant: the database, the entities' models at their poses, the eye on the
  // ownship (entity 0) with the views' offsets and frusta, fog from the visibility, the light
  // groups, the sun and stars from the time of day, and `time` (seconds since the start).
  const scene::Scene& frameScene(double time);
  // That scene, once made, at a quality level (overload.h): without `stars`, no star field; with
  // `replication` r > 1, every channel ⌈width / r⌉ × ⌈height / r⌉ pixels, to be shown each pixel
  // r × r times. Changed in place: the next frameScene starts again from full quality.
  const scene::Scene& atQuality(bool stars, int replication);
  // The channels' sizes as configured (before any replication).
  const std::vector<scene::Channel>& channels() const { return channels_; }

  // The ground under a world point (terrain or the database's polygons; the highest): its height
  // above the base (the Earth frame's: synthvis/geodesy.h) and the point's height above it,
  // along the base's normal there. And the first point the segment a → b meets (its fraction
  // along the segment).
  struct Ground {
    double elevation = 0, above = 0;
  };
  std::optional<Ground> groundUnder(Vec3d p) const;
  std::optional<double> segmentHit(Vec3d a, Vec3d b) const;

  const TrafficCounts& counts() const { return counts_; }
  TrafficCounts& counts() { return counts_; }
  size_t activeEntities() const;
  const IgConfig& config() const { return config_; }
  // Where geodetic positions land in the world (synthvis/geodesy.h).
  const GeoFrame& earth() const { return earth_; }
  const scene::Scene& database() const { return base_; }

 private:
  struct Model {
    std::vector<scene::Instance> instances;  // in the model's own space
  };
  struct Entity {
    bool exists = false;
    bool visible = true;  // an entity switch (Component Control)
    cigi::EntityControl control;
    cigi::RateControl rate;
    bool hasRate = false;
    int model = -1;  // index into models_, −1 for a type the table does not name
  };
  struct View {
    bool controlled = false, defined = false;
    cigi::ViewControl control;
    cigi::ViewDefinition definition;
  };
  struct Pose {
    Vec3d position;
    Frame3 frame;
  };

  bool pose(uint16_t entity, Pose& out, int depth = 0) const;
  void applyPacket(const cigi::Packet& packet, std::vector<cigi::Packet>& replies);
  // applyPacket's cases: each packet the IG acts on, a packet out of range or not finite counted
  // as rejected and ignored.
  void applyEntityControl(const cigi::EntityControl& ec);
  void applyComponentControl(const cigi::ComponentControl& cc);
  void applyRateControl(const cigi::RateControl& rc);
  void applyViewControl(const cigi::ViewControl& vc);
  void applyViewDefinition(const cigi::ViewDefinition& vd);
  // The answers to the host's requests, naming the host frame they were asked in (its low 4 bits).
  cigi::HatHotResponse answerHatHot(const cigi::HatHotRequest& hr, uint8_t lsn) const;
  cigi::LosResponse answerLos(const cigi::LosSegmentRequest& lr, uint8_t lsn) const;
  Vec3d requestPoint(bool entityRelative, uint16_t entity, const double p[3], bool& ok) const;

  IgConfig config_;
  GeoFrame earth_;
  scene::Scene base_;   // the database as loaded, the models' meshes appended
  scene::Scene frame_;  // this frame's scene (base_ plus the entities' instances)
  size_t baseInstances_ = 0;
  std::vector<scene::Channel> channels_;  // the configured channels before the views' changes
  std::vector<uint16_t> modelTypes_;
  std::vector<Model> models_;
  std::vector<Entity> entities_;
  std::vector<View> views_;
  cigi::IgMode mode_ = cigi::IgMode::operate;
  bool extrapolation_ = false;
  uint32_t igFrame_ = 0, lastHostFrame_ = 0;
  // Environment.
  float atmosphereVisibility_ = 0, weatherVisibility_ = 0;  // m; 0: as the database says
  bool timeOfDay_ = false;
  cigi::CelestialSphereControl celestial_;
  TrafficCounts counts_;
};

}  // namespace sv::ig
