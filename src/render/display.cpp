// The public display (synthvis/display.h) over the display stage's tables (render/correction.h),
// and the renderer's frames of it.
#include "synthvis/display.h"

#include <fmt/format.h>

#include "display/mpcdi.h"
#include "render/correction.h"

namespace sv {

Display::Display(std::shared_ptr<const render::DisplaySetup> setup) : setup_(std::move(setup)) {}

Display Display::cylinder(int width, int height, double overlapDegrees) {
  return Display(std::make_shared<const render::DisplaySetup>(
      render::cylinderDisplay(width, height, overlapDegrees)));
}

Result<Display> Display::readMpcdi(const std::string& path) {
  Result<render::DisplaySetup> setup = render::mpcdiDisplay(path);
  if (!setup.ok()) return setup.error();
  return Display(std::make_shared<const render::DisplaySetup>(std::move(setup).value()));
}

Status Display::writeMpcdi(const std::string& path) const {
  Result<display::Mpcdi> m = render::mpcdiOf(*setup_);
  if (!m.ok()) {
    Error e = m.error();
    if (e.file.empty()) e.file = path;
    return e;
  }
  return display::writeMpcdi(path, m.value());
}

int Display::projectorCount() const { return int(setup_->projectors.size()); }
const std::string& Display::projectorName(int p) const {
  return setup_->projectors[size_t(p)].name;
}
int Display::projectorWidth(int p) const { return setup_->projectors[size_t(p)].table.width; }
int Display::projectorHeight(int p) const { return setup_->projectors[size_t(p)].table.height; }
bool Display::hasGeometry() const { return setup_->rig.has_value(); }
Display Display::scaled(int r) const {
  if (r <= 1) return *this;
  return Display(std::make_shared<const render::DisplaySetup>(render::scaledDisplay(*setup_, r)));
}

}  // namespace sv
