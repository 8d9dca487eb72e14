// The IG configuration file (docs/ig.md, "Configuration"), JSON.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "ig/json_input.h"
#include "synthvis/ig.h"

namespace sv::ig {
namespace {

using Json = nlohmann::json;

[[noreturn]] void bad(const std::string& message) { badField(message); }

double number(const Json& v, const char* what, double lo, double hi) {
  if (!v.is_number()) bad(fmt::format("{}: expected a number", what));
  const double x = v.get<double>();
  if (!std::isfinite(x) || x < lo || x > hi)
    bad(fmt::format("{}: {} is outside [{}, {}]", what, x, lo, hi));
  return x;
}

int integer(const Json& v, const char* what, int lo, int hi) {
  const double x = number(v, what, lo, hi);
  if (x != std::floor(x)) bad(fmt::format("{}: expected a whole number", what));
  return int(x);
}

void known(const Json& object, const char* what, std::initializer_list<const char*> keys) {
  if (!object.is_object()) bad(fmt::format("{}: expected an object", what));
  for (const auto& [key, value] : object.items()) {
    bool found = false;
    for (const char* k : keys) found = found || key == k;
    if (!found) bad(fmt::format("{}: unknown field \"{}\"", what, key));
  }
}

// "display": a curved screen instead of channels (docs/ig.md, "A curved screen").
void readDisplay(const Json& display, const Json& root, const std::string& path, IgConfig& c) {
  known(display, "display", {"cylinder", "mpcdi", "correction"});
  IgConfig::DisplayConfig d;
  if (display.contains("cylinder") == display.contains("mpcdi"))
    bad("display: either \"cylinder\" (the demo rig) or \"mpcdi\" (a file) expected");
  if (const auto cyl = display.find("cylinder"); cyl != display.end()) {
    known(*cyl, "display.cylinder", {"width", "height", "overlap"});
    if (cyl->contains("width"))
      d.width = integer((*cyl)["width"], "display.cylinder.width", 16, kMaxRasterSize);
    if (cyl->contains("height"))
      d.height = integer((*cyl)["height"], "display.cylinder.height", 16, kMaxRasterSize);
    if (cyl->contains("overlap"))
      d.overlapDegrees = number((*cyl)["overlap"], "display.cylinder.overlap", 0, 30);
  } else {
    const Json& f = display["mpcdi"];
    if (!f.is_string() || f.get<std::string>().empty())
      bad("display.mpcdi: an MPCDI file name expected");
    d.mpcdi = core::resolvePath(core::directoryOf(path), f.get<std::string>());
  }
  if (display.contains("correction")) {
    const Json& m = display["correction"];
    const std::string name = m.is_string() ? m.get<std::string>() : "";
    if (name == "subfrusta")
      c.render.correction = RenderOptions::Correction::subFrusta;
    else if (name == "bilinear")
      c.render.correction = RenderOptions::Correction::bilinear;
    else if (name == "bicubic")
      c.render.correction = RenderOptions::Correction::bicubic;
    else
      bad("display.correction: subfrusta, bilinear or bicubic");
  }
  if (root.contains("channels"))
    bad("display: a display's projectors are the channels (not with \"channels\")");
  if (!c.splits.empty()) bad("display: a projector is drawn by one rank (not with cluster.split)");
  c.display = d;
}

IgConfig read(const Json& root, const std::string& path) {
  known(root, "configuration",
        {"synthvis-ig", "scene", "rate", "channels", "width", "height", "models", "origin", "port",
         "host", "render", "deadline", "maxEntities", "cluster", "display"});
  IgConfig c;
  if (!root.contains("synthvis-ig") || root["synthvis-ig"] != 1)
    bad("\"synthvis-ig\": 1 expected (the configuration format's version)");
  if (!root.contains("scene") || !root["scene"].is_string() || root["scene"].get<std::string>().empty())
    bad("\"scene\": the database's file name expected");
  c.scene = root["scene"].get<std::string>();
  c.scene = core::resolvePath(core::directoryOf(path), c.scene);
  if (root.contains("rate")) c.rate = number(root["rate"], "rate", 1, 240);
  if (root.contains("width")) c.width = integer(root["width"], "width", 1, kMaxRasterSize);
  if (root.contains("height")) c.height = integer(root["height"], "height", 1, kMaxRasterSize);
  if (const auto it = root.find("channels"); it != root.end()) {
    known(*it, "channels", {"count", "arc", "width", "height", "vfov"});
    const int n = it->contains("count")
                      ? integer((*it)["count"], "channels.count", 1, int(scene::kMaxChannels))
                      : 1;
    const double arc = it->contains("arc") ? number((*it)["arc"], "channels.arc", 1, 180.0 * n - 1)
                                           : 60.0 * n;
    if (arc / n >= 180) bad("channels.arc: each channel must span less than 180°");
    const int w = it->contains("width") ? integer((*it)["width"], "channels.width", 1, kMaxRasterSize)
                                        : c.width;
    const int h = it->contains("height")
                      ? integer((*it)["height"], "channels.height", 1, kMaxRasterSize)
                      : c.height;
    const double vfov = it->contains("vfov") ? number((*it)["vfov"], "channels.vfov", 0, 170) : 0;
    c.channels = scene::arcChannels(n, float(arc), w, h, float(vfov));
  }
  if (const auto it = root.find("models"); it != root.end()) {
    if (!it->is_object()) bad("models: expected an object of entity type → model file");
    for (const auto& [key, value] : it->items()) {
      size_t used = 0;
      int type = -1;
      try {
        type = std::stoi(key, &used);
      } catch (...) {
      }
      if (used != key.size() || type < 0 || type > 65535)
        bad(fmt::format("models: \"{}\" is not an entity type (0 … 65535)", key));
      if (!value.is_string() || value.get<std::string>().empty())
        bad(fmt::format("models.{}: a model file name expected", key));
      std::string file = value.get<std::string>();
      file = core::resolvePath(core::directoryOf(path), file);
      c.models[uint16_t(type)] = file;
    }
  }
  if (const auto it = root.find("origin"); it != root.end()) {
    known(*it, "origin", {"lat", "lon", "alt"});
    c.hasOrigin = true;
    if (it->contains("lat")) c.origin.lat = number((*it)["lat"], "origin.lat", -89, 89);
    if (it->contains("lon")) c.origin.lon = number((*it)["lon"], "origin.lon", -180, 180);
    if (it->contains("alt")) c.origin.alt = number((*it)["alt"], "origin.alt", -1e4, 1e5);
  }
  if (root.contains("port")) c.port = uint16_t(integer(root["port"], "port", 0, 65535));
  if (const auto it = root.find("host"); it != root.end()) {
    known(*it, "host", {"address", "port"});
    if (it->contains("address")) {
      if (!(*it)["address"].is_string()) bad("host.address: expected a dotted IPv4 address");
      c.hostAddress = (*it)["address"].get<std::string>();
    }
    if (it->contains("port")) c.hostPort = uint16_t(integer((*it)["port"], "host.port", 0, 65535));
  }
  c.render.threads = 2;
  if (const auto it = root.find("render"); it != root.end()) {
    known(*it, "render", {"threads", "aa", "textureFilter"});
    if (it->contains("threads"))
      c.render.threads = integer((*it)["threads"], "render.threads", 1, kMaxThreads);
    if (it->contains("aa")) {
      c.render.samples = integer((*it)["aa"], "render.aa", 1, 64);
      if (!isSampleCount(c.render.samples))
        bad(fmt::format("render.aa: {} samples", sampleCountNames()));
    }
    if (it->contains("textureFilter")) {
      const Json& f = (*it)["textureFilter"];
      Result<scene::TextureFilter> filter =
          f.is_string() ? scene::parseTextureFilter(f.get<std::string>())
                        : Result<scene::TextureFilter>(Error{"", "", "expected a name"});
      if (!filter || filter.value() == scene::TextureFilter::inherit)
        bad("render.textureFilter: point, nearest, tri3, bilinear, trilinear3, trilinear or aniso");
      c.render.textureFilter = filter.value();
    }
  }
  if (root.contains("deadline")) c.deadline = number(root["deadline"], "deadline", 0.1, 1);
  if (root.contains("maxEntities"))
    c.maxEntities = uint16_t(integer(root["maxEntities"], "maxEntities", 1, 65535));
  if (const auto it = root.find("cluster"); it != root.end()) {
    known(*it, "cluster", {"ranks", "timeout", "split"});
    if (it->contains("ranks")) {
      const Json& ranks = (*it)["ranks"];
      if (!ranks.is_array() || ranks.empty() || ranks.size() > 4096)
        bad("cluster.ranks: an array of 1 … 4096 arrays of channel indices expected");
      for (size_t r = 0; r < ranks.size(); ++r) {
        if (!ranks[r].is_array()) bad(fmt::format("cluster.ranks[{}]: an array of channel indices expected", r));
        std::vector<int> channels;
        for (size_t k = 0; k < ranks[r].size(); ++k)
          channels.push_back(integer(ranks[r][k], fmt::format("cluster.ranks[{}][{}]", r, k).c_str(), 0,
                                     int(scene::kMaxChannels) - 1));
        c.ranks.push_back(std::move(channels));
      }
    }
    if (it->contains("timeout")) c.rankTimeout = number((*it)["timeout"], "cluster.timeout", 0.1, 3600);
    if (it->contains("split")) {
      const Json& split = (*it)["split"];
      if (!split.is_array() || split.size() > scene::kMaxChannels)
        bad("cluster.split: an array of {\"channel\": C, \"ranks\": [R, …]} expected");
      for (size_t k = 0; k < split.size(); ++k) {
        const std::string at = fmt::format("cluster.split[{}]", k);
        if (!split[k].is_object()) bad(at + ": an object {\"channel\": C, \"ranks\": [R, …]} expected");
        known(split[k], at.c_str(), {"channel", "ranks"});
        IgConfig::Split one;
        if (!split[k].contains("channel")) bad(at + ".channel: missing");
        one.channel = integer(split[k]["channel"], (at + ".channel").c_str(), 0,
                              int(scene::kMaxChannels) - 1);
        const Json* ranks = split[k].contains("ranks") ? &split[k]["ranks"] : nullptr;
        if (!ranks || !ranks->is_array() || ranks->empty() || ranks->size() > 4096)
          bad(at + ".ranks: an array of 1 … 4096 rank numbers expected");
        for (size_t r = 0; r < ranks->size(); ++r)
          one.ranks.push_back(integer((*ranks)[r], fmt::format("{}.ranks[{}]", at, r).c_str(), 0, 4095));
        c.splits.push_back(std::move(one));
      }
    }
  }
  if (const auto it = root.find("display"); it != root.end()) readDisplay(*it, root, path, c);
  c.render.width = c.width;
  c.render.height = c.height;
  return c;
}

}  // namespace

Result<std::vector<std::vector<ChannelShare>>> channelsByRank(const IgConfig& config,
                                                             int channelCount, int ranks) {
  std::vector<std::vector<ChannelShare>> out(static_cast<size_t>(ranks));
  // Who draws each channel: a rank (assigned or dealt), or the split's ranks.
  std::vector<std::string> owner(static_cast<size_t>(channelCount));
  std::vector<const IgConfig::Split*> splitOf(size_t(channelCount), nullptr);
  for (size_t k = 0; k < config.splits.size(); ++k) {
    const IgConfig::Split& split = config.splits[k];
    if (split.channel >= channelCount)
      return Error{"", "", fmt::format("cluster.split[{}]: channel {} does not exist ({} channels)",
                                       k, split.channel, channelCount)};
    if (splitOf[size_t(split.channel)])
      return Error{"", "", fmt::format("cluster.split: channel {} is split twice", split.channel)};
    for (size_t i = 0; i < split.ranks.size(); ++i) {
      if (split.ranks[i] >= ranks)
        return Error{"", "", fmt::format("cluster.split[{}]: rank {} does not exist (the job has {})",
                                         k, split.ranks[i], ranks)};
      if (std::find(split.ranks.begin(), split.ranks.begin() + long(i), split.ranks[i]) !=
          split.ranks.begin() + long(i))
        return Error{"", "", fmt::format("cluster.split[{}]: rank {} is listed twice", k,
                                         split.ranks[i])};
    }
    splitOf[size_t(split.channel)] = &split;
    owner[size_t(split.channel)] = fmt::format("ranks {} (split)", fmt::join(split.ranks, ", "));
  }
  std::vector<std::vector<int>> whole(static_cast<size_t>(ranks));
  if (config.ranks.empty()) {
    int dealt = 0;
    for (int i = 0; i < channelCount; ++i)
      if (!splitOf[size_t(i)]) whole[size_t(dealt++ % ranks)].push_back(i);
  } else {
    if (int(config.ranks.size()) != ranks)
      return Error{"", "",
                   fmt::format("cluster.ranks assigns channels to {} ranks, the job has {}",
                               config.ranks.size(), ranks)};
    for (int r = 0; r < ranks; ++r)
      for (int i : config.ranks[size_t(r)]) {
        if (i >= channelCount)
          return Error{"", "", fmt::format("cluster.ranks[{}]: channel {} does not exist ({} channels)", r, i, channelCount)};
        if (!owner[size_t(i)].empty())
          return Error{"", "", fmt::format("cluster.ranks: channel {} is assigned to {} and to rank {}", i, owner[size_t(i)], r)};
        owner[size_t(i)] = fmt::format("rank {}", r);
      }
    for (int i = 0; i < channelCount; ++i)
      if (owner[size_t(i)].empty())
        return Error{"", "", fmt::format("cluster.ranks: channel {} is assigned to no rank", i)};
    whole = config.ranks;
  }
  // By rank, in channel order (the order every part meets its shared channels in).
  for (int i = 0; i < channelCount; ++i) {
    if (const IgConfig::Split* split = splitOf[size_t(i)]) {
      for (size_t p = 0; p < split->ranks.size(); ++p)
        out[size_t(split->ranks[p])].push_back(
            ChannelShare{i, TileShare{int(split->ranks.size()), int(p), nullptr}});
      continue;
    }
    for (int r = 0; r < ranks; ++r)
      if (std::find(whole[size_t(r)].begin(), whole[size_t(r)].end(), i) != whole[size_t(r)].end())
        out[size_t(r)].push_back(ChannelShare{i, {}});
  }
  for (int r = 0; r < ranks; ++r)
    if (out[size_t(r)].empty())
      return Error{"", "",
                   config.ranks.empty() && config.splits.empty()
                       ? fmt::format("{} ranks for {} channels: a rank would draw nothing (give "
                                     "cluster.ranks or cluster.split, or fewer ranks)",
                                     ranks, channelCount)
                       : fmt::format("cluster: rank {} draws nothing", r)};
  return out;
}

Result<IgConfig> parseIgConfig(const std::string& text, const std::string& path) {
  return parseJsonInput<IgConfig>(text, path, [&](const Json& root) { return read(root, path); });
}

Result<IgConfig> loadIgConfig(const std::string& path) {
  Result<std::string> text = readJsonInput(path);
  if (!text) return text.error();
  return parseIgConfig(text.value(), path);
}

}  // namespace sv::ig
