// The command-line tool as a user meets it: malformed input gives one clear line naming the file
// and the problem, and a non-zero exit — never a crash.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/shell.h"
#include "support/temp_dir.h"

namespace {

namespace fs = std::filesystem;

using CliRun = sv::tests::ShellRun;

CliRun run(const std::string& args, const std::string& environment = "") {
  return sv::tests::shell(environment + std::string(SV_CLI) + " " + args);
}

fs::path tempDir() { return sv::tests::processTemp().dir(); }

std::string write(const std::string& name, const std::string& content) {
  const fs::path p = tempDir() / name;
  std::ofstream(p, std::ios::binary) << content;
  return p.string();
}

void expectOneLineError(const CliRun& r, const std::string& file, const std::string& what) {
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_EQ(r.out.rfind("synthvis: ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find(file), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(what), std::string::npos) << r.out;
}

TEST(Cli, RendersTheDemoSceneAndPrintsOneStatsLine) {
  const std::string out = (tempDir() / "demo.png").string();
  const CliRun r = run("render -o " + out + " --width 96 --height 64 --threads 2");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_NE(r.out.find("triangles in"), std::string::npos);
  EXPECT_NE(r.out.find("windows"), std::string::npos);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
}

TEST(Cli, TheSegmentPipelineDrawsThePriorityImageAndRefusesWhatItCannotDraw) {
  // --pipeline segments on a scene of vertex colours: the bytes of the tile pipeline under
  // priority masking; on the airport (light points) and with --aa: a one-line error.
  const std::string scene = std::string(SV_SOURCE_DIR) + "/scenes/mixed.json";
  const std::string seg = (tempDir() / "segments.png").string();
  const std::string tiles = (tempDir() / "tiles.png").string();
  const CliRun a =
      run("render " + scene + " -o " + seg + " --width 160 --height 96 --pipeline segments");
  EXPECT_EQ(a.status, 0) << a.out;
  EXPECT_NE(a.out.find("segments "), std::string::npos) << a.out;
  const CliRun b =
      run("render " + scene + " -o " + tiles + " --width 160 --height 96 --hsr priority");
  EXPECT_EQ(b.status, 0) << b.out;
  std::ifstream fa(seg, std::ios::binary), fb(tiles, std::ios::binary);
  const std::string bytesA((std::istreambuf_iterator<char>(fa)), {});
  const std::string bytesB((std::istreambuf_iterator<char>(fb)), {});
  EXPECT_FALSE(bytesA.empty());
  EXPECT_EQ(bytesA, bytesB);
  const std::string airport = std::string(SV_SOURCE_DIR) + "/scenes/airport.json";
  expectOneLineError(run("render " + airport + " -o " + seg + " --pipeline segments"), airport,
                     "light points");
  const CliRun aa = run("render " + scene + " -o " + seg + " --pipeline segments --aa 4");
  EXPECT_EQ(aa.status, 1) << aa.out;
  EXPECT_NE(aa.out.find("--donor"), std::string::npos) << aa.out;
  // The channel's options: the filters, fields and a throttled rate draw a complete frame, whose
  // statistics say how many lines were repeated; without --pipeline segments they are refused.
  const CliRun ch = run("render " + scene + " -o " + seg +
                        " --width 160 --height 96 --pipeline segments --donor --filter tent3 "
                        "--interlaced --segment-rate 8 --critical-lines 3 --fifo-words 256");
  EXPECT_EQ(ch.status, 0) << ch.out;
  EXPECT_NE(ch.out.find("lines repeated "), std::string::npos) << ch.out;
  EXPECT_EQ(ch.out.find("lines repeated 0 "), std::string::npos) << ch.out;
  const CliRun tiled = run("render " + scene + " -o " + seg + " --donor");
  EXPECT_EQ(tiled.status, 1) << tiled.out;
  EXPECT_NE(tiled.out.find("--pipeline segments"), std::string::npos) << tiled.out;
  const CliRun fifo = run("render " + scene + " -o " + seg + " --pipeline segments --fifo-words 3");
  EXPECT_EQ(fifo.status, 1) << fifo.out;
  EXPECT_NE(fifo.out.find("FIFO of 3"), std::string::npos) << fifo.out;
  const CliRun bad = run("render " + scene + " -o " + seg + " --pipeline scanlines");
  EXPECT_EQ(bad.status, 1) << bad.out;
  EXPECT_NE(bad.out.find("tiles or segments"), std::string::npos) << bad.out;
}

TEST(Cli, TheSegmentPipelinesFogIsTheTilePipelines) {
  // A fogged ground and boxes of plain colours: the segment pipeline's fog (the range from the
  // 1/w plane and the view window) against the tile pipeline's (the eye position interpolated):
  // the same image but for rounding.
  const auto text = [](const std::string& beta) {
    return R"({"synthvis": 1, "background": [0.6, 0.7, 0.8],
      "camera": {"position": [0, 2, 0], "target": [0, 1.5, -40], "yfov": 45, "near": 0.5,
                 "far": 2000},
      "fog": {"color": [0.6, 0.7, 0.8], "beta": )" +
           beta + R"(},
      "objects": [
        {"primitive": "box", "size": 3, "color": [0.8, 0.2, 0.1],
         "transform": {"translate": [2, 1.5, -20]}},
        {"primitive": "box", "size": 6, "color": [0.1, 0.6, 0.2],
         "transform": {"translate": [-6, 3, -70]}},
        {"primitive": "checker", "size": [400, 400], "color": [0.3, 0.3, 0.3]}]})";
  };
  const std::string scene = write("fogged.json", text("0.02"));
  const std::string clearScene = write("unfogged.json", text("0"));
  const std::string seg = (tempDir() / "fog-segments.png").string();
  const std::string tiles = (tempDir() / "fog-tiles.png").string();
  const CliRun a =
      run("render " + scene + " -o " + seg + " --width 320 --height 180 --pipeline segments");
  ASSERT_EQ(a.status, 0) << a.out;
  const CliRun b =
      run("render " + scene + " -o " + tiles + " --width 320 --height 180 --hsr priority");
  ASSERT_EQ(b.status, 0) << b.out;
  const CliRun c = run("compare " + seg + " " + tiles);
  ASSERT_EQ(c.status, 0) << c.out;
  const size_t at = c.out.find("PSNR ");
  ASSERT_NE(at, std::string::npos) << c.out;
  const std::string psnr = c.out.substr(at + 5, c.out.find(' ', at + 5) - at - 5);
  EXPECT_TRUE(psnr == "inf" || std::stod(psnr) > 50) << c.out;
  // And the fog did something: without it the frame is far from the fogged one.
  const std::string clear = (tempDir() / "fog-clear.png").string();
  ASSERT_EQ(
      run("render " + clearScene + " -o " + clear + " --width 320 --height 180 --pipeline segments")
          .status,
      0);
  const CliRun d = run("compare " + seg + " " + clear);
  const size_t at2 = d.out.find("PSNR ");
  ASSERT_NE(at2, std::string::npos) << d.out;
  EXPECT_LT(std::stod(d.out.substr(at2 + 5)), 30) << d.out;
}

TEST(Cli, TruncatedJsonNamesFileAndPosition) {
  const std::string f =
      write("trunc.json", "{\"synthvis\": 1, \"objects\": [ {\"primitive\": \"box\"");
  expectOneLineError(run("render " + f + " -o " + (tempDir() / "x.png").string()), f, ":");
}

TEST(Cli, TruncatedGlbIsAnError) {
  const std::string f = write("trunc.glb", std::string("glTF\x02\x00\x00\x00\xff\x00\x00\x00", 12));
  expectOneLineError(run("render " + f + " -o " + (tempDir() / "x.png").string()), f, "");
}

TEST(Cli, MissingReferencedFileIsNamed) {
  const std::string f =
      write("missing_ref.json", R"({"synthvis": 1, "objects": [{"mesh": "no_such_model.glb"}]})");
  expectOneLineError(run("render " + f + " -o " + (tempDir() / "x.png").string()), f,
                     "no_such_model.glb");
}

TEST(Cli, WrongTypesAreReported) {
  const std::string f = write("types.json", R"({"synthvis": 1, "background": "blue"})");
  expectOneLineError(run("render " + f + " -o " + (tempDir() / "x.png").string()), f, "background");
}

// The IG's configuration and the host's script are read by the scene readers' rules: a device is
// refused before anything is read (`synthvis ig /dev/zero` used to read it for ever), and so is a
// file over the inputs' 1 MiB, by its size.
TEST(Cli, TheIgsInputsRefuseDevicesAndHugeFilesBeforeReadingThem) {
  expectOneLineError(run("ig /dev/zero --frames 1"), "/dev/zero", "not a regular file");
  expectOneLineError(run("host /dev/zero --frames 1"), "/dev/zero", "not a regular file");
  const std::string huge = write("huge.json", std::string((1 << 20) + 1, ' '));
  expectOneLineError(run("ig " + huge + " --frames 1"), huge, "file is too large");
  expectOneLineError(run("host " + huge), huge, "file is too large");
}

// A host with no IG at its port waits `--wait` seconds for the first Start of Frame, then says
// where it looked; --wait outside its range is refused.
TEST(Cli, TheHostWaitsForTheIgsFirstFrameAsLongAsItIsTold) {
  const std::string script = std::string(SV_SOURCE_DIR) + "/scenes/ig/terrain-host.json";
  const auto start = std::chrono::steady_clock::now();
  const CliRun r = run("host " + script + " --ig-port 1 --port 0 --wait 0.3");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  expectOneLineError(r, "127.0.0.1:1", "no Start of Frame from the IG");
  EXPECT_NE(r.out.find("for 300 ms"), std::string::npos) << r.out;
  EXPECT_LT(s, 10.0);
  EXPECT_NE(run("host " + script + " --wait 0").status, 0);
}

// A model whose every triangle faces away from the camera renders an empty picture and says why;
// --no-cull draws it.
TEST(Cli, APictureEmptiedByBackFaceCullingSaysSo) {
  const std::string scene =
      write("away.json",
            R"({"synthvis": 1, "camera": {"position": [0, 0, 3], "target": [0, 0, 0]},
          "objects": [{"mesh": {"positions": [-1, -1, 0, 0, 1, 0, 1, -1, 0]}}]})");
  const std::string out = (tempDir() / "away.png").string();
  const CliRun culled = run("render " + scene + " -o " + out + " --width 64 --height 48");
  EXPECT_EQ(culled.status, 0) << culled.out;
  EXPECT_NE(culled.out.find("synthvis: warning: " + out +
                            ": every triangle faced away from the camera and was culled"),
            std::string::npos)
      << culled.out;
  const CliRun drawn = run("render " + scene + " -o " + out + " --width 64 --height 48 --no-cull");
  EXPECT_EQ(drawn.status, 0) << drawn.out;
  EXPECT_EQ(drawn.out.find("warning"), std::string::npos) << drawn.out;
}

