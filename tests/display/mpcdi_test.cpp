// MPCDI files: the writer's archives read back exactly, an archive made by hand (minizip's own
// file writer, XML text and PFM bytes written here) read as the standard lays it out, malformed
// archives refused with one line naming the file, the entry and the problem, and the 3d profile's
// directions against the analytic display geometry.
#include <gtest/gtest.h>
#include <minizip/zip.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>


#include "display/mpcdi.h"
#include "support/temp_dir.h"
#include "texture/png.h"

namespace sv::display {
namespace {

const float kNaN = std::numeric_limits<float>::quiet_NaN();

// A file in this process's own directory (support/temp_dir.h).
std::string tempPath(const char* name) { return sv::tests::processTemp().path(name); }

// Bit-exact float comparison (NaN payloads and −0 included).
bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * 4) == 0;
}

FloatMap warp(int w, int h, float seed) {
  FloatMap m;
  m.width = w;
  m.height = h;
  m.values.resize(size_t(w) * size_t(h) * 3);
  for (size_t i = 0; i < m.values.size(); ++i) m.values[i] = seed + float(i) * 0.001f;
  return m;
}

Mpcdi sample3d() {
  Mpcdi m;
  m.profile = MpcdiProfile::simulation3d;
  m.level = 2;
  m.date = "2026-12-05 15:00:00";
  MpcdiBuffer b;
  b.id = "buffer & co";  // escaped in the XML
  b.xResolution = 64;
  b.yResolution = 20;
  for (int i = 0; i < 2; ++i) {
    MpcdiRegion r;
    r.id = "region" + std::to_string(i);
    r.xResolution = 32;
    r.yResolution = 20;
    r.x = 0.5 * i;
    r.y = 0;
    r.xSize = 0.5;
    r.ySize = 1;
    r.frustum = MpcdiFrustum{{-15.25 + 30.5 * i, 1.0 / 3, 0.1}, {-17.5, 16.125, -10.0 / 7, 11}};
    r.warp = warp(9, 5, float(i));
    // The invalid marker, a negative zero, a denormal and an extreme value survive bit for bit.
    r.warp.values[0] = r.warp.values[1] = r.warp.values[2] = kNaN;
    r.warp.values[3] = -0.0f;
    r.warp.values[4] = std::numeric_limits<float>::denorm_min();
    r.warp.values[5] = std::numeric_limits<float>::max();
    BlendMap alpha;
    alpha.width = 7;
    alpha.height = 3;
    alpha.bitDepth = 8;
    for (int k = 0; k < 21; ++k) alpha.codes.push_back(uint16_t(k * 12));
    r.alpha = alpha;
    r.alphaGammaEmbedded = 2.2;
    if (i == 1) {
      BlendMap beta;
      beta.width = 2;
      beta.height = 2;
      beta.bitDepth = 16;
      beta.codes = {0, 1000, 65535, 7};
      r.beta = beta;
      FloatMap d;
      d.width = 3;
      d.height = 2;
      d.channels = 1;
      d.values = {0.5f, -1, 2, 3, 4.25f, 1e-30f};
      r.distortion = d;
      r.coordinateFrame = MpcdiCoordinateFrame{{1.5, -2, 3}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}};
      r.warpPath = "custom/path warp.pfm";
    }
    b.regions.push_back(std::move(r));
  }
  m.buffers.push_back(std::move(b));
  return m;
}

// A buffer's or a region's id and resolution.
template <class T>
void expectSameHeader(const T& a, const T& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.xResolution, b.xResolution);
  EXPECT_EQ(a.yResolution, b.yResolution);
}

