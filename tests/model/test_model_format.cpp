// Model format 01, pinned by a committed model folder (tests/data/model-format-01, a small
// ellipsoid built with `build-model --image --faces 320`): it reads, its bytes decode as
// docs/model-format.md says (little-endian, whatever the machine), and writing what was read
// gives the same bytes again.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "model/model_io.h"
#include "model/sections.h"
#include "snake/reference_image.h"
#include "tests/test_support.h"

using namespace mrsnake;
namespace fs = std::filesystem;

namespace {

const fs::path kCommitted = fs::path(MRSNAKE_SOURCE_DIR) / "tests" / "data" / "model-format-01";

// Little-endian, byte by byte: independent of the codec under test and of the machine.
std::uint64_t little_endian(const std::vector<std::uint8_t>& bytes, std::size_t offset, int size) {
  std::uint64_t v = 0;
  for (int b = size - 1; b >= 0; --b) v = (v << 8) | bytes.at(offset + b);
  return v;
}

double little_endian_f64(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
  const std::uint64_t bits = little_endian(bytes, offset, 8);
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

}  // namespace

TEST(ModelFormat01, TheCommittedModelReads) {
  const ShapeModel m = load_model(kCommitted.string(), {true});
  EXPECT_EQ(m.levels(), 1);
  EXPECT_EQ(m.connectivity().vertex_counts.back(), 162);
  EXPECT_EQ(m.connectivity().faces.back().rows(), 320);
  EXPECT_EQ(m.sections.count("appearance"), 1u);
  EXPECT_EQ(m.sections.count(kReferenceImageSection), 1u);
  EXPECT_EQ(m.build_options["faces"].get<int>(), 320);
}

TEST(ModelFormat01, DetailsDecodeLittleEndianAsDocumented) {
  const std::vector<std::uint8_t> bytes = test::read_all(kCommitted / "details.bin");
  const ShapeModel m = load_model(kCommitted.string());
  ASSERT_EQ(std::string(bytes.begin(), bytes.begin() + 8), "MRSNKDET");
  EXPECT_EQ(little_endian(bytes, 8, 4), 1u);   // layout version
  EXPECT_EQ(little_endian(bytes, 12, 4), 1u);  // butterfly
  const auto L = static_cast<std::size_t>(little_endian(bytes, 32, 4));
  const auto n0 = static_cast<std::size_t>(little_endian(bytes, 36, 4));
  const auto m0 = static_cast<std::size_t>(little_endian(bytes, 40, 4));
  EXPECT_EQ(L, static_cast<std::size_t>(m.levels()));
  EXPECT_EQ(n0, static_cast<std::size_t>(m.base.rows()));
  EXPECT_EQ(m0, static_cast<std::size_t>(m.base_faces.rows()));
  // The first base face, then S_0's first and last coordinates, exactly.
  const std::size_t faces_at = 48 + 4 * (L + 1), positions_at = faces_at + 12 * m0;
  EXPECT_EQ(static_cast<int>(little_endian(bytes, faces_at, 4)), m.base_faces(0, 0));
  EXPECT_EQ(little_endian_f64(bytes, positions_at), m.base(0, 0));
  EXPECT_EQ(little_endian_f64(bytes, positions_at + 8 * (3 * n0 - 1)), m.base(n0 - 1, 2));
  // The checksum closes the file: FNV-1a 64 of every byte before it.
  EXPECT_EQ(little_endian(bytes, bytes.size() - 8, 8), fnv1a64(bytes.data(), bytes.size() - 8));
}

TEST(ModelFormat01, TheReferenceImageDecodesLittleEndianAsDocumented) {
  const ShapeModel m = load_model(kCommitted.string());
  const std::vector<std::uint8_t>& bytes = m.sections.at(kReferenceImageSection);
  const Volume crop = deserialize_reference_image(bytes);
  ASSERT_EQ(std::string(bytes.begin(), bytes.begin() + 8), "MRSNKREF");
  EXPECT_EQ(little_endian(bytes, 8, 4), 1u);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(little_endian(bytes, 12 + 4 * a, 4), crop.size[a]);
  EXPECT_EQ(little_endian_f64(bytes, 24), crop.spacing[0]);
}

TEST(ModelFormat01, WritingWhatWasReadGivesTheSameBytes) {
  const ShapeModel m = load_model(kCommitted.string(), {true});
  const fs::path again = test::scratch_dir("model-format-01") / "again.model";
  save_model(again.string(), m);
  for (const char* part : {"details.bin", "appearance.bin", "reference_image.bin"})
    EXPECT_EQ(test::read_all(again / part), test::read_all(kCommitted / part)) << part;
  // And the sections decode to what encodes to the same bytes.
  EXPECT_EQ(serialize_appearance(deserialize_appearance(m.sections.at("appearance"))), m.sections.at("appearance"));
  EXPECT_EQ(serialize_reference_image(deserialize_reference_image(m.sections.at(kReferenceImageSection))),
            m.sections.at(kReferenceImageSection));
}