TEST(Cli, MissingSceneFileAndBadOptions) {
  expectOneLineError(run("render /no/such/scene.json -o x.png"), "/no/such/scene.json", "");
  const CliRun big = run("render --width 100000 -o " + (tempDir() / "x.png").string());
  EXPECT_EQ(big.status, 1) << big.out;
  EXPECT_NE(big.out.find("out of range"), std::string::npos) << big.out;
  const CliRun fmt = run("render -o " + (tempDir() / "x.bmp").string() + " --width 8 --height 8");
  EXPECT_EQ(fmt.status, 1) << fmt.out;
  EXPECT_NE(run("render --no-such-flag").status, 0);
  expectOneLineError(run("render --gamma 9 -o " + (tempDir() / "x.png").string()), "",
                     "gamma 9 is out of range");
  expectOneLineError(run("render --aa 3 -o " + (tempDir() / "x.png").string()), "",
                     "3 samples per pixel is not supported");
  expectOneLineError(run("render --filter gauss -o " + (tempDir() / "x.png").string()), "",
                     "unknown filter 'gauss'");
}

TEST(Cli, BenchWritesTheJsonFieldsBenchMdNames) {
  const std::string json = (tempDir() / "bench.json").string();
  const CliRun r =
      run("bench tris --count 2000 --area 20 --width 320 --height 240 --frames 2 "
          "--warmup 1 --json " +
          json);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream f(json);
  std::string text((std::istreambuf_iterator<char>(f)), {});
  for (const char* key :
       {"\"scene\"", "\"renderer\"", "\"width\"", "\"height\"", "\"threads\"", "\"frames\"",
        "\"median_ms\"", "\"min_ms\"", "\"max_ms\"", "\"triangles\""})
    EXPECT_NE(text.find(key), std::string::npos) << key;
}