void expectSame(const Mpcdi& a, const Mpcdi& b) {
  EXPECT_EQ(a.profile, b.profile);
  EXPECT_EQ(a.level, b.level);
  EXPECT_EQ(a.version, b.version);
  EXPECT_EQ(a.date, b.date);
  ASSERT_EQ(a.buffers.size(), b.buffers.size());
  for (size_t i = 0; i < a.buffers.size(); ++i) {
    const MpcdiBuffer &x = a.buffers[i], &y = b.buffers[i];
    expectSameHeader(x, y);
    ASSERT_EQ(x.regions.size(), y.regions.size());
    for (size_t j = 0; j < x.regions.size(); ++j) {
      const MpcdiRegion &r = x.regions[j], &s = y.regions[j];
      expectSameHeader(r, s);
      EXPECT_EQ(r.x, s.x);
      EXPECT_EQ(r.y, s.y);
      EXPECT_EQ(r.xSize, s.xSize);
      EXPECT_EQ(r.ySize, s.ySize);
      ASSERT_EQ(r.frustum.has_value(), s.frustum.has_value());
      if (r.frustum) {
        EXPECT_EQ(r.frustum->orientation.yawDegrees, s.frustum->orientation.yawDegrees);
        EXPECT_EQ(r.frustum->orientation.pitchDegrees, s.frustum->orientation.pitchDegrees);
        EXPECT_EQ(r.frustum->orientation.rollDegrees, s.frustum->orientation.rollDegrees);
        EXPECT_EQ(r.frustum->window.leftDegrees, s.frustum->window.leftDegrees);
        EXPECT_EQ(r.frustum->window.rightDegrees, s.frustum->window.rightDegrees);
        EXPECT_EQ(r.frustum->window.downDegrees, s.frustum->window.downDegrees);
        EXPECT_EQ(r.frustum->window.upDegrees, s.frustum->window.upDegrees);
      }
      ASSERT_EQ(r.coordinateFrame.has_value(), s.coordinateFrame.has_value());
      if (r.coordinateFrame) {
        EXPECT_EQ(std::memcmp(&*r.coordinateFrame, &*s.coordinateFrame, sizeof(MpcdiCoordinateFrame)), 0);
      }
      EXPECT_EQ(r.warp.width, s.warp.width);
      EXPECT_EQ(r.warp.height, s.warp.height);
      EXPECT_EQ(r.warp.channels, s.warp.channels);
      EXPECT_TRUE(sameBits(r.warp.values, s.warp.values));
      EXPECT_EQ(r.geometricUnit, s.geometricUnit);
      EXPECT_EQ(r.interpolation, s.interpolation);
      EXPECT_EQ(r.originOf3DData, s.originOf3DData);
      EXPECT_EQ(r.alphaGammaEmbedded, s.alphaGammaEmbedded);
      for (const auto& [p, q] : {std::pair{&r.alpha, &s.alpha}, std::pair{&r.beta, &s.beta}}) {
        ASSERT_EQ(p->has_value(), q->has_value());
        if (*p) {
          EXPECT_EQ((*p)->width, (*q)->width);
          EXPECT_EQ((*p)->height, (*q)->height);
          EXPECT_EQ((*p)->bitDepth, (*q)->bitDepth);
          EXPECT_EQ((*p)->codes, (*q)->codes);
        }
      }
      ASSERT_EQ(r.distortion.has_value(), s.distortion.has_value());
      if (r.distortion) {
        EXPECT_EQ(r.distortion->channels, s.distortion->channels);
        EXPECT_TRUE(sameBits(r.distortion->values, s.distortion->values));
      }
    }
  }
}

TEST(Mpcdi, WritersArchiveReadsBackExactly) {
  const Mpcdi m = sample3d();
  Result<std::string> bytes = encodeMpcdi(m, "sample.mpcdi");
  ASSERT_TRUE(bytes.ok()) << bytes.error().str();
  Result<Mpcdi> back = parseMpcdi(bytes->data(), bytes->size(), "sample.mpcdi");
  ASSERT_TRUE(back.ok()) << back.error().str();
  expectSame(m, back.value());
  // Default names where none was given; the given one kept.
  EXPECT_EQ(back->buffers[0].regions[0].warpPath, "buffer & co/region0_warp.pfm");
  EXPECT_EQ(back->buffers[0].regions[0].alphaPath, "buffer & co/region0_alpha.png");
  EXPECT_EQ(back->buffers[0].regions[1].warpPath, "custom/path warp.pfm");
  // Written again, the same bytes: the writer is a function of the data alone.
  Result<std::string> again = encodeMpcdi(back.value(), "again.mpcdi");
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again.value(), bytes.value());
}

