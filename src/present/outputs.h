// The presenters behind makePresenter's specs (presenter.cpp parses, these make).
#pragma once

#include <memory>
#include <string>

#include "present/present.h"

namespace sv::present::detail {

// How many frames a file output's writer thread may have waiting before new ones are dropped.
inline constexpr size_t kQueueDepth = 3;

Result<std::unique_ptr<Presenter>> makePngSequence(const std::string& dir);
Result<std::unique_ptr<Presenter>> makeY4mStream(const std::string& path, int rate);
// perChannel: one window per channel instead of one showing the mosaic. Without SDL2 an error.
Result<std::unique_ptr<Presenter>> makeWindow(bool perChannel);

}  // namespace sv::present::detail