// SPEC §9: --channels N writes OUT-<i>.png per channel with a statistics line each, and the
// mosaic; a scene's own channels are written by name; misuse is a one-line error.
TEST(Cli, RenderWritesAnImageAndAStatisticsLinePerChannelAndTheMosaic) {
  const fs::path dir = tempDir() / "channels";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "view.png").string(), mosaic = (dir / "all.png").string();
  CliRun r =
      run("render -o " + out + " --width 64 --height 48 --threads 2 --channels 3 --arc 150 " +
          "--mosaic " + mosaic);
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* name : {"view-0.png", "view-1.png", "view-2.png", "all.png"})
    EXPECT_TRUE(fs::exists(dir / name)) << name;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 5) << r.out;  // 3 channels, frame, mosaic
  EXPECT_NE(r.out.find("view-2.png: 64x48 | triangles in"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frame: 3 channels"), std::string::npos) << r.out;

  const std::string scene = write("channels.json", R"({"synthvis": 1,
      "objects": [{"primitive": "box"}],
      "channels": [{"name": "left", "yaw": -30, "width": 32, "height": 24},
                   {"name": "right", "yaw": 30, "width": 40, "height": 24,
                    "frustum": {"left": -10, "right": 20, "down": -10, "up": 10}}]})");
  r = run("render " + scene + " -o " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "view-left.png"));
  EXPECT_TRUE(fs::exists(dir / "view-right.png"));
  expectOneLineError(run("render " + scene + " -o " + out + " --channels 2"), "channels.json",
                     "--channels: the scene has 2 channels of its own");
  expectOneLineError(run("render -o " + out + " --channels 17"), "", "--channels 17: must be 1…16");
  const std::string bad = write("bad_channels.json", R"({"synthvis": 1,
      "channels": [{"width": 32, "height": 24, "frustum": {"left": 5, "right": -5, "down": -5, "up": 5}}]})");
  expectOneLineError(run("render " + bad + " -o " + out), "bad_channels.json",
                     "channels[0].frustum: left (5) must be less than right (-5)");
}