TEST(Mpcdi, FileRoundTripIn2dProfile) {
  Mpcdi m = sample3d();
  m.profile = MpcdiProfile::media2d;
  m.level = 1;
  m.buffers[0].regions[0].frustum.reset();  // the 2d profile needs none
  const std::string path = tempPath("sv_display_roundtrip.mpcdi");
  ASSERT_TRUE(writeMpcdi(path, m).ok());
  Result<Mpcdi> back = readMpcdi(path);
  ASSERT_TRUE(back.ok()) << back.error().str();
  expectSame(m, back.value());
  std::filesystem::remove(path);
}

TEST(Pfm, BothByteOrdersAndBottomFirstRows) {
  // A 2 × 2 single-channel PFM in big-endian order (positive scale): the file's first row is the
  // image's bottom.
  std::string s = "Pf\n2 2\n1.0\n";
  for (float v : {3.0f, 4.0f, 1.0f, 2.0f}) {  // bottom row 3 4, top row 1 2
    const uint32_t be = __builtin_bswap32(std::bit_cast<uint32_t>(v));
    s.append(reinterpret_cast<const char*>(&be), 4);
  }
  Result<FloatMap> m = parsePfm(s, "be.pfm");
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->channels, 1);
  EXPECT_EQ(m->values, (std::vector<float>{1, 2, 3, 4}));
  // The writer's little-endian form of the same map reads back the same.
  Result<FloatMap> le = parsePfm(encodePfm(m.value()), "le.pfm");
  ASSERT_TRUE(le.ok());
  EXPECT_EQ(le->values, m->values);
  EXPECT_EQ(encodePfm(m.value()).substr(0, 11), "Pf\n2 2\n-1.0");
}

// ---------------------------------------------------------------------------------------------
// A hand-made archive: minizip's file writer (not the project's), with the XML and PFM bytes
// laid out here from the standard.

struct Entry {
  std::string name, bytes;
  int method = Z_DEFLATED;
};
std::string handZip(const std::vector<Entry>& entries) {
  const std::string path = tempPath("sv_display_hand.zip");
  zipFile zf = zipOpen(path.c_str(), APPEND_STATUS_CREATE);
  EXPECT_NE(zf, nullptr);
  for (const Entry& e : entries) {
    zip_fileinfo info{};
    EXPECT_EQ(zipOpenNewFileInZip(zf, e.name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr,
                                  e.method, Z_DEFAULT_COMPRESSION),
              ZIP_OK);
    EXPECT_EQ(zipWriteInFileInZip(zf, e.bytes.data(), unsigned(e.bytes.size())), ZIP_OK);
    EXPECT_EQ(zipCloseFileInZip(zf), ZIP_OK);
  }
  EXPECT_EQ(zipClose(zf, nullptr), ZIP_OK);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  return bytes;
}

// A little-endian "PF" file of w × h samples given top row first.
std::string handPfm(int w, int h, const std::vector<float>& topFirst, const char* scale = "-1.000000") {
  std::string s = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n" + scale + "\n";
  for (int y = h - 1; y >= 0; --y)
    s.append(reinterpret_cast<const char*>(topFirst.data() + size_t(y) * size_t(w) * 3),
             size_t(w) * 12);
  return s;
}

// MPCDI 2.0 style: xResolution spelt in lower camel case, geometry in place of level, fileSet.
const char* kHandXml = R"(<?xml version="1.0" encoding="utf-8"?>
<MPCDI profile="3d" geometry="1" color="1" date="2026-12-05" version="2.0">
  <display>
    <buffer id="main" xResolution="6" yResolution="4">
      <region id="left" xResolution="6" yResolution="4" x="0" y="0" xsize="1" ysize="1">
        <frustum>
          <yaw>-30</yaw><pitch>5</pitch><roll>0</roll>
          <rightAngle>20</rightAngle><leftAngle>-20</leftAngle>
          <upAngle>10</upAngle><downAngle>-10</downAngle>
        </frustum>
      </region>
    </buffer>
  </display>
  <files>
    <fileSet region="left">
      <geometryWarpFile>
        <path>left/warp.pfm</path>
        <geometricUnit>mm</geometricUnit>
        <interpolation>linear</interpolation>
        <originOf3DData>idealEyePoint</originOf3DData>
      </geometryWarpFile>
      <alphaMap>
        <path>left/alpha.png</path>
        <componentDepth>1</componentDepth>
        <bitDepth>8</bitDepth>
        <gammaEmbedded>2</gammaEmbedded>
      </alphaMap>
    </fileSet>
  </files>
