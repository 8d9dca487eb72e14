// makePresenter: an output spec to its presenter; the "null" output.
#include <fmt/format.h>

#include "present/outputs.h"
#include "present/present.h"

namespace sv::present {
namespace {

class NullPresenter final : public Presenter {
 public:
  Status present(const Frame&) override { return {}; }
};

Error specError(const std::string& spec, const std::string& problem) {
  return Error{"", "", fmt::format("output '{}': {} (use png:DIR, y4m:PATH, y4m:-, window, "
                                   "window:channels or null)", spec, problem)};
}

}  // namespace

Result<std::unique_ptr<Presenter>> makePresenter(const std::string& spec, int rate) {
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string arg = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  const bool hasArg = colon != std::string::npos;
  if (kind == "null" && !hasArg) return std::unique_ptr<Presenter>(new NullPresenter);
  if (kind == "png") {
    if (arg.empty()) return specError(spec, "png needs a directory, as png:DIR");
    return detail::makePngSequence(arg);
  }
  if (kind == "y4m") {
    if (arg.empty()) return specError(spec, "y4m needs a file, as y4m:PATH (y4m:- for stdout)");
    return detail::makeY4mStream(arg, rate);
  }
  if (kind == "window") {
    if (hasArg && arg != "channels") return specError(spec, "the window's only option is 'channels'");
    return detail::makeWindow(hasArg);
  }
  return specError(spec, "unknown kind");
}

#ifndef SV_HAVE_SDL2
Result<std::unique_ptr<Presenter>> detail::makeWindow(bool) {
  return Error{"", "", "output 'window': synthvis was built without SDL2 (install libsdl2-dev)"};
}
#endif

}  // namespace sv::present
