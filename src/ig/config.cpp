// The IG configuration file (docs/ig.md, "Configuration"), JSON.
#include "ig/config.h"

#include "ig/json_input.h"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

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

std::string directoryOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

IgConfig read(const Json& root, const std::string& path) {
  known(root, "configuration",
        {"synthvis-ig", "scene", "rate", "channels", "width", "height", "models", "origin", "port",
         "host", "render", "deadline", "maxEntities", "cluster"});
  IgConfig c;
  if (!root.contains("synthvis-ig") || root["synthvis-ig"] != 1)
    bad("\"synthvis-ig\": 1 expected (the configuration format's version)");
  if (!root.contains("scene") || !root["scene"].is_string() || root["scene"].get<std::string>().empty())
    bad("\"scene\": the database's file name expected");
  c.scene = root["scene"].get<std::string>();
  if (c.scene[0] != '/') c.scene = directoryOf(path) + c.scene;
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
      if (file[0] != '/') file = directoryOf(path) + file;
      c.models[uint16_t(type)] = file;
    }
  }
  if (const auto it = root.find("origin"); it != root.end()) {
    known(*it, "origin", {"lat", "lon", "alt"});
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
      if (c.render.samples & (c.render.samples - 1) || c.render.samples == 2 ||
          c.render.samples == 32)
        bad("render.aa: 1, 4, 8, 16 or 64 samples");
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
    known(*it, "cluster", {"ranks", "timeout"});
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
  }
  c.render.width = c.width;
  c.render.height = c.height;
  return c;
}

}  // namespace

Result<std::vector<std::vector<int>>> channelsByRank(const IgConfig& config, int channelCount,
                                                    int ranks) {
  std::vector<std::vector<int>> out(static_cast<size_t>(ranks));
  if (config.ranks.empty()) {
    if (ranks > channelCount)
      return Error{"", "",
                   fmt::format("{} ranks for {} channels: a rank would draw nothing (give "
                               "cluster.ranks, or fewer ranks)",
                               ranks, channelCount)};
    for (int i = 0; i < channelCount; ++i) out[size_t(i % ranks)].push_back(i);
    return out;
  }
  if (int(config.ranks.size()) != ranks)
    return Error{"", "",
                 fmt::format("cluster.ranks assigns channels to {} ranks, the job has {}",
                             config.ranks.size(), ranks)};
  std::vector<int> owner(size_t(channelCount), -1);
  for (int r = 0; r < ranks; ++r)
    for (int i : config.ranks[size_t(r)]) {
      if (i >= channelCount)
        return Error{"", "", fmt::format("cluster.ranks[{}]: channel {} does not exist ({} channels)", r, i, channelCount)};
      if (owner[size_t(i)] >= 0)
        return Error{"", "", fmt::format("cluster.ranks: channel {} is assigned to rank {} and rank {}", i, owner[size_t(i)], r)};
      owner[size_t(i)] = r;
    }
  for (int i = 0; i < channelCount; ++i)
    if (owner[size_t(i)] < 0)
      return Error{"", "", fmt::format("cluster.ranks: channel {} is assigned to no rank", i)};
  return config.ranks;
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
