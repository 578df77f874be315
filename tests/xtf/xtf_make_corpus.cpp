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
  return 0;
}
