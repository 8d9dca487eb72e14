// pcap captures of CIGI sessions: written, read back, and broken files refused with one line.
#include "cigi/pcap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "cigi/session.h"
#include "support/temp_dir.h"

namespace sv::cigi {
namespace {

std::string tempPath(const std::string& name) { return sv::tests::processTemp().path(name); }

std::vector<uint8_t> fileBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<CapturedDatagram> session() {
  return {{1718000000.125, true, writeDatagram(test::hostPackets())},
          {1718000000.141667, false, writeDatagram(test::igPackets())},
          {1718000000.999999, true, writeDatagram(test::hostPackets(), true)},
          {1718000001.0000004, false, writeDatagram(test::igPackets(), true)},
          {0, true, {}}};  // an empty datagram: UDP carries it, the reader returns it
}

void expectSameCapture(const std::vector<CapturedDatagram>& read,
                       const std::vector<CapturedDatagram>& written) {
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_NEAR(read[i].time, written[i].time, 0.6e-6) << i;  // microseconds, rounded
    EXPECT_EQ(read[i].fromHost, written[i].fromHost) << i;
    EXPECT_EQ(read[i].bytes, written[i].bytes) << i;
  }
}

TEST(CigiPcap, AWrittenCaptureReadsBackDatagramForDatagram) {
  const std::string path = tempPath("roundtrip.pcap");
  const auto written = session();
  ASSERT_TRUE(writePcap(path, written).ok());
  const auto read = readPcap(path);
  ASSERT_TRUE(read.ok()) << read.error().str();
  expectSameCapture(read.value(), written);
}

TEST(CigiPcap, TheIncrementalWriterLeavesAReadableFileAfterEachRecord) {
  const std::string path = tempPath("incremental.pcap");
  const auto written = session();
  PcapWriter writer;
  ASSERT_TRUE(writer.open(path).ok());
  // Read while the writer is still open, as after a killed process: every record flushed.
  for (size_t n = 0; n < written.size(); ++n) {
    ASSERT_TRUE(writer.add(written[n]).ok());
    const auto read = readPcap(path);
    ASSERT_TRUE(read.ok()) << read.error().str();
    expectSameCapture(read.value(), {written.begin(), written.begin() + long(n) + 1});
  }
}

// Every record is flushed, so a disk that is full fails the record (here already the file's header),
// and the error names the file and the system's reason.
TEST(CigiPcap, AFullDiskIsAnError) {
  const std::string path = sv::tests::fullDiskPath("full.pcap");
  if (path.empty()) GTEST_SKIP() << "no /dev/full here";
  PcapWriter writer;
  const Status s = writer.open(path);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().str(), path + ": cannot write: No space left on device");
  const Status whole = writePcap(path, session());
  ASSERT_FALSE(whole.ok());
  EXPECT_EQ(whole.error().str(), path + ": cannot write: No space left on device");
}

TEST(CigiPcap, FramesCarryTheSessionsAddressesPortsAndACorrectIpv4Checksum) {
  const std::string path = tempPath("frame.pcap");
  const std::vector<CapturedDatagram> one = {{5.5, true, {1, 2, 3, 4, 5, 6, 7, 8}}};
  ASSERT_TRUE(writePcap(path, one).ok());
  const auto b = fileBytes(path);
  ASSERT_EQ(b.size(), 24u + 16 + 14 + 20 + 8 + 8);
  // The global header: magic (little-endian), version 2.4, link type 1.
  EXPECT_EQ(std::vector<uint8_t>(b.begin(), b.begin() + 4), (std::vector<uint8_t>{0xd4, 0xc3,
                                                                                  0xb2, 0xa1}));
  EXPECT_EQ(b[4], 2);
  EXPECT_EQ(b[6], 4);
  EXPECT_EQ(b[20], 1);
  // The record header: 5 s and 500000 µs.
  EXPECT_EQ(b[24], 5);
  EXPECT_EQ(b[28] | b[29] << 8 | b[30] << 16, 500000);
  const uint8_t* ip = b.data() + 24 + 16 + 14;
  EXPECT_EQ(ip[-2] << 8 | ip[-1], 0x0800);  // EtherType IPv4
  EXPECT_EQ(ip[9], 17);                      // UDP
  EXPECT_EQ(std::vector<uint8_t>(ip + 12, ip + 20),
            (std::vector<uint8_t>{127, 0, 0, 1, 127, 0, 0, 2}));
  // RFC 1071: a header with its checksum sums to 0xffff in one's complement arithmetic.
  uint32_t sum = 0;
  for (int i = 0; i < 20; i += 2) sum += uint32_t(ip[i] << 8 | ip[i + 1]);
  while (sum >> 16) sum = (sum & 0xffff) + (sum >> 16);
  EXPECT_EQ(sum, 0xffffu);
  const uint8_t* udp = ip + 20;
  EXPECT_EQ(udp[0] << 8 | udp[1], kHostPort);
  EXPECT_EQ(udp[2] << 8 | udp[3], kIgPort);
  EXPECT_EQ(udp[4] << 8 | udp[5], 16);
}