</MPCDI>
)";

// The hand sample's 3 × 2 warp, top row first: the frustum image's top edge, then its bottom
// edge with the last sample marked invalid.
const std::vector<float> kHandWarp = {0, 0, 0, 0.5f, 0, 0, 1, 0, 0,
                                      0, 1, 0, 0.5f, 1, 0, kNaN, kNaN, kNaN};

std::string handAlpha() {
  const uint8_t codes[4] = {255, 128, 64, 0};
  Result<std::vector<uint8_t>> png = texture::encodePngGrey8("alpha.png", 2, 2, codes);
  EXPECT_TRUE(png.ok());
  return std::string(png->begin(), png->end());
}

std::string handArchive() {
  return handZip({{"mpcdi.xml", kHandXml}, {"left/warp.pfm", handPfm(3, 2, kHandWarp)},
                  {"left/alpha.png", handAlpha()}});
}

TEST(Mpcdi, HandMadeSampleReadsAsTheStandardLaysItOut) {
  const std::string zip = handArchive();
  Result<Mpcdi> m = parseMpcdi(zip.data(), zip.size(), "hand.mpcdi");
  ASSERT_TRUE(m.ok()) << m.error().str();
  EXPECT_EQ(m->profile, MpcdiProfile::simulation3d);
  EXPECT_EQ(m->level, 1);
  EXPECT_EQ(m->version, "2.0");
  ASSERT_EQ(m->buffers.size(), 1u);
  EXPECT_EQ(m->buffers[0].id, "main");
  EXPECT_EQ(m->buffers[0].xResolution, 6);
  ASSERT_EQ(m->buffers[0].regions.size(), 1u);
  const MpcdiRegion& r = m->buffers[0].regions[0];
  EXPECT_EQ(r.id, "left");
  EXPECT_EQ(r.xResolution, 6);
  EXPECT_EQ(r.yResolution, 4);
  ASSERT_TRUE(r.frustum);
  EXPECT_EQ(r.frustum->orientation.yawDegrees, -30);
  EXPECT_EQ(r.frustum->orientation.pitchDegrees, 5);
  EXPECT_EQ(r.frustum->window.leftDegrees, -20);
  EXPECT_EQ(r.frustum->window.upDegrees, 10);
  EXPECT_EQ(r.geometricUnit, "mm");
  EXPECT_EQ(r.warp.width, 3);
  EXPECT_EQ(r.warp.height, 2);
  EXPECT_TRUE(sameBits(r.warp.values, kHandWarp));
  ASSERT_TRUE(r.alpha);
  EXPECT_EQ(r.alpha->bitDepth, 8);
  EXPECT_EQ(r.alpha->codes, (std::vector<uint16_t>{255, 128, 64, 0}));
  EXPECT_EQ(r.alphaGammaEmbedded, 2);
  EXPECT_FALSE(r.beta);

  // On the 6 × 4 region the samples sit at x = 1, 3, 5 and y = 1, 3.
  EXPECT_EQ(sampleWarp(r, 1, 1).value(), (Vec2{0, 0}));         // a sample centre
  EXPECT_EQ(sampleWarp(r, 3, 1).value(), (Vec2{0.5f, 0}));      // the next
  EXPECT_EQ(sampleWarp(r, 2, 1).value(), (Vec2{0.25f, 0}));     // halfway: bilinear
  EXPECT_EQ(sampleWarp(r, 1, 2).value(), (Vec2{0, 0.5f}));
  EXPECT_EQ(sampleWarp(r, 0.5, 1).value(), (Vec2{-0.125f, 0}));  // beyond: extrapolated
  EXPECT_FALSE(sampleWarp(r, 5, 3).has_value());                 // the invalid sample itself
  EXPECT_FALSE(sampleWarp(r, 4, 2).has_value());                 // it weighs in
  // Pixel (0, 0)'s centre (0.5, 0.5) is a quarter cell beyond sample (0, 0) both ways: u = −0.125,
  // v = −0.25 — taken through the frustum, yaw −30 then pitch 5 of
  // (tan −20° + u·(tan 20° − tan −20°), tan 10° − v·(tan 10° − tan −10°), −1).
  Result<DirectionMap> d = directionMap(r);
  ASSERT_TRUE(d.ok());
  const double k = std::numbers::pi / 180;
  const double t20 = std::tan(20 * k), t10 = std::tan(10 * k);
  const Vec3 body = normalize(Vec3{float(-t20 - 0.125 * 2 * t20), float(t10 + 0.25 * 2 * t10), -1});
  const Vec3 expected = rotationOf({-30, 5, 0}).apply(body.x, body.y, body.z);
  ASSERT_TRUE(d->isValid(0, 0));
  EXPECT_NEAR(d->direction(0, 0).x, expected.x, 1e-6);
  EXPECT_NEAR(d->direction(0, 0).y, expected.y, 1e-6);
  EXPECT_NEAR(d->direction(0, 0).z, expected.z, 1e-6);
  EXPECT_TRUE(d->isValid(2, 3));
  EXPECT_FALSE(d->isValid(3, 0));  // pixels x ≥ 3 reach into the invalid sample's cell
}

