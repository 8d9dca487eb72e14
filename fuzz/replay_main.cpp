// A main() for fuzz targets built without libFuzzer (any compiler): runs LLVMFuzzerTestOneInput
// over every file given (directories are walked), then over deterministic pseudo-random
// mutations of each, so that the gcc build runs the fuzz targets as regression tests.
//
//   replay_json_scene [--mutations N] [--seed S] [--verbose] [--only M] [--save DIR] PATH...
//
// --verbose prints each run's file and mutation number before running it, so the last line
// before a crash names the input; --only M runs just mutation M of each file, and --save DIR
// writes the mutated inputs it runs to DIR (as <file>.m<M>) for a debugger or libFuzzer.
//
// Mutations stack 1–4 edits chosen from: bit flips, byte overwrites with "interesting" values,
// truncation, insertion of random bytes or format tokens, deletion and duplication of spans, and
// replacement of a digit run by a boundary number. The generator is xorshift64* (Vigna 2016, "An
// experimental exploration of Marsaglia's xorshift generators, scrambled"), seeded per file from
// --seed and the file's name, so a run is reproducible and independent of file order.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

class XorShift64Star {
 public:
  explicit XorShift64Star(uint64_t seed) : state_(seed ? seed : 0x9E3779B97F4A7C15ull) {}
  uint64_t next() {
    state_ ^= state_ >> 12;
    state_ ^= state_ << 25;
    state_ ^= state_ >> 27;
    return state_ * 2685821657736338717ull;
  }
  // Uniform enough in [0, n) for n ≪ 2^64; n must be > 0.
  size_t below(size_t n) { return size_t(next() % n); }

 private:
  uint64_t state_;
};

// FNV-1a, to derive a per-file seed from its name.
uint64_t hashName(std::string_view s) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (char c : s) h = (h ^ uint8_t(c)) * 0x100000001b3ull;
  return h;
}

// Tokens of the three formats, spliced in so that mutations reach past the first syntax check.
constexpr std::string_view kTokens[] = {
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "null",
    "true",
    "false",
    "-",
    "e",
    ".",
    "\n",
    " ",
    "\\",
    "\"synthvis\": 1",
    "\"objects\"",
    "\"mesh\"",
    "\"primitive\"",
    "\"sphere\"",
    "\"checker\"",
    "\"transform\"",
    "\"matrix\"",
    "\"rotate\"",
    "\"segments\"",
    "\"squares\"",
    "\"material\"",
    "\"accessors\"",
    "\"bufferViews\"",
    "\"buffers\"",
    "\"byteOffset\"",
    "\"byteStride\"",
    "\"byteLength\"",
    "\"count\"",
    "\"componentType\"",
    "\"indices\"",
    "\"nodes\"",
    "\"children\"",
    "\"mode\"",
    "\"scene\"",
    "\"camera\"",
    "glTF",
    "JSON",
    "BIN",
    "v ",
    "vn ",
    "vt ",
    "f ",
    "o ",
    "g ",
    "usemtl ",
    "mtllib ",
    "/",
    "//",
    "l ",
    "p ",
};
constexpr std::string_view kNumbers[] = {
    "0",           "-1",
    "1",           "2",
    "3",           "4096",
    "4097",        "65535",
    "65536",       "2147483647",
    "-2147483648", "4294967295",
    "4294967296",  "18446744073709551615",
    "1e308",       "1e999",
    "-0",          "0.5",
    "1e-40",
};
constexpr uint8_t kBytes[] = {0,   1,   0x7f, 0x80, 0xff, '{', '}', '[',
                              ']', '"', '\n', ' ',  '0',  '9', '-', '/'};

// Inputs never grow past this, so stacked insertions cannot snowball.
constexpr size_t kMaxInput = size_t(1) << 20;