// Issue 34: --display cylinder3 writes each projector's pre-distorted image, the viewer's
// panorama and the rig as MPCDI, which --display then reads back; misuse is a one-line error.
TEST(Cli, RenderDisplayWritesEachProjectorTheViewerAndAnMpcdiFileThatReadsBack) {
  const fs::path dir = tempDir() / "display";
  fs::create_directories(dir);
  const std::string out = (dir / "p.png").string(), viewer = (dir / "viewer.png").string(),
                    mpcdi = (dir / "rig.mpcdi").string();
  CliRun r = run("render -o " + out + " --width 96 --height 60 --threads 2 --display cylinder3 " +
                 "--viewer " + viewer + " --write-mpcdi " + mpcdi);
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* name : {"p-left.png", "p-centre.png", "p-right.png", "viewer.png", "rig.mpcdi"})
    EXPECT_TRUE(fs::exists(dir / name)) << name;
  EXPECT_NE(r.out.find("p-centre.png: 96x60 | "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sub-frusta, residual <= "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frame: 3 projectors"), std::string::npos) << r.out;
  r = run("render -o " + (dir / "m.png").string() + " --threads 2 --display " + mpcdi +
          " --correction bicubic");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("m-centre.png: 96x60 | flat "), std::string::npos) << r.out;
  expectOneLineError(run("render -o " + out + " --display " + (dir / "none.mpcdi").string()),
                     "none.mpcdi", "");
  expectOneLineError(run("render -o " + out + " --display cylinder3 --correction sharp"), "",
                     "correction 'sharp': expected subfrusta, bilinear or bicubic");
  expectOneLineError(run("render -o " + out + " --viewer " + viewer), "",
                     "--viewer and --write-mpcdi need --display");
}

