// The image generator's configuration (docs/ig.md, "Configuration"): the database, the display
// channels, the rate, the model table, the network and the quality the frame starts from.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "ig/geo.h"
#include "synthvis/render.h"
#include "synthvis/result.h"
#include "synthvis/scene.h"

namespace sv::ig {

struct IgConfig {
  std::string scene;          // the database (a scene file), relative paths from the config's folder
  double rate = 60;           // frames per second, 1 … 240
  // The channels; empty: the scene's own, or one channel of width × height.
  std::vector<scene::Channel> channels;
  int width = 1280, height = 720;
  std::map<uint16_t, std::string> models;  // CIGI entity type → model file (any scene format)
  GeoOrigin origin;                        // the database's origin (geo.h)
  // UDP: the IG listens on `port` (0: no network — replay, tests) and answers the host at
  // hostAddress:hostPort (or, when hostPort is 0, at whatever address last sent to it).
  uint16_t port = 8004;
  std::string hostAddress = "127.0.0.1";
  uint16_t hostPort = 8005;
  RenderOptions render;       // threads, anti-aliasing, filters: full quality
  double deadline = 0.9;      // the share of a frame period a frame may take (overload.h)
  uint16_t maxEntities = 1024;  // entity IDs 0 … maxEntities − 1
  // Under mpirun (docs/cluster.md): the channels each rank draws, by channel index — rank r draws
  // ranks[r]; empty: channel i on rank i mod N. And how long rank 0 waits at the frame lock for a
  // rank before it ends the job, naming it.
  std::vector<std::vector<int>> ranks;
  double rankTimeout = 5;
  // Channels drawn by several ranks together (synthvis/tile_share.h): each split channel's tiles
  // dealt to its ranks, the first of which assembles and presents it.
  struct Split {
    int channel = 0;
    std::vector<int> ranks;
  };
  std::vector<Split> splits;
};

// What each of `ranks` processes draws under `config` with `channelCount` channels, by rank, in
// channel order: whole channels — the configuration's assignment, or the channels not split
// dealt round the ranks (the j-th on rank j mod ranks) — and its parts of split channels (their
// exchange left for the caller). Errors: a channel on no rank or on two (assigned twice, or
// assigned and split), an index beyond the channels or the ranks, an assignment for another
// number of ranks, and a rank left with nothing to draw.
Result<std::vector<std::vector<ChannelShare>>> channelsByRank(const IgConfig& config,
                                                             int channelCount, int ranks);

// Reads a configuration file; errors name the file and the field.
Result<IgConfig> loadIgConfig(const std::string& path);
Result<IgConfig> parseIgConfig(const std::string& text, const std::string& path);

}  // namespace sv::ig