// ---------------------------------------------------------------------------------------------
// Malformed archives: each refused with one line naming the file, the entry and the problem.

std::string errorOf(const std::string& zip, const MpcdiLimits& limits = {}) {
  Result<Mpcdi> m = parseMpcdi(zip.data(), zip.size(), "bad.mpcdi", limits);
  EXPECT_FALSE(m.ok());
  return m.ok() ? "" : m.error().str();
}

std::string withXml(const std::string& xml) {
  return handZip({{"mpcdi.xml", xml}, {"left/warp.pfm", handPfm(3, 2, kHandWarp)},
                  {"left/alpha.png", handAlpha()}});
}
std::string withWarp(const std::string& pfm) {
  return handZip({{"mpcdi.xml", kHandXml}, {"left/warp.pfm", pfm}, {"left/alpha.png", handAlpha()}});
}
std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(MpcdiErrors, TruncatedOrNotAZip) {
  const std::string zip = handArchive();
  EXPECT_EQ(errorOf(zip.substr(0, zip.size() / 2)),
            "bad.mpcdi: not a zip archive (no end of central directory, or it is damaged)");
  EXPECT_EQ(errorOf(""), "bad.mpcdi: not a zip archive (no end of central directory, or it is damaged)");
}

TEST(MpcdiErrors, MissingXmlAndMissingEntries) {
  EXPECT_EQ(errorOf(handZip({{"readme.txt", "hello"}})), "bad.mpcdi: the archive has no mpcdi.xml");
  EXPECT_EQ(errorOf(handZip({{"mpcdi.xml", kHandXml}, {"left/alpha.png", handAlpha()}})),
            "bad.mpcdi:left/warp.pfm: no such entry in the archive");
}