TEST(Cli, BenchChannelsTimesTheWholeFrameAndWritesTheChannelsField) {
  const std::string json = (tempDir() / "bench_channels.json").string();
  const CliRun r =
      run("bench tris --count 2000 --area 20 --width 160 --height 120 --frames 2 "
          "--warmup 1 --channels 3 --json " +
          json);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("channel 2:"), std::string::npos) << r.out;
  std::ifstream f(json);
  const nlohmann::json row = nlohmann::json::parse(f);
  EXPECT_EQ(row["channels"], 3);
  EXPECT_EQ(row["width"], 160);
  EXPECT_GT(row["median_ms"].get<double>(), 0);
}

// Light points (issue 30): --time moves a blinking light (a different image), a non-finite time
// is a one-line error, and bench lights writes its light and star counts.
TEST(Cli, RenderTimeBlinksLightsAndBenchLightsWritesItsCounts) {
  const std::string scene = write("blink.json", R"({"synthvis": 1, "background": [0, 0, 0],
    "camera": {"position": [0, 0, 5], "target": [0, 0, 0]},
    "lights": {"settings": {"exposure": 200},
               "appearances": [{"blink": {"period": 1, "on": 0.5}}],
               "points": [{"position": [0, 0, 0]}]}})");
  const std::string on = (tempDir() / "on.png").string(), off = (tempDir() / "off.png").string();
  const CliRun a = run("render " + scene + " -o " + on + " --width 64 --height 48 --time 0.25");
  const CliRun b = run("render " + scene + " -o " + off + " --width 64 --height 48 --time 0.75");
  ASSERT_EQ(a.status, 0) << a.out;
  ASSERT_EQ(b.status, 0) << b.out;
  EXPECT_NE(a.out.find("lights 1: drawn 1"), std::string::npos) << a.out;
  EXPECT_NE(b.out.find("lights 1: drawn 0"), std::string::npos) << b.out;
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), {});
  };
  EXPECT_NE(bytes(on), bytes(off));
  expectOneLineError(run("render " + scene + " -o " + on + " --time nan"), "--time",
                     "not a finite number");
  const std::string json = (tempDir() / "bench_lights.json").string();
  const CliRun c =
      run("bench lights --lights 3000 --stars none --width 160 --height 120 "
          "--frames 1 --warmup 0 --json " +
          json);
  ASSERT_EQ(c.status, 0) << c.out;
  std::ifstream f(json);
  const nlohmann::json row = nlohmann::json::parse(f);
  EXPECT_EQ(row["lights"], 3000);
  EXPECT_EQ(row["stars"], 0);
  EXPECT_NE(c.out.find("lights 3000: drawn"), std::string::npos) << c.out;
}

// --repeat N: each measurement printed and written as a JSON row numbered by its repeat, then the
// medians over them; an impossible count is a one-line error.
TEST(Cli, BenchRepeatPrintsEachMeasurementAndTheirMedian) {
  const std::string json = (tempDir() / "repeat.json").string();
  const CliRun r =
      run("bench tris --count 500 --area 20 --width 160 --height 120 --frames 2 "
          "--warmup 0 --repeat 3 --json " +
          json);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("repeat 3/3"), std::string::npos) << r.out;
  const size_t median = r.out.find("median of 3 repeats:  synthvis ");
  ASSERT_NE(median, std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("ratio", median), std::string::npos) << r.out;  // one renderer: no ratio
  std::ifstream f(json);
  const nlohmann::json rows = nlohmann::json::parse(f);
  ASSERT_TRUE(rows.is_array()) << rows.dump();
  ASSERT_EQ(rows.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(rows[k]["repeat"], k + 1);
    EXPECT_EQ(rows[k]["renderer"], "synthvis");
  }
  expectOneLineError(run("bench tris --repeat 0"), "", "--repeat 0: must be 1…100");
}