void mutate(std::string& s, XorShift64Star& random) {
  const int edits = 1 + int(random.below(4));
  for (int e = 0; e < edits; ++e) {
    const size_t at = s.empty() ? 0 : random.below(s.size() + 1);
    switch (random.below(8)) {
      case 0:  // flip one bit
        if (!s.empty()) s[random.below(s.size())] ^= char(1u << random.below(8));
        break;
      case 1:  // overwrite a byte with an interesting value
        if (!s.empty()) s[random.below(s.size())] = char(kBytes[random.below(std::size(kBytes))]);
        break;
      case 2:  // truncate
        s.resize(at);
        break;
      case 3: {  // insert random bytes
        std::string bytes(1 + random.below(16), '\0');
        for (char& c : bytes) c = char(random.next());
        s.insert(at, bytes);
        break;
      }
      case 4:  // delete a span
        if (at < s.size()) s.erase(at, 1 + random.below(std::min<size_t>(64, s.size() - at)));
        break;
      case 5:  // duplicate a span elsewhere
        if (!s.empty()) {
          size_t from = random.below(s.size());
          std::string span =
              s.substr(from, 1 + random.below(std::min<size_t>(256, s.size() - from)));
          s.insert(random.below(s.size() + 1), span);
        }
        break;
      case 6: {  // replace the next digit run with a boundary number
        size_t d = s.find_first_of("0123456789", at);
        if (d == std::string::npos) break;
        size_t end = s.find_first_not_of("0123456789.eE+-", d);
        s.replace(d, (end == std::string::npos ? s.size() : end) - d,
                  kNumbers[random.below(std::size(kNumbers))]);
        break;
      }
      default:  // splice in a format token
        s.insert(at, kTokens[random.below(std::size(kTokens))]);
        break;
    }
    if (s.size() > kMaxInput) s.resize(kMaxInput);
  }
}

bool readFile(const std::filesystem::path& path, std::string& out) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  out.clear();
  char buffer[65536];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) out.append(buffer, n);
  std::fclose(f);
  return true;
}

void run(const std::string& input) {
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(input.data()), input.size());
}

}  // namespace

int main(int argc, char** argv) {
  size_t mutations = 0;
  uint64_t seed = 1;
  bool verbose = false;
  long long only = -1;
  std::filesystem::path saveDir;
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    std::string_view arg = argv[i];
    if (arg == "--mutations" && i + 1 < argc) {
      mutations = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--seed" && i + 1 < argc) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--only" && i + 1 < argc) {
      only = std::strtoll(argv[++i], nullptr, 10);
    } else if (arg == "--save" && i + 1 < argc) {
      saveDir = argv[++i];
    } else if (arg == "--verbose") {
      verbose = true;
    } else if (arg.starts_with("-")) {
      std::fprintf(
          stderr,
          "usage: %s [--mutations N] [--seed S] [--verbose] [--only M] [--save DIR] PATH...\n",
          argv[0]);
      return 2;
    } else if (std::filesystem::is_directory(argv[i])) {
      for (const auto& entry : std::filesystem::recursive_directory_iterator(argv[i]))
        if (entry.is_regular_file()) files.push_back(entry.path());
    } else {
      files.push_back(argv[i]);
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "%s: no input files\n", argv[0]);
    return 2;
  }
  if (only >= 0) mutations = std::max(mutations, size_t(only) + 1);

  const auto start = std::chrono::steady_clock::now();
  size_t runs = 0;
  std::string original, input;
  for (const auto& path : files) {
    if (!readFile(path, original)) {
      std::fprintf(stderr, "%s: cannot read %s\n", argv[0], path.c_str());
      return 2;
    }
    if (only < 0) {
      std::fprintf(stderr, "%s: %s\n", argv[0], path.c_str());
      run(original);
      ++runs;
    }
    XorShift64Star random(seed ^ hashName(path.filename().string()));
    for (size_t m = 0; m < mutations; ++m) {
      input = original;
      mutate(input, random);  // always, so that mutation m is the same with or without --only
      if (only >= 0 && m != size_t(only)) continue;
      if (verbose) std::fprintf(stderr, "%s: %s mutation %zu\n", argv[0], path.c_str(), m);
      if (!saveDir.empty()) {
        std::filesystem::create_directories(saveDir);
        std::string name = path.filename().string() + ".m" + std::to_string(m);
        if (std::FILE* f = std::fopen((saveDir / name).c_str(), "wb")) {
          std::fwrite(input.data(), 1, input.size(), f);
          std::fclose(f);
        }
      }
      run(input);
      ++runs;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %zu files, %zu runs, %.2f s, no failures\n", argv[0], files.size(), runs,
              seconds);
  return 0;
}