TEST(MpcdiErrors, MalformedXml) {
  EXPECT_EQ(errorOf(withXml("<MPCDI profile=\"3d\" level=\"1\">\n<display>\n</MPCDI>")),
            "bad.mpcdi:mpcdi.xml:2: malformed XML (XML_ERROR_MISMATCHED_ELEMENT)");
  EXPECT_EQ(errorOf(withXml("<Other/>")), "bad.mpcdi:mpcdi.xml: the root element is not <MPCDI>");
  EXPECT_EQ(errorOf(withXml(replaced(kHandXml, "profile=\"3d\"", "profile=\"sl\""))),
            "bad.mpcdi:mpcdi.xml:2: profile 'sl' is not supported (only 2d and 3d)");
  EXPECT_EQ(errorOf(withXml(replaced(kHandXml, "<frustum>", "<frustumX>"))).substr(0, 20),
            "bad.mpcdi:mpcdi.xml:");  // the frustumX … </frustum> mismatch
  EXPECT_EQ(errorOf(withXml(replaced(kHandXml, "<yaw>-30</yaw>", "<yaw>west</yaw>"))),
            "bad.mpcdi:mpcdi.xml:7: yaw: 'west' is not a finite number");
  EXPECT_EQ(errorOf(withXml(replaced(kHandXml, "<yaw>-30</yaw>", "<yaw>nan</yaw>"))),
            "bad.mpcdi:mpcdi.xml:7: yaw: 'nan' is not a finite number");
  EXPECT_EQ(errorOf(withXml(replaced(kHandXml, "xResolution=\"6\" yResolution=\"4\" x=",
                                     "xResolution=\"99999\" yResolution=\"4\" x="))),
            "bad.mpcdi:mpcdi.xml:5: Xresolution: '99999' is not a whole number in 1 … 16384");
  EXPECT_EQ(errorOf(withXml(replaced(kHandXml, "fileSet region=\"left\"", "fileSet region=\"right\""))),
            "bad.mpcdi:mpcdi.xml:15: <fileset> for unknown region 'right'");
  // The 3d profile needs a frustum per region.
  std::string noFrustum = kHandXml;
  noFrustum.erase(noFrustum.find("<frustum>"),
                  noFrustum.find("</frustum>") + 10 - noFrustum.find("<frustum>"));
  EXPECT_EQ(errorOf(withXml(noFrustum)),
            "bad.mpcdi:mpcdi.xml:5: region 'left' has no <frustum> (the 3d profile needs one)");
  // Bit depth stated against the PNG's.
  EXPECT_EQ(errorOf(withXml(replaced(kHandXml, "<bitDepth>8", "<bitDepth>16"))),
            "bad.mpcdi:mpcdi.xml:25: bitDepth 16 but left/alpha.png is a 8-bit PNG");
}

TEST(MpcdiErrors, BadPfmHeaders) {
  const struct {
    std::string pfm, error;
  } cases[] = {
      {"P6\n2 2\n255\n", "not a PFM file (it must begin with \"PF\" or \"Pf\")"},
      {"PF\n2 two\n-1.0\n", "PFM header: the height is not a whole number"},
      {"PF\n2 2\n0\n" + std::string(48, '\0'), "PFM header: the scale must be a non-zero number"},
      {handPfm(3, 2, kHandWarp).substr(0, 40),  // truncated
       "PFM of 3 × 2 × 3 floats needs 72 bytes of samples, the file has 23"},
      {"Pf\n2 2\n-1.0\n" + std::string(16, '\0'),  // a one-channel map cannot be a warp
       "a geometry warp must have three components per sample (\"PF\", not \"Pf\")"},
      // The header alone claims the grids: refused on their size, not on the missing bytes.
      {"PF\n20000 4\n-1.0\n", "PFM of 20000 × 4 samples: each side must be 1 … 16384"},
      {"PF\n16384 16384\n-1.0\n", "PFM of 16384 × 16384 samples: more than 67108864"},
  };
  for (const auto& c : cases) EXPECT_EQ(errorOf(withWarp(c.pfm)), "bad.mpcdi:left/warp.pfm: " + c.error);
}

TEST(MpcdiErrors, AbsurdSizesRefusedBeforeAllocating) {
  // An entry declaring more than the cap, and more regions than the limit.
  MpcdiLimits small;
  small.maxEntryBytes = 40;
  EXPECT_EQ(errorOf(handArchive(), small),
            "bad.mpcdi:left/warp.pfm: declares 89 bytes decompressed, more than the limit of 40");
  std::string many = "<MPCDI profile=\"2d\" level=\"1\"><display><buffer id=\"b\">";
  for (int i = 0; i < 65; ++i)
    many += "<region id=\"r" + std::to_string(i) +
            "\" Xresolution=\"2\" Yresolution=\"2\" x=\"0\" y=\"0\" xsize=\"1\" ysize=\"1\"/>";
  many += "</buffer></display><files/></MPCDI>";
  EXPECT_EQ(errorOf(withXml(many)), "bad.mpcdi:mpcdi.xml:1: more than 64 regions");
}