// Side by side with the gl reference when it can start here; otherwise the line says why and the
// run goes on with synthvis alone. (Mesa's driver leaks a little at unload: no leak check.)
TEST(Cli, BenchBothRenderersWritesARowEachWithPsnrAndAnHtmlPage) {
  const std::string json = (tempDir() / "both.json").string();
  const std::string html = (tempDir() / "both_html").string();
  const CliRun r =
      run("bench tris --renderer both --count 800 --area 40 --width 320 --height 240 "
          "--frames 2 --warmup 1 --json " +
              json + " --html " + html,
          "ASAN_OPTIONS=detect_leaks=0 ");
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream f(json);
  const nlohmann::json rows = nlohmann::json::parse(f);
  EXPECT_TRUE(fs::exists(fs::path(html) / "index.html"));
  if (r.out.find("reference: not available") != std::string::npos) {
    EXPECT_EQ(rows["renderer"], "synthvis") << r.out;
    return;
  }
  ASSERT_TRUE(rows.is_array()) << r.out;
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0]["renderer"], "synthvis");
  EXPECT_EQ(rows[1]["renderer"], "gl");
  EXPECT_GE(rows[0]["psnr_db"].get<double>(), 40.0);
  EXPECT_TRUE(fs::exists(fs::path(html) / "tris-gl.png"));
}

TEST(Cli, GenWritesAGlbThatRenders) {
  const std::string glb = (tempDir() / "gen.glb").string();
  const CliRun g = run("gen layers --layers 2 --width 320 --height 240 -o " + glb);
  ASSERT_EQ(g.status, 0) << g.out;
  EXPECT_NE(g.out.find("depth complexity 2.00"), std::string::npos) << g.out;
  const CliRun r = run("render " + glb + " -o " + (tempDir() / "gen.png").string() +
                       " --width 320 --height 240");
  EXPECT_EQ(r.status, 0) << r.out;
  // BENCH.md's grazing scene, textured: its textures travel in the .glb as PNGs.
  const std::string grazing = (tempDir() / "grazing.glb").string();
  const CliRun gz = run("gen grazing -o " + grazing);
  ASSERT_EQ(gz.status, 0) << gz.out;
  EXPECT_NE(gz.out.find("62 triangles, 2 textures"), std::string::npos) << gz.out;
  EXPECT_EQ(run("render " + grazing + " -o " + (tempDir() / "grazing.png").string() +
                " --width 160 --height 90")
                .status,
            0);
  const CliRun b = run("bench grazing --fog --width 160 --height 90 --frames 1 --warmup 0");
  EXPECT_EQ(b.status, 0) << b.out;
  EXPECT_NE(b.out.find("grazing"), std::string::npos) << b.out;
  expectOneLineError(run("gen tris --shade matte -o " + glb), "", "unknown shading");
  expectOneLineError(run("gen freeform -o " + glb), "", "free forms");
  expectOneLineError(run("bench --suite huge"), "", "unknown suite");
}

TEST(Cli, TruthAndCompare) {
  const std::string truth = (tempDir() / "truth.png").string();
  const std::string ours = (tempDir() / "ours.png").string();
  const std::string edges = (tempDir() / "edges.png").string();
  ASSERT_EQ(run("truth -o " + truth + " --edges " + edges + " --width 64 --height 48 --samples 16")
                .status,
            0);
  ASSERT_EQ(run("render -o " + ours + " --width 64 --height 48 --supersample 2").status, 0);
  const CliRun c = run("compare " + ours + " " + truth + " --edges " + edges);
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_NE(c.out.find("edge pixels"), std::string::npos) << c.out;
  ASSERT_EQ(run("render -o " + ours + " --width 64 --height 48 --aa 16 --filter tent3").status, 0);
  EXPECT_EQ(run("compare " + ours + " " + truth).status, 0);
  expectOneLineError(run("truth -o " + truth + " --samples 3"), "", "must be a square");
  expectOneLineError(run("compare " + ours + " /no/such.png"), "/no/such.png", "");
}

}  // namespace
