// Writes the XTF fuzz seeds into a directory (run by hand: xtf_make_corpus tests/xtf/corpus):
// small valid files of each layout and a few faulty ones.
#include <cstdio>
#include <fstream>
#include <string>

#include "tests/xtf/xtf_test_data.hpp"

namespace {
void save(const std::string& directory, const std::string& name, const std::vector<uint8_t>& bytes) {
  std::ofstream out(directory + "/" + name, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
    return 2;
  }
  using namespace sss;
  const std::string dir = argv[1];
  const xtf::XtfWriterOptions two16 = test::makeXtfOptions({100.0f}, 2);
  save(dir, "two_channel_16bit", test::makeXtfFile(two16, 3, 16));
  const xtf::XtfWriterOptions four8 = test::makeXtfOptions({410.0f, 120.0f}, 1, xtf::kNavUnitsMetres);
  save(dir, "four_channel_8bit_metres", test::makeXtfFile(four8, 3, 16));
  const xtf::XtfWriterOptions eight = test::makeXtfOptions({100.0f, 200.0f, 300.0f, 400.0f}, 2);
  save(dir, "eight_channel_two_blocks", test::makeXtfFile(eight, 2, 8));
  std::vector<uint8_t> mixed = xtf::encodeFileHeader(two16);
  test::appendBytes(mixed, xtf::encodeOtherPacket(3, 64));
  test::appendBytes(mixed, xtf::encodeSonarPacket(two16, test::makeXtfPing(two16, 0, 16)));
  test::appendBytes(mixed, std::vector<uint8_t>(20, 0xA5));
  test::appendBytes(mixed, xtf::encodeSonarPacket(two16, test::makeXtfPing(two16, 1, 16)));
  std::vector<uint8_t> cut = xtf::encodeSonarPacket(two16, test::makeXtfPing(two16, 2, 16));
  cut.resize(cut.size() / 2);
  test::appendBytes(mixed, cut);
  save(dir, "other_types_garbage_truncated", mixed);
  xtf::XtfWriterOptions float32 = test::makeXtfOptions({100.0f}, 4);
  for (auto& c : float32.channels) c.sample_format = 5;
  save(dir, "float32_samples", test::makeXtfFile(float32, 2, 8));
  // Navigation in its own packets (attitude 3, navigation 42, raw position 107) around a ping
  // whose sensor position is unset and whose vessel position (ShipY/X) is set.
  std::vector<uint8_t> navigation = xtf::encodeFileHeader(two16);
  for (const uint8_t type : {xtf::kHeaderAttitude, xtf::kHeaderNavigation, xtf::kHeaderPosRawNavigation}) {
    std::vector<uint8_t> packet = xtf::encodeOtherPacket(type, 64);
    const size_t date_at = type == xtf::kHeaderAttitude ? 54 : 14;
    xtf::writeU16(packet.data(), date_at, 2026);
    packet[date_at + 2] = 6;
    packet[date_at + 3] = 1;
    packet[date_at + 4] = 8;
    if (type == xtf::kHeaderNavigation) {
      xtf::writeF64(packet.data(), 33, 59.35);
      xtf::writeF64(packet.data(), 41, 18.07);
    } else if (type == xtf::kHeaderPosRawNavigation) {
      xtf::writeF64(packet.data(), 23, 59.35);
      xtf::writeF64(packet.data(), 31, 18.07);
      xtf::writeF32(packet.data(), 59, 45.0f);
    } else {
      xtf::writeF32(packet.data(), 30, 1.5f);
      xtf::writeF32(packet.data(), 50, 45.0f);
    }
    test::appendBytes(navigation, packet);
  }
  xtf::XtfPingInput unpositioned = test::makeXtfPing(two16, 0, 16);
  unpositioned.sensor_x = unpositioned.sensor_y = 0.0;
  std::vector<uint8_t> ping = xtf::encodeSonarPacket(two16, unpositioned);
  xtf::writeF64(ping.data(), xtf::offset::kShipY, 59.3501);
  xtf::writeF64(ping.data(), xtf::offset::kShipX, 18.0701);
  test::appendBytes(navigation, ping);
  save(dir, "navigation_packets_ship_position", navigation);
  return 0;
}