TEST(MpcdiErrors, NonFiniteWarpValues) {
  std::vector<float> w = kHandWarp;
  w[4] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(errorOf(withWarp(handPfm(3, 2, w))),
            "bad.mpcdi:left/warp.pfm: warp sample (1, 0) is (0.5, inf, 0): not finite, and not the "
            "invalid marker (x and y both NaN)");
  w = kHandWarp;
  w[0] = kNaN;  // x alone NaN is not the marker
  EXPECT_EQ(errorOf(withWarp(handPfm(3, 2, w))),
            "bad.mpcdi:left/warp.pfm: warp sample (0, 0) is (nan, 0, 0): not finite, and not the "
            "invalid marker (x and y both NaN)");
}

TEST(MpcdiErrors, DamagedEntryFailsItsCrc) {
  // A stored (uncompressed) warp with one sample byte changed after the CRC was computed.
  std::string zip = handZip({{"mpcdi.xml", kHandXml},
                             {"left/warp.pfm", handPfm(3, 2, kHandWarp), 0},
                             {"left/alpha.png", handAlpha()}});
  const std::string header = "PF\n3 2\n-1.000000\n";
  const size_t at = zip.find(header);
  ASSERT_NE(at, std::string::npos);
  zip[at + header.size() + 5] ^= 0x40;
  EXPECT_EQ(errorOf(zip), "bad.mpcdi:left/warp.pfm: CRC-32 mismatch: the entry is damaged");
}

TEST(MpcdiErrors, WriterRefusesWhatTheReaderWould) {
  Mpcdi m = sample3d();
  m.buffers[0].regions[1].id = "region0";
  Result<std::string> r = encodeMpcdi(m, "out.mpcdi");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().str(), "out.mpcdi:mpcdi.xml: region id 'region0' is empty or not unique");
  m = sample3d();
  m.buffers[0].regions[0].warp.values[7] = std::numeric_limits<float>::infinity();
  r = encodeMpcdi(m, "out.mpcdi");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().str().find("out.mpcdi:buffer & co/region0_warp.pfm: warp sample (2, 0)"),
            std::string::npos)
      << r.error().str();
}

TEST(MpcdiErrors, WriterRefusesBadRegions) {
  const struct {
    void (*spoil)(MpcdiRegion&);
    std::string error;
  } cases[] = {
      {[](MpcdiRegion& r) { r.xResolution = 0; },
       "region 'region0': 0 × 20 pixels, each side must be 1 … 16384"},
      {[](MpcdiRegion& r) { r.xSize = 0.8; },  // 0.25 + 0.8 > 1
       "region 'region0': the region must lie within its buffer (x, y ≥ 0, sizes > 0, x + xsize "
       "and y + ysize ≤ 1)"},
      {[](MpcdiRegion& r) { r.frustum->window.leftDegrees = 20; },
       "region 'region0': frustum: leftAngle must be less than rightAngle, downAngle less than "
       "upAngle"},
      {[](MpcdiRegion& r) { r.frustum->orientation.yawDegrees = NAN; },
       "region 'region0': frustum: yaw, pitch and roll must be finite"},
  };
  for (const auto& c : cases) {
    Mpcdi m = sample3d();
    m.buffers[0].regions[0].x = 0.25;
    c.spoil(m.buffers[0].regions[0]);
    Result<std::string> r = encodeMpcdi(m, "out.mpcdi");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().str(), "out.mpcdi:mpcdi.xml: " + c.error);
  }
}

TEST(Mpcdi2d, ContentMapHoldsTheWarpAtEachPixelCentre) {
  // A per-pixel 4 × 2 warp: each pixel's content coordinate is its own sample; the invalid
  // sample's pixel alone is invalid (a per-pixel warp has no neighbours weighing in).
  MpcdiRegion r;
  r.xResolution = 4;
  r.yResolution = 2;
  r.warp.width = 4;
  r.warp.height = 2;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      for (float v : {0.1f * x, 0.3f + 0.5f * y, 0.0f}) r.warp.values.push_back(v);
  r.warp.values[3 * 5] = r.warp.values[3 * 5 + 1] = kNaN;  // pixel (1, 1)
  const ContentMap c = contentMap(r);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const size_t i = size_t(y) * 4 + size_t(x);
      if (x == 1 && y == 1) {
        EXPECT_FALSE(c.valid[i]);
        continue;
      }
      ASSERT_TRUE(c.valid[i]) << x << " " << y;
      EXPECT_EQ(c.uv[i], (Vec2{r.warp.values[i * 3], r.warp.values[i * 3 + 1]}));
    }
  // The 2d profile has no frustum: no directions.
  EXPECT_FALSE(directionMap(r).ok());
}

