// Display channels (SPEC §9): the checks scene::validate makes of Scene::channels.
#pragma once

#include <string>
#include <vector>

#include "synthvis/scene.h"

namespace sv::scene::detail {

// The first problem of `channels` as "channels[i]…: problem", or "" when they are valid: too many,
// a name that is not a plain file-name part or repeats, angles not finite or out of range, a
// frustum with left ≥ right or down ≥ up, a size outside 1 … 8192.
std::string channelsProblem(const std::vector<Channel>& channels);

// True for a channel name that may be part of a file name: 1 … 64 letters, digits, '-' or '_'.
bool isChannelName(const std::string& name);

}  // namespace sv::scene::detail
