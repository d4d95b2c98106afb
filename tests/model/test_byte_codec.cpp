// The model folder's byte encoding: little-endian whatever the host, and exact round trips.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "model/byte_codec.h"
#include "mesh/errors.h"

namespace mrsnake {
namespace {

TEST(ByteCodec, WritesLittleEndianBytes) {
  ByteWriter w({'M', 'G'});
  w.put<std::uint32_t>(0x01020304u);
  w.put<std::int32_t>(-2);
  w.put<double>(1.0);   // IEEE-754: 0x3FF0000000000000
  w.put<float>(-2.0f);  // 0xC0000000
  w.put<std::uint8_t>(7);
  const std::vector<std::uint8_t> expected = {'M', 'G', 4, 3, 2,    1,    0xFE, 0xFF, 0xFF, 0xFF, 0, 0,
                                              0,   0,   0, 0, 0xF0, 0x3F, 0,    0,    0,    0xC0, 7};
  EXPECT_EQ(w.bytes(), expected);
}

TEST(ByteCodec, ReadsBackWhatItWroteAndRefusesToReadPastTheEnd) {
  ByteWriter w;
  const double tiny = std::numeric_limits<double>::denorm_min();
  w.put<double>(tiny);
  w.put<std::uint64_t>(0x0123456789ABCDEFull);
  w.put<float>(3.25f);
  const std::vector<std::uint8_t> bytes = w.take();
  ByteReader r(bytes, 0, InputError("the test buffer is truncated"));
  EXPECT_EQ(r.get<double>(), tiny);
  EXPECT_EQ(r.get<std::uint64_t>(), 0x0123456789ABCDEFull);
  EXPECT_EQ(r.get<float>(), 3.25f);
  EXPECT_EQ(r.position(), bytes.size());
  try {
    r.get<std::uint8_t>();
    FAIL() << "read past the end";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "the test buffer is truncated");
  }
}

}  // namespace
}  // namespace mrsnake
