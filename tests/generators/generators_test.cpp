// The benchmark scenes' names (BENCH.md).
#include "synthvis/generators.h"

#include <gtest/gtest.h>

namespace sv::generators {
namespace {

// BENCH.md's generators are named in one place: every name parses back to its generator, an
// unknown one is refused with the list, and those of later issues say what they need.
TEST(Generators, NamesParseBack) {
  for (Generator g : {Generator::tris, Generator::layers, Generator::grazing, Generator::freeform,
                      Generator::freeformOne, Generator::terrain, Generator::volume,
                      Generator::lights, Generator::city}) {
    const Result<Generator> parsed = parseGenerator(generatorName(g));
    ASSERT_TRUE(parsed.ok()) << generatorName(g);
    EXPECT_EQ(parsed.value(), g);
  }
  EXPECT_STREQ(generatorName(Generator::freeformOne), "freeform-one");
  const Result<Generator> bad = parseGenerator("trees");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message,
            "unknown generator 'trees' (tris, layers, grazing, freeform, freeform-one, terrain, "
            "volume, lights, city)");
}

}  // namespace
}  // namespace sv::generators