TEST(CigiPcap, TheWriterRefusesWhatAFrameCannotHold) {
  PcapWriter closed;
  EXPECT_FALSE(closed.add({0, true, {}}).ok());
  PcapWriter writer;
  ASSERT_TRUE(writer.open(tempPath("refuses.pcap")).ok());
  EXPECT_FALSE(writer.add({-1, true, {}}).ok());
  EXPECT_FALSE(writer.add({std::nan(""), true, {}}).ok());
  EXPECT_FALSE(writer.add({0, true, std::vector<uint8_t>(65508)}).ok());
  EXPECT_TRUE(writer.add({0, true, std::vector<uint8_t>(65507)}).ok());
  EXPECT_FALSE(PcapWriter().open("/nonexistent-dir/x.pcap").ok());
}

// A valid capture's bytes with one change; the reader must refuse it with a line naming the file.
struct Broken {
  const char* why;
  std::vector<uint8_t> bytes;
};

std::vector<Broken> brokenCaptures() {
  const std::string path = tempPath("valid.pcap");
  const std::vector<CapturedDatagram> two = {{1, true, writeDatagram(test::hostPackets())},
                                             {2, false, writeDatagram(test::igPackets())}};
  EXPECT_TRUE(writePcap(path, two).ok());
  const auto valid = fileBytes(path);
  auto with = [&](size_t at, std::vector<uint8_t> values) {
    auto b = valid;
    std::copy(values.begin(), values.end(), b.begin() + long(at));
    return b;
  };
  const size_t record = 24, frame = record + 16, ip = frame + 14;
  return {
      {"empty file", {}},
      {"half a global header", std::vector<uint8_t>(valid.begin(), valid.begin() + 12)},
      {"pcapng magic", with(0, {0x0a, 0x0d, 0x0d, 0x0a})},
      {"text", with(0, {'h', 'e', 'l', 'l'})},
      {"link type 101 (raw IP)", with(20, {101, 0, 0, 0})},
      {"truncated record header", std::vector<uint8_t>(valid.begin(), valid.begin() + 30)},
      {"truncated record", std::vector<uint8_t>(valid.begin(), valid.end() - 1)},
      {"absurd record length", with(record + 8, {0x01, 0x00, 0x10, 0x00})},
      {"record length 2^32 - 1", with(record + 8, {0xff, 0xff, 0xff, 0xff})},
      {"ARP, not IPv4", with(frame + 12, {0x08, 0x06})},
      {"TCP, not UDP", with(ip + 9, {6})},
      {"IPv6 version nibble", with(ip, {0x65})},
      {"IPv4 total length past the frame", with(ip + 2, {0xff, 0xff})},
      {"UDP length past its packet", with(ip + 20 + 4, {0xff, 0xff})},
      {"UDP length below its header", with(ip + 20 + 4, {0x00, 0x07})},
  };
}

TEST(CigiPcap, BrokenCapturesAreRefusedWithOneLineNamingTheFile) {
  for (const Broken& b : brokenCaptures()) {
    const std::string path = tempPath("broken.pcap");
    writeBytes(path, b.bytes);
    const auto read = readPcap(path);
    ASSERT_FALSE(read.ok()) << b.why;
    const std::string line = read.error().str();
    EXPECT_EQ(line.rfind(path, 0), 0u) << b.why << ": " << line;
    EXPECT_EQ(line.find('\n'), std::string::npos) << b.why;
    EXPECT_FALSE(read.error().message.empty()) << b.why;
  }
  const auto missing = readPcap(tempPath("no-such-file.pcap"));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().str().find("no-such-file.pcap"), std::string::npos);
}

TEST(CigiPcap, BigEndianAndNanosecondCapturesAreReadToo) {
  // The global and record headers of a big-endian, nanosecond capture, built by hand.
  const std::string path = tempPath("be.pcap");
  ASSERT_TRUE(writePcap(path, std::vector<CapturedDatagram>{{3.25, false, {9, 9, 9, 9}}}).ok());
  auto b = fileBytes(path);
  auto reverse4 = [&](size_t at) { std::reverse(b.begin() + long(at), b.begin() + long(at) + 4); };
  b[0] = 0x4d, b[1] = 0x3c;  // 0xa1b23c4d, little-endian for now
  for (size_t at : {0, 16, 20, 24, 28, 32, 36}) reverse4(at);
  b[24 + 4] = 0x0e, b[24 + 5] = 0xe6, b[24 + 6] = 0xb2, b[24 + 7] = 0x80;  // 250000000 ns
  writeBytes(path, b);
  const auto read = readPcap(path);
  ASSERT_TRUE(read.ok()) << read.error().str();
  ASSERT_EQ(read->size(), 1u);
  EXPECT_DOUBLE_EQ(read.value()[0].time, 3.25);
  EXPECT_FALSE(read.value()[0].fromHost);
  EXPECT_EQ(read.value()[0].bytes, (std::vector<uint8_t>{9, 9, 9, 9}));
}

}  // namespace
}  // namespace sv::cigi
