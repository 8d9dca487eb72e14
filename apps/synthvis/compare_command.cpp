// `synthvis compare IMAGE REFERENCE [--edges MASK]`: differences in linear light, over all pixels
// and over the pixels an edge crosses (synthvis/ground_truth.h).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "synthvis/ground_truth.h"
#include "synthvis/image.h"

namespace sv::cli {
namespace {

int runCompare(const std::string& imagePath, const std::string& referencePath,
               const std::string& edgesPath) {
  auto a = readPng(imagePath);
  if (!a) return fail(a.error());
  auto b = readPng(referencePath);
  if (!b) return fail(b.error());
  Result<Image> mask = Image{};
  if (!edgesPath.empty()) {
    mask = readPng(edgesPath);
    if (!mask) return fail(mask.error());
  }
  auto d =
      reference::compareImages(a.value(), b.value(), edgesPath.empty() ? nullptr : &mask.value());
  if (!d) return fail({imagePath, "", d.error().message});
  const auto& r = d.value();
  fmt::print(
      "all pixels ({}): RMSE {:.6f}, PSNR {:.2f} dB | edge pixels ({}): RMSE {:.6f}, "
      "PSNR {:.2f} dB (linear light)\n",
      r.pixels, r.rmse, r.psnrDb, r.edgePixels, r.edgeRmse, r.edgePsnrDb);
  return 0;
}

}  // namespace

void addCompareCommand(CLI::App& app, Run& run) {
  struct CompareArgs {
    std::string compareImage, compareReference, compareEdges;
  };
  auto args = std::make_shared<CompareArgs>();
  CLI::App* compare = app.add_subcommand(
      "compare", "RMSE and PSNR of IMAGE against REFERENCE in linear light, all and edge pixels");
  compare->add_option("image", args->compareImage, "PNG image")->required();
  compare->add_option("reference", args->compareReference, "PNG reference, e.g. from `truth`")
      ->required();
  compare->add_option("--edges", args->compareEdges,
                      "edge mask from `truth --edges` (default: pixels "
                      "whose neighbours differ in the reference)");
  compare->callback([&run, args] {
    run = [args] {
      return runCompare(args->compareImage, args->compareReference, args->compareEdges);
    };
  });
}

}  // namespace sv::cli
