// The checking deserialiser of the node's inputs (checked_subscription.h, issue 42), without a
// master: forged array length prefixes in LaserScan, PlacedScan and TFMessage are refused before
// any array is sized, whatever they claim (one element too many, 1e8, 2^32 - 1), truncated
// messages are refused, and everything well formed reads back exactly as roscpp reads it. A
// seeded fuzz loop rewrites prefixes and bytes of real messages: every message is either refused
// or read with no array larger than the bytes it came in.
#include <gtest/gtest.h>
#include <ros/serialization.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "checked_subscription.h"
#include "placed_scan_fixture.h"
#include "wavog_mapping/PlacedScan.h"

namespace {

namespace ser = ros::serialization;

template <typename M>
std::vector<std::uint8_t> bytesOf(const M& m) {
  std::vector<std::uint8_t> b(ser::serializationLength(m));
  ser::OStream out(b.data(), static_cast<std::uint32_t>(b.size()));
  ser::serialize(out, m);
  return b;
}

template <typename M>
std::vector<std::uint8_t> bytesOf(const M& m, std::size_t n) {
  std::vector<std::uint8_t> b = bytesOf(m);
  b.resize(n);
  return b;
}

sensor_msgs::LaserScan scan(std::size_t beams, std::size_t intensities) {
  sensor_msgs::LaserScan s;
  s.header.seq = 77;
  s.header.stamp = ros::Time(12.5);
  s.header.frame_id = "laser";
  s.angle_min = -1.5f;
  s.angle_max = 1.5f;
  s.angle_increment = 3.0f / static_cast<float>(beams - 1);
  s.range_min = 0.1f;
  s.range_max = 30.0f;
  for (std::size_t i = 0; i < beams; ++i) s.ranges.push_back(1.0f + 0.01f * static_cast<float>(i));
  for (std::size_t i = 0; i < intensities; ++i) s.intensities.push_back(static_cast<float>(i));
  return s;
}

/// Offset of the ranges' length prefix in a serialised LaserScan.
std::size_t rangesPrefix(const sensor_msgs::LaserScan& s) {
  return 4 + 8 + 4 + s.header.frame_id.size() + 7 * 4;
}

void setPrefix(std::vector<std::uint8_t>* b, std::size_t at, std::uint32_t n) {
  std::memcpy(b->data() + at, &n, 4);
}

template <typename M>
bool read(std::vector<std::uint8_t> b, M* m, std::string* why) {
  return wavog_ros::checkedDeserialize(b.data(), static_cast<std::uint32_t>(b.size()), m, why);
}

TEST(CheckedDeserialize, WellFormedMessagesReadAsRoscppReadsThem) {
  for (std::size_t intensities : {0u, 181u}) {
    const sensor_msgs::LaserScan s = scan(181, intensities);
    sensor_msgs::LaserScan got;
    std::string why;
    ASSERT_TRUE(read(bytesOf(s), &got, &why)) << why;
    EXPECT_EQ(got, s);
  }
  for (bool codes : {false, true}) {
    const wavog_mapping::PlacedScan p = placed_scan_fixture::goodScan(5, codes);
    wavog_mapping::PlacedScan got;
    std::string why;
    ASSERT_TRUE(read(bytesOf(p), &got, &why)) << why;
    EXPECT_EQ(got, p);
  }
  tf2_msgs::TFMessage tf;
  tf.transforms.resize(3);
  tf.transforms[1].child_frame_id = "base_link";
  tf.transforms[2].transform.rotation.w = 1.0;
  tf2_msgs::TFMessage got;
  std::string why;
  ASSERT_TRUE(read(bytesOf(tf), &got, &why)) << why;
  EXPECT_EQ(got, tf);
  // Empty arrays, and an array that takes every byte left.
  sensor_msgs::LaserScan empty = scan(2, 0);
  empty.ranges.clear();
  sensor_msgs::LaserScan got_empty;
  EXPECT_TRUE(read(bytesOf(empty), &got_empty, &why)) << why;
  EXPECT_EQ(got_empty, empty);
}

TEST(CheckedDeserialize, ForgedScanPrefixesRefusedBeforeSizing) {
  const sensor_msgs::LaserScan s = scan(181, 0);
  const std::size_t at = rangesPrefix(s);
  // The intensities' prefix follows the ranges.
  const std::size_t at_intensities = at + 4 + 4 * s.ranges.size();
  // After the ranges' prefix, 181 ranges and the intensities' prefix: 182 floats' worth of bytes.
  // 183 is the smallest count that cannot be there.
  for (std::uint32_t n : {183u, 1000u, 100000000u, std::numeric_limits<std::uint32_t>::max()}) {
    for (std::size_t where : {at, at_intensities}) {
      std::vector<std::uint8_t> b = bytesOf(s);
      setPrefix(&b, where, n);
      sensor_msgs::LaserScan got;
      std::string why;
      EXPECT_FALSE(read(b, &got, &why)) << n;
      EXPECT_NE(why.find("claims " + std::to_string(n) + " elements"), std::string::npos) << why;
      // Nothing sized from the forged prefix; the header read before it is there.
      EXPECT_LE(got.ranges.capacity(), s.ranges.size());
      EXPECT_EQ(got.intensities.capacity(), 0u);
      EXPECT_EQ(got.header.seq, 77u);
      EXPECT_EQ(got.header.frame_id, "laser");
    }
  }
  // One element fewer than the bytes hold is a well-formed message of another shape: read.
  std::vector<std::uint8_t> b = bytesOf(s);
  setPrefix(&b, at, 180);  // the last range's bytes are then the intensities' prefix
  sensor_msgs::LaserScan got;
  std::string why;
  EXPECT_FALSE(read(b, &got, &why));  // 2.8f: 0x40333333 intensities claimed in 4 bytes
  setPrefix(&b, at + 4 + 4 * 180, 0);
  ASSERT_TRUE(read(b, &got, &why)) << why;
  EXPECT_EQ(got.ranges.size(), 180u);
  EXPECT_TRUE(got.intensities.empty());
}

TEST(CheckedDeserialize, ForgedPlacedScanPrefixesRefused) {
  for (bool codes : {false, true}) {
    const wavog_mapping::PlacedScan p = placed_scan_fixture::goodScan(5, codes);
    const std::vector<std::uint8_t> good = bytesOf(p);
    // The arrays sit just before range_step (8 bytes at the end): ranges, then range_codes.
    const std::size_t codes_at = good.size() - 8 - (4 + 2 * p.range_codes.size());
    const std::size_t ranges_at = codes_at - (4 + 4 * p.ranges.size());
    for (std::uint32_t n : {100000000u, std::numeric_limits<std::uint32_t>::max()}) {
      for (std::size_t where : {ranges_at, codes_at}) {
        std::vector<std::uint8_t> b = good;
        setPrefix(&b, where, n);
        wavog_mapping::PlacedScan got;
        std::string why;
        EXPECT_FALSE(read(b, &got, &why));
        EXPECT_NE(why.find("claims"), std::string::npos) << why;
        EXPECT_LE(got.ranges.capacity(), p.ranges.size());
        EXPECT_LE(got.range_codes.capacity(), p.range_codes.size());
        EXPECT_EQ(got.index, 5u);  // read before the arrays: the stream index can step
      }
    }
  }
}

TEST(CheckedDeserialize, ArraysOfMessagesBoundedByTheirSmallestSize) {
  // A TransformStamped takes at least 4 + 8 + 4 + 4 + 7 * 8 = 76 bytes.
  EXPECT_EQ(wavog_ros::minSerializedSize<geometry_msgs::TransformStamped>(), 76u);
  EXPECT_EQ(wavog_ros::minSerializedSize<float>(), 4u);
  EXPECT_EQ(wavog_ros::minSerializedSize<std::string>(), 4u);
  tf2_msgs::TFMessage tf;
  tf.transforms.resize(2);
  std::vector<std::uint8_t> b = bytesOf(tf);
  for (std::uint32_t n : {3u, 1000u, std::numeric_limits<std::uint32_t>::max()}) {
    setPrefix(&b, 0, n);
    tf2_msgs::TFMessage got;
    std::string why;
    EXPECT_FALSE(read(b, &got, &why)) << n;
    EXPECT_LE(got.transforms.capacity(), 2u);
  }
}

TEST(CheckedDeserialize, TruncatedMessagesRefused) {
  const sensor_msgs::LaserScan s = scan(10, 10);
  const std::vector<std::uint8_t> full = bytesOf(s);
  for (std::size_t n = 0; n < full.size(); ++n) {
    sensor_msgs::LaserScan got;
    std::string why;
    ASSERT_FALSE(read(bytesOf(s, n), &got, &why)) << n << " of " << full.size() << " bytes";
    EXPECT_FALSE(why.empty());
  }
}

/// Bytes that fuzzed arrays of `m` may take at most: as many elements as bytes of the message.
std::size_t arrayBytes(const sensor_msgs::LaserScan& m) {
  return 4 * (m.ranges.size() + m.intensities.size());
}
std::size_t arrayBytes(const wavog_mapping::PlacedScan& m) {
  return 4 * m.ranges.size() + 2 * m.range_codes.size();
}

template <typename M>
void fuzz(const M& seed, std::uint32_t rounds) {
  std::mt19937 rng(42);
  const std::vector<std::uint8_t> good = bytesOf(seed);
  std::size_t refused = 0;
  for (std::uint32_t r = 0; r < rounds; ++r) {
    std::vector<std::uint8_t> b = good;
    // A few random 4-byte words set to lengths near the edges, a few random bytes, a random cut.
    const int words = 1 + static_cast<int>(rng() % 3);
    for (int w = 0; w < words; ++w) {
      const std::size_t at = rng() % (b.size() - 3);
      const std::uint32_t kinds[] = {static_cast<std::uint32_t>(rng()),
                                     static_cast<std::uint32_t>(rng() % 400),
                                     std::numeric_limits<std::uint32_t>::max(), 100000000u};
      setPrefix(&b, at, kinds[rng() % 4]);
    }
    for (int k = static_cast<int>(rng() % 3); k > 0; --k) b[rng() % b.size()] ^= rng() & 0xff;
    if (rng() % 4 == 0) b.resize(rng() % b.size());
    M got;
    std::string why;
    if (!read(b, &got, &why)) {
      ++refused;
      EXPECT_FALSE(why.empty());
    }
    // Refused or not, nothing larger than the bytes it came in.
    ASSERT_LE(arrayBytes(got), b.size()) << "round " << r;
  }
  EXPECT_GT(refused, rounds / 4);  // the forged prefixes were met
  EXPECT_LT(refused, rounds);      // and some messages still read
}

TEST(CheckedDeserialize, FuzzedPrefixesNeverSizeBeyondTheMessage) {
  fuzz(scan(181, 181), 20000);
  fuzz(placed_scan_fixture::goodScan(3, false), 20000);
  fuzz(placed_scan_fixture::goodScan(3, true), 20000);
}

TEST(CheckedDeserialize, HelperHandsRefusalsToTheSubscriberNotTheCallback) {
  int calls = 0;
  int refusals = 0;
  std::uint32_t refused_seq = 0;
  std::string refused_why;
  std::uint32_t refused_read = 0;
  std::uint32_t refused_length = 0;
  const boost::function<void(const ros::MessageEvent<sensor_msgs::LaserScan const>&)> cb =
      [&](const ros::MessageEvent<sensor_msgs::LaserScan const>&) { ++calls; };
  wavog_ros::CheckedCallbackHelper<sensor_msgs::LaserScan> helper(
      cb, [&](const sensor_msgs::LaserScan& partial, const wavog_ros::Refused& r) {
        ++refusals;
        refused_seq = partial.header.seq;
        refused_why = r.why;
        refused_read = r.bytes_read;
        refused_length = r.length;
      });
  const sensor_msgs::LaserScan s = scan(50, 0);
  std::vector<std::uint8_t> b = bytesOf(s);
  ros::SubscriptionCallbackHelperDeserializeParams params;
  params.buffer = b.data();
  params.length = static_cast<std::uint32_t>(b.size());
  params.connection_header = boost::make_shared<ros::M_string>();
  ros::VoidConstPtr ok = helper.deserialize(params);
  ASSERT_TRUE(ok);
  EXPECT_EQ(*boost::static_pointer_cast<const sensor_msgs::LaserScan>(ok), s);
  setPrefix(&b, rangesPrefix(s), std::numeric_limits<std::uint32_t>::max());
  EXPECT_FALSE(helper.deserialize(params));
  EXPECT_EQ(refusals, 1);
  EXPECT_EQ(refused_seq, 77u);
  EXPECT_NE(refused_why.find("4294967295"), std::string::npos) << refused_why;
  EXPECT_EQ(refused_read, rangesPrefix(s));  // every field before the ranges
  EXPECT_EQ(refused_length, b.size());
  EXPECT_EQ(calls, 0);  // deserialize never calls back
}

}  // namespace
