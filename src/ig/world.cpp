// Based on: CIGI 3.3 ICD (the packets' meaning, an IG's side); seed 004 (the IG's state, changed by
// the host between frames); SPEC §8 (fog from visibility), §9 (channels), §13 (light groups).
#include "ig/world.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "synthvis/formats.h"
#include "synthvis/terrain.h"

namespace sv::ig {
namespace {

constexpr double kRad = std::numbers::pi / 180;

bool finite3(const double p[3]) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// Visibility V (m) as fog: the distance at which a black object's contrast falls to 5 % (the
// meteorological convention), 2^(−β·V) = 0.05, β = log2(20) / V.
float fogBetaForVisibility(float v) { return float(std::log2(20.0) / double(v)); }

}  // namespace

Result<IgWorld> IgWorld::load(const IgConfig& config) {
  IgWorld w;
  w.config_ = config;
  Result<scene::Scene> db = formats::loadScene(config.scene);
  if (!db) return db.error();
  w.base_ = std::move(db.value());
  for (const auto& [type, file] : config.models) {
    Result<scene::Scene> model = formats::loadScene(file);
    if (!model) return model.error();
    if (!model->freeForms.empty() || !model->terrains.empty())
      return Error{file, "", "an entity model holds triangles only (free forms and terrain belong to the database)"};
    // Only the model's meshes stay in the database; its placements become the entity's (its
    // switches, degrees of freedom, light points and lines are not carried by entities).
    scene::Scene& b = w.base_;
    const size_t before = b.instances.size(), cameras = b.cameras.size(),
                 switches = b.switches.size(), dofs = b.dofs.size(),
                 lights = b.lightPoints.size(), looks = b.lightAppearances.size(),
                 groups = b.lightGroups.size(), lines = b.lines.size();
    scene::appendScene(b, std::move(model.value()), Mat4{});
    Model m;
    m.instances.assign(b.instances.begin() + std::ptrdiff_t(before), b.instances.end());
    for (scene::Instance& inst : m.instances) inst.visible = true, inst.articulated = false;
    b.instances.resize(before);
    b.cameras.resize(cameras);
    b.switches.resize(switches);
    b.dofs.resize(dofs);
    b.lightPoints.resize(lights);
    b.lightAppearances.resize(looks);
    b.lightGroups.resize(groups);
    b.lines.resize(lines);
    w.modelTypes_.push_back(type);
    w.models_.push_back(std::move(m));
  }
  if (Status s = scene::validate(w.base_, config.scene, false); !s) return s.error();
  // The one Earth frame (synthvis/geodesy.h): the database's own, else the configuration's origin.
  if (const std::optional<scene::Geodetic>& g = w.base_.geodetic) {
    if (config.hasOrigin &&
        (config.origin.lat != g->origin.lat || config.origin.lon != g->origin.lon ||
         config.origin.alt != g->origin.alt))
      return Error{config.scene, "",
                   fmt::format("the database's geodetic origin ({}, {}, {}) is not the "
                               "configuration's origin ({}, {}, {})",
                               g->origin.lat, g->origin.lon, g->origin.alt, config.origin.lat,
                               config.origin.lon, config.origin.alt)};
    w.earth_ = g->frame();
  } else {
    w.earth_ = GeoFrame(config.origin);
  }
  w.baseInstances_ = w.base_.instances.size();
  w.channels_ = config.channels.empty() ? w.base_.channels : config.channels;
  if (w.channels_.empty()) {
    scene::Channel c;
    c.name = "0";
    c.width = config.width;
    c.height = config.height;
    w.channels_.push_back(c);
  }
  w.entities_.resize(config.maxEntities);
  w.views_.resize(w.channels_.size());
  w.frame_ = w.base_;
  return w;
}

size_t IgWorld::activeEntities() const {
  size_t n = 0;
  for (const Entity& e : entities_) n += e.exists;
  return n;
}

bool IgWorld::pose(uint16_t id, Pose& out, int depth) const {
  if (id >= entities_.size() || !entities_[id].exists || depth > 16) return false;
  const cigi::EntityControl& c = entities_[id].control;
  if (c.attached) {
    Pose parent;
    if (!pose(c.parent, parent, depth + 1)) return false;
    out.position = parent.position + parent.frame.apply({c.latOrX, c.lonOrY, c.altOrZ});
    out.frame = eulerFrame(parent.frame, c.yaw, c.pitch, c.roll);
  } else {
    out.position = earth_.toWorld({c.latOrX, c.lonOrY, c.altOrZ});
    out.frame = eulerFrame(levelFrame(), c.yaw, c.pitch, c.roll);
  }
  return true;
}

Vec3d IgWorld::requestPoint(bool entityRelative, uint16_t entity, const double p[3],
                            bool& ok) const {
  ok = finite3(p);
  if (!ok) return {};
  if (!entityRelative) return earth_.toWorld({p[0], p[1], p[2]});
  Pose e;
  ok = pose(entity, e);
  return ok ? e.position + e.frame.apply({p[0], p[1], p[2]}) : Vec3d{};
}

void IgWorld::apply(const cigi::Datagram& datagram, std::vector<cigi::Packet>& replies) {
  ++counts_.datagrams;
  counts_.skipped += datagram.skipped;
  for (const cigi::Packet& p : datagram.packets) {
    ++counts_.packets;
    applyPacket(p, replies);
  }
}

void IgWorld::applyEntityControl(const cigi::EntityControl& ec) {
  const double v[3] = {ec.latOrX, ec.lonOrY, ec.altOrZ};
  if (ec.entity >= entities_.size() || !finite3(v) || !std::isfinite(ec.roll) ||
      !std::isfinite(ec.pitch) || !std::isfinite(ec.yaw) ||
      (ec.attached && (ec.parent >= entities_.size() || ec.parent == ec.entity))) {
    ++counts_.rejected;
    return;
  }
  Entity& e = entities_[ec.entity];
  if (ec.state == cigi::EntityState::destroyed) {
    e = Entity{};
    return;
  }
  if (!e.exists || e.control.type != ec.type) {
    e.model = -1;
    for (size_t m = 0; m < modelTypes_.size(); ++m)
      if (modelTypes_[m] == ec.type) e.model = int(m);
    e.hasRate = false;
  }
  e.exists = true;
  e.control = ec;
  e.hasRate = false;  // a new pose from the host ends the extrapolation from the old one
}

void IgWorld::applyComponentControl(const cigi::ComponentControl& cc) {
  if (cc.componentClass == cigi::ComponentClass::system) {
    // Light groups (docs/ig.md): component ID = the group's index, state 0 off, 1 on, 2 on and
    // dimmed to data[0] read as an IEEE float (0 … 1).
    if (cc.component >= base_.lightGroups.size()) {
      ++counts_.rejected;
      return;
    }
    scene::LightGroup& g = frame_.lightGroups[cc.component];
    g.on = cc.state != 0;
    g.dim = 1;
    if (cc.state == 2) {
      float dim;
      std::memcpy(&dim, &cc.data[0], sizeof dim);
      if (!(dim >= 0 && dim <= 1)) {
        ++counts_.rejected;
        return;
      }
      g.dim = dim;
    }
  } else if (cc.componentClass == cigi::ComponentClass::entity) {
    // An entity switch: component 0 of entity `instance`, state 0 hidden, 1 shown.
    if (cc.instance >= entities_.size() || cc.component != 0) {
      ++counts_.rejected;
      return;
    }
    entities_[cc.instance].visible = cc.state != 0;
  } else {
    ++counts_.skipped;
  }
}

void IgWorld::applyRateControl(const cigi::RateControl& rc) {
  const float r[6] = {rc.x, rc.y, rc.z, rc.roll, rc.pitch, rc.yaw};
  const bool finite = std::all_of(r, r + 6, [](float x) { return std::isfinite(x); });
  if (rc.entity >= entities_.size() || !entities_[rc.entity].exists || !finite) {
    ++counts_.rejected;
    return;
  }
  if (rc.applyToPart) {
    ++counts_.skipped;  // articulated parts: not modelled
    return;
  }
  entities_[rc.entity].rate = rc;
  entities_[rc.entity].hasRate = true;
}

void IgWorld::applyViewControl(const cigi::ViewControl& vc) {
  const float v[6] = {vc.x, vc.y, vc.z, vc.roll, vc.pitch, vc.yaw};
  if (vc.view >= views_.size() || vc.entity >= entities_.size() ||
      !std::all_of(v, v + 6, [](float x) { return std::isfinite(x); })) {
    ++counts_.rejected;
    return;
  }
  views_[vc.view].controlled = true;
  views_[vc.view].control = vc;
}

void IgWorld::applyViewDefinition(const cigi::ViewDefinition& vd) {
  const float v[6] = {vd.nearPlane, vd.farPlane, vd.left, vd.right, vd.top, vd.bottom};
  const bool ok = std::all_of(v, v + 6, [](float x) { return std::isfinite(x); }) &&
                  vd.left < vd.right && vd.bottom < vd.top && vd.left > -90 && vd.right < 90 &&
                  vd.bottom > -90 && vd.top < 90 && vd.nearPlane > 0 && vd.farPlane > vd.nearPlane;
  if (vd.view >= views_.size() || !ok) {
    ++counts_.rejected;
    return;
  }
  views_[vd.view].defined = true;
  views_[vd.view].definition = vd;
}

cigi::HatHotResponse IgWorld::answerHatHot(const cigi::HatHotRequest& hr, uint8_t lsn) const {
  const double q[3] = {hr.latOrX, hr.lonOrY, hr.altOrZ};
  bool ok = false;
  const Vec3d w = requestPoint(hr.entityCoordinates, hr.entity, q, ok);
  cigi::HatHotResponse r;
  r.id = hr.id;
  r.hostFrameLsn = lsn;
  // A HOT asks for the ground under the point; a HAT for the point's height above it (an
  // extended request is answered as a HAT: the extended response is not implemented).
  r.hot = hr.type == cigi::HatHotType::hot;
  if (const std::optional<Ground> g = ok ? groundUnder(w) : std::nullopt) {
    r.valid = true;
    r.height = r.hot ? g->elevation + earth_.origin().alt : g->above;
  }
  return r;
}

cigi::LosResponse IgWorld::answerLos(const cigi::LosSegmentRequest& lr, uint8_t lsn) const {
  bool okA = false, okB = false;
  const Vec3d a = requestPoint(lr.sourceEntityCoordinates, lr.sourceEntity, lr.source, okA);
  const Vec3d b =
      requestPoint(lr.destinationEntityCoordinates, lr.sourceEntity, lr.destination, okB);
  cigi::LosResponse r;
  r.id = lr.id;
  r.hostFrameLsn = lsn;
  if (okA && okB) {
    const std::optional<double> t = segmentHit(a, b);
    const Vec3d d = b - a;
    r.valid = t.has_value();  // the range is valid where the segment meets something
    r.visible = !t;
    r.range = t ? *t * std::sqrt(dot(d, d)) : 0;
  }
  return r;
}

void IgWorld::applyPacket(const cigi::Packet& packet, std::vector<cigi::Packet>& replies) {
  using namespace cigi;
  const uint8_t lsn = uint8_t(lastHostFrame_ & 0xF);
  if (const auto* ig = std::get_if<IgControl>(&packet)) {
    mode_ = ig->mode;
    extrapolation_ = ig->extrapolation;
    lastHostFrame_ = ig->hostFrame;
    if (ig->mode == IgMode::reset)
      for (Entity& e : entities_) e = Entity{};
  } else if (const auto* ec = std::get_if<EntityControl>(&packet)) {
    applyEntityControl(*ec);
  } else if (const auto* cc = std::get_if<ComponentControl>(&packet)) {
    applyComponentControl(*cc);
  } else if (const auto* rc = std::get_if<RateControl>(&packet)) {
    applyRateControl(*rc);
  } else if (const auto* cs = std::get_if<CelestialSphereControl>(&packet)) {
    if (cs->hour > 23 || cs->minute > 59 || !std::isfinite(cs->starIntensity)) {
      ++counts_.rejected;
      return;
    }
    celestial_ = *cs;
    timeOfDay_ = true;
  } else if (const auto* ac = std::get_if<AtmosphereControl>(&packet)) {
    if (!std::isfinite(ac->visibility) || ac->visibility < 0) {
      ++counts_.rejected;
      return;
    }
    atmosphereVisibility_ = ac->visibility;
  } else if (const auto* wc = std::get_if<WeatherControl>(&packet)) {
    if (!std::isfinite(wc->visibility) || wc->visibility < 0) {
      ++counts_.rejected;
      return;
    }
    // Global weather (scope 0) sets the visibility; regional and entity weather are not modelled.
    if (wc->scope == 0) weatherVisibility_ = wc->enabled ? wc->visibility : 0;
    else ++counts_.skipped;
  } else if (const auto* vc = std::get_if<ViewControl>(&packet)) {
    applyViewControl(*vc);
  } else if (const auto* vd = std::get_if<ViewDefinition>(&packet)) {
    applyViewDefinition(*vd);
  } else if (const auto* hr = std::get_if<HatHotRequest>(&packet)) {
    ++counts_.hatRequests;
    replies.push_back(answerHatHot(*hr, lsn));
  } else if (const auto* lr = std::get_if<LosSegmentRequest>(&packet)) {
    ++counts_.losRequests;
    replies.push_back(answerLos(*lr, lsn));
  } else {
    ++counts_.skipped;  // decoded but not acted on (environmental regions; IG → host packets)
  }
}

void IgWorld::advance(double dt) {
  if (!extrapolation_) return;
  for (Entity& e : entities_) {
    if (!e.exists || !e.hasRate) continue;
    cigi::EntityControl& c = e.control;
    const cigi::RateControl& r = e.rate;
    // The rates in the parent's axes (CIGI's "world/parent" coordinate system) or in the entity's
    // own body axes ("local"), turned into the parent's.
    const Frame3 parentAxes{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // forward, right, down as themselves
    const Vec3d own = r.worldCoordinates
                          ? Vec3d{r.x, r.y, r.z}
                          : eulerFrame(parentAxes, c.yaw, c.pitch, c.roll).apply({r.x, r.y, r.z});
    if (c.attached) {
      // Offsets in the parent's body axes (forward, right, down).
      c.latOrX += own.x * dt;
      c.lonOrY += own.y * dt;
      c.altOrZ += own.z * dt;
    } else {
      // North, east, down, into degrees and metres up.
      c.latOrX += own.x * dt / earth_.metresPerDegreeNorth();
      c.lonOrY += own.y * dt / earth_.metresPerDegreeEast();
      c.altOrZ -= own.z * dt;
    }
    c.roll = float(std::remainder(c.roll + r.roll * dt, 360.0));
    c.pitch = float(std::clamp(c.pitch + r.pitch * dt, -90.0, 90.0));
    c.yaw = float(std::remainder(c.yaw + r.yaw * dt, 360.0));
  }
}

const scene::Scene& IgWorld::frameScene(double time) {
  scene::Scene& s = frame_;
  s.time = time;
  // The star field's settings as the database has them (its catalogue stays in place: frame_
  // began as a copy of the database and the stars themselves never change).
  s.stars.brightness = base_.stars.brightness;
  s.stars.limit = base_.stars.limit;
  // The entities' models at their poses.
  s.instances.resize(baseInstances_);
  for (uint16_t id = 0; id < entities_.size(); ++id) {
    const Entity& e = entities_[id];
    Pose p;
    if (!e.exists || !e.visible || e.model < 0 || e.control.state != cigi::EntityState::active ||
        !pose(id, p))
      continue;
    const Mat4 place = modelMatrix(p.frame, p.position);
    for (scene::Instance i : models_[size_t(e.model)].instances) {
      i.transform = place * i.transform;
      s.instances.push_back(i);
    }
  }
  // The eye on the ownship (entity 0), when the host has made it; else the database's camera.
  s.channels = channels_;
  Pose own;
  if (pose(0, own)) {
    scene::Camera cam = base_.cameras.empty() ? scene::Camera{} : base_.cameras[0];
    cam.position = toFloat(own.position);
    cam.target = toFloat(own.position + own.frame.forward * 100.0);
    cam.up = toFloat(own.frame.down * -1.0);
    if (s.cameras.empty()) s.cameras.push_back(cam);
    else s.cameras[0] = cam;
  }
  for (size_t v = 0; v < views_.size() && v < s.channels.size(); ++v) {
    scene::Channel& ch = s.channels[v];
    const View& view = views_[v];
    if (view.controlled) {
      // Offsets in the ownship's body axes (x forward, y right, z down) into the camera's eye
      // space (x right, y up, z back); the angles replace the channel's where enabled.
      const cigi::ViewControl& c = view.control;
      if (c.enable & 1) ch.offset.z = -c.x;
      if (c.enable & 2) ch.offset.x = c.y;
      if (c.enable & 4) ch.offset.y = -c.z;
      if (c.enable & 8) ch.rollDegrees = c.roll;
      if (c.enable & 16) ch.pitchDegrees = c.pitch;
      if (c.enable & 32) ch.yawDegrees = c.yaw;
    }
    if (view.defined) {
      const cigi::ViewDefinition& d = view.definition;
      ch.frustum = scene::ChannelFrustum{d.left, d.right, d.bottom, d.top};
      if (!s.cameras.empty()) {
        s.cameras[0].znear = d.nearPlane;
        s.cameras[0].zfar = d.farPlane;
      }
    }
  }
  // Fog from the visibility: the nearer of the atmosphere's and the global weather's.
  float visibility = 0;
  for (float v : {atmosphereVisibility_, weatherVisibility_})
    if (v > 0) visibility = visibility > 0 ? std::min(visibility, v) : v;
  s.fog = base_.fog;
  if (visibility > 0) {
    s.fog.enabled = true;
    s.fog.beta = fogBetaForVisibility(visibility);
  }
  // Time of day (docs/ig.md): the sun's elevation from the hour, its light and the sky.
  if (timeOfDay_) {
    const double hours = celestial_.hour + celestial_.minute / 60.0;
    const double elevation = 60 * std::sin(std::numbers::pi * (hours - 6) / 12);  // degrees
    const double azimuth = 90 + 180 * (hours - 6) / 12;  // from north, east at 6 h, west at 18 h
    const double ce = std::cos(elevation * kRad);
    const Vec3 toSun{float(ce * std::sin(azimuth * kRad)), float(std::sin(elevation * kRad)),
                     float(-ce * std::cos(azimuth * kRad))};
    const float day = float(std::clamp(std::sin(elevation * kRad) * 4, 0.0, 1.0));
    s.light = base_.light;
    s.light.direction = toSun * -1.0f;
    s.light.enabled = celestial_.sun;
    s.light.color = base_.light.color * (1 - day) + Vec3{1, 0.97f, 0.9f} * day;
    s.light.ambient = base_.light.ambient * (1 - day) + 0.3f * day;
    s.background = base_.background * (1 - day) + Vec3{0.35f, 0.5f, 0.8f} * day;
    s.stars.brightness = celestial_.starField
                             ? base_.stars.brightness * (celestial_.starIntensity / 100) * (1 - day)
                             : 0;
  }
  return s;
}

const scene::Scene& IgWorld::atQuality(bool stars, int replication) {
  scene::Scene& s = frame_;
  // No star is brighter than this limit (the Sun is −27): the light pass drops each on its
  // magnitude alone.
  if (!stars) s.stars.limit = -1000;
  for (scene::Channel& ch : s.channels) {
    ch.width = (ch.width + replication - 1) / replication;
    ch.height = (ch.height + replication - 1) / replication;
  }
  return s;
}

// ---- queries ---------------------------------------------------------------------------------

namespace {

// The nearest t in (0, tMax] where the ray o + t·d meets triangle (a, b, c) — Möller–Trumbore,
// both faces.
std::optional<double> rayTriangle(Vec3d o, Vec3d d, Vec3d a, Vec3d b, Vec3d c, double tMax) {
  const Vec3d e1 = b - a, e2 = c - a;
  const Vec3d p{d.y * e2.z - d.z * e2.y, d.z * e2.x - d.x * e2.z, d.x * e2.y - d.y * e2.x};
  const double det = dot(e1, p);
  if (std::fabs(det) < 1e-12) return std::nullopt;
  const double inv = 1 / det;
  const Vec3d s = o - a;
  const double u = dot(s, p) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  const Vec3d q{s.y * e1.z - s.z * e1.y, s.z * e1.x - s.x * e1.z, s.x * e1.y - s.y * e1.x};
  const double v = dot(d, q) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = dot(e2, q) * inv;
  if (t < 0 || t > tMax) return std::nullopt;
  return t;
}

// Whether the segment o → o + d (t in [0, 1]) meets the box [lo, hi] (slabs, in double; a margin
// of 1e-6 of the extent keeps float boxes conservative).
bool segmentMeetsBox(Vec3d o, Vec3d d, Vec3d lo, Vec3d hi) {
  double t0 = 0, t1 = 1;
  const double os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z}, ls[3] = {lo.x, lo.y, lo.z},
               hs[3] = {hi.x, hi.y, hi.z};
  for (int a = 0; a < 3; ++a) {
    const double margin = 1e-6 * (std::fabs(ls[a]) + std::fabs(hs[a]) + 1);
    const double l = ls[a] - margin, h = hs[a] + margin;
    if (ds[a] == 0) {
      if (os[a] < l || os[a] > h) return false;
      continue;
    }
    double ta = (l - os[a]) / ds[a], tb = (h - os[a]) / ds[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// The nearest hit of the segment o → o + d (t in [0, 1]) with instance `i`'s triangles (its full
// detail), or `best` (the nearest so far).
std::optional<double> instanceHit(const scene::Scene& s, size_t i, Vec3d o, Vec3d d,
                                  std::optional<double> best) {
  const scene::Instance& inst = s.instances[i];
  if (!inst.visible) return best;  // switched off
  const scene::Mesh& mesh = s.meshes[size_t(inst.mesh)];
  // The segment against the instance's world box first.
  const auto box = mesh.bounds();
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner =
        inst.transform.transformPoint({box[k & 1].x, box[(k >> 1) & 1].y, box[(k >> 2) & 1].z});
    lo = {std::min(lo.x, double(corner.x)), std::min(lo.y, double(corner.y)),
          std::min(lo.z, double(corner.z))};
    hi = {std::max(hi.x, double(corner.x)), std::max(hi.y, double(corner.y)),
          std::max(hi.z, double(corner.z))};
  }
  if (!segmentMeetsBox(o, d, lo, hi)) return best;
  auto world = [&](uint32_t index) {
    const Vec3 p = inst.transform.transformPoint(mesh.positions[index]);
    return Vec3d{p.x, p.y, p.z};
  };
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::optional<double> hit =
        rayTriangle(o, d, world(mesh.indices[t]), world(mesh.indices[t + 1]),
                    world(mesh.indices[t + 2]), best.value_or(1.0));
    if (hit) best = hit;
  }
  return best;
}

// The nearest hit of the segment o → o + d (t in [0, 1]) with the database's polygons: through
// the instance tree for the instances it holds (only the leaves the segment meets), one by one for
// the rest.
std::optional<double> polygonHit(const scene::Scene& s, size_t instances, Vec3d o, Vec3d d) {
  std::optional<double> best;
  size_t from = 0;
  if (const scene::InstanceTree* tree = s.instanceTree.get();
      tree && !tree->nodes.empty() && tree->instanceCount <= instances) {
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
      const scene::InstanceTree::Node& n = tree->nodes[stack.back()];
      stack.pop_back();
      if (!segmentMeetsBox(o, d, {n.lo.x, n.lo.y, n.lo.z}, {n.hi.x, n.hi.y, n.hi.z})) continue;
      if (n.count == 0) {
        stack.push_back(n.first);
        stack.push_back(n.first + 1);
        continue;
      }
      for (uint32_t k = n.first; k < n.first + n.count; ++k)
        best = instanceHit(s, tree->order[k], o, d, best);
    }
    for (uint32_t i : tree->loose) best = instanceHit(s, i, o, d, best);
    from = tree->instanceCount;
  }
  for (size_t i = from; i < instances; ++i) best = instanceHit(s, i, o, d, best);
  return best;
}

}  // namespace

std::optional<IgWorld::Ground> IgWorld::groundUnder(Vec3d p) const {
  std::optional<Ground> ground;
  if (const std::optional<TerrainHeight> t = terrainHeight(base_, p.x, p.y, p.z))
    ground = Ground{t->elevation, t->above};
  // The polygons under the point: a vertical segment from far above to far below (world up: the
  // base's normal near the origin, where a database's polygons are).
  constexpr double kReach = 1e5;
  const Vec3d top{p.x, p.y + kReach, p.z};
  if (const std::optional<double> t = polygonHit(base_, baseInstances_, top, {0, -2 * kReach, 0}))
    if (const double y = top.y - *t * 2 * kReach; !ground || y > ground->elevation)
      ground = Ground{y, p.y - y};
  return ground;
}

std::optional<double> IgWorld::segmentHit(Vec3d a, Vec3d b) const {
  std::optional<double> best;
  const double from[3] = {a.x, a.y, a.z}, to[3] = {b.x, b.y, b.z};
  if (const std::optional<TerrainHit> t = lineOfSight(base_, from, to)) best = t->fraction;
  if (const std::optional<double> t = polygonHit(base_, baseInstances_, a, b - a))
    best = std::min(best.value_or(1.0), *t);
  return best;
}

}  // namespace sv::ig