// ---------------------------------------------------------------------------------------------
// The 3d profile against the analytic geometry.

// The angle between two directions, in double (a float dot product cannot resolve angles below
// about 5e-4 rad).
double angle(Vec3 a, Vec3 b) {
  const double c[3] = {double(a.y) * b.z - double(a.z) * b.y, double(a.z) * b.x - double(a.x) * b.z,
                       double(a.x) * b.y - double(a.y) * b.x};
  const double d = double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z;
  return std::atan2(std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), d);
}

TEST(Mpcdi3d, PerPixelWarpGivesTheAnalyticDirections) {
  // The centre projector of the demo rig at 64 × 40, drawn from a frustum around its image; a
  // per-pixel warp (level 2), written and read back, reproduces each pixel's direction to float
  // precision.
  const CylinderRig rig = threeProjectorCylinder(3, 10, 64, 40);
  const DisplayGeometry g = rig.geometry(1);
  const MpcdiFrustum frustum{{0, 0, 0}, {-45, 45, -25, 30}};
  Mpcdi m;
  m.level = 2;
  MpcdiBuffer b;
  b.id = "rig";
  b.regions.push_back(regionFromGeometry(g, frustum, 64, 40, "centre"));
  m.buffers.push_back(b);
  Result<std::string> bytes = encodeMpcdi(m, "rig.mpcdi");
  ASSERT_TRUE(bytes.ok()) << bytes.error().str();
  Result<Mpcdi> back = parseMpcdi(bytes->data(), bytes->size(), "rig.mpcdi");
  ASSERT_TRUE(back.ok()) << back.error().str();
  Result<DirectionMap> fromFile = directionMap(back->buffers[0].regions[0]);
  ASSERT_TRUE(fromFile.ok());
  const DirectionMap exact = directionMap(g);
  double worst = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 64; ++x) {
      ASSERT_TRUE(fromFile->isValid(x, y));
      worst = std::max(worst, angle(fromFile->direction(x, y), exact.direction(x, y)));
    }
  EXPECT_LT(worst, 1e-6);  // radians (7.7e-8 seen): float rounding of u, v and the directions
}

TEST(Mpcdi3d, CoarseWarpIsBilinearBetweenExactSamples) {
  // An 8 × 5 warp (level 1) for a 64 × 40 projector: exact at the sample centres; between them the
  // bilinear warp departs from the curved mapping — by 2.1e-3 rad at most (0.12°, a tenth of this
  // projector's 1.25° pixel), and not by nothing.
  const CylinderRig rig = threeProjectorCylinder(3, 10, 64, 40);
  const DisplayGeometry g = rig.geometry(0);
  const MpcdiFrustum frustum{{-60, 0, 0}, {-45, 45, -25, 30}};
  const MpcdiRegion r = regionFromGeometry(g, frustum, 8, 5, "left");
  Result<DirectionMap> coarse = directionMap(r);
  ASSERT_TRUE(coarse.ok());
  const DirectionMap exact = directionMap(g);
  double worst = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 64; ++x) {
      worst = std::max(worst, angle(coarse->direction(x, y), exact.direction(x, y)));
    }
  // Sample (0, 0) of 8 × 5 sits at region position (4, 4) (between pixel centres): the warp there
  // is that sample exactly.
  const PixelView at = viewOfPixel(g, 4, 4);
  const std::optional<Vec2> uv = sampleWarp(r, 4, 4);
  ASSERT_TRUE(uv);
  EXPECT_EQ(uv->x, r.warp.values[0]);
  EXPECT_EQ(uv->y, r.warp.values[1]);
  EXPECT_TRUE(at.valid);
  EXPECT_GT(worst, 1e-4);
  EXPECT_LT(worst, 3e-3);
}

}  // namespace
}  // namespace sv::display
