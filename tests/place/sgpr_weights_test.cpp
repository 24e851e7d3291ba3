// The `.sgw` reader: real files, round trip, and clear errors for bad files.

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "saloam/core/error.hpp"
#include "saloam/place/sgpr_network.hpp"
#include "saloam/place/sgpr_weights.hpp"
#include "testing/test_support.hpp"

namespace saloam {
namespace {

std::vector<std::byte> file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::vector<char> raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> bytes(raw.size());
  std::memcpy(bytes.data(), raw.data(), raw.size());
  return bytes;
}

std::string error_of(const std::vector<std::byte>& bytes) {
  try {
    (void)SgprNetwork(parse_sgpr_weights(bytes, "bad.sgw"));
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), std::filesystem::path("bad.sgw"));
    return e.what();
  }
  return "";
}

TEST(SgprWeights, ReadsTheSharedModelWithAllTensors) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto weights = read_sgpr_weights(testing::shared_file("models/sgpr/sgpr_kitti.sgw"));
  EXPECT_EQ(weights.tensors.size(), 43U);
  const auto& wt = weights.require("tensor_network.weight_matrix", {32, 32, 16});
  EXPECT_EQ(wt.values.size(), 32U * 32U * 16U);
  EXPECT_THROW((void)weights.require("tensor_network.weight_matrix", {32, 16, 32}), InputError);
  EXPECT_THROW((void)weights.require("no.such.tensor", {1}), InputError);
  // Subnormal running variances are kept exactly (no flush to zero in the reader).
  bool subnormal = false;
  for (const auto& [name, t] : weights.tensors)
    for (const float v : t.values) subnormal |= (v != 0.0F && std::fpclassify(v) == FP_SUBNORMAL);
  EXPECT_TRUE(subnormal);
}

TEST(SgprWeights, SerializeRoundTripIsBitExact) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto path = testing::shared_file("models/sgpr/sgpr_kitti.sgw");
  const auto weights = read_sgpr_weights(path);
  const auto bytes = serialize_sgpr_weights(weights);
  const auto again = parse_sgpr_weights(bytes, "memory");
  ASSERT_EQ(again.tensors.size(), weights.tensors.size());
  for (const auto& [name, t] : weights.tensors) {
    const auto& u = again.tensors.at(name);
    EXPECT_EQ(u.dims, t.dims);
    ASSERT_EQ(u.values.size(), t.values.size());
    EXPECT_EQ(std::memcmp(u.values.data(), t.values.data(), 4 * t.values.size()), 0) << name;
  }
  // The file itself has the same size as our serialization (same content, other record order).
  EXPECT_EQ(bytes.size(), std::filesystem::file_size(path));
}

TEST(SgprWeights, WrittenFileReadsBackBitExact) {
  testing::TempDir dir;
  SgprWeights weights;
  weights.tensors["a.weight"] = {{2, 3, 1, 1}, {1.5F, -2.0F, 1e-40F, 0.0F, 3.25F, -7.0F}};  // 1e-40: subnormal, kept
  weights.tensors["b"] = {{1}, {0.125F}};
  const auto file = dir / "sub" / "model.sgw";
  write_sgpr_weights(file, weights);
  EXPECT_FALSE(std::filesystem::exists(dir / "sub" / "model.sgw.partial"));
  const auto again = read_sgpr_weights(file);
  ASSERT_EQ(again.tensors.size(), 2U);
  for (const auto& [name, t] : weights.tensors) {
    const auto& u = again.tensors.at(name);
    EXPECT_EQ(u.dims, t.dims) << name;
    ASSERT_EQ(u.values.size(), t.values.size());
    EXPECT_EQ(std::memcmp(u.values.data(), t.values.data(), 4 * t.values.size()), 0) << name;
  }
  // Nothing unreadable is written: a shape that does not match the values is refused.
  weights.tensors["b"] = {{2}, {0.125F}};
  EXPECT_THROW(write_sgpr_weights(dir / "bad.sgw", weights), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.sgw"));
}

TEST(SgprWeights, MissingFileIsAClearError) {
  try {
    (void)read_sgpr_weights("/nonexistent/model.sgw");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/model.sgw"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

TEST(SgprWeights, MalformedFilesAreClearErrors) {
  SALOAM_REQUIRE_SHARED_DATA();
  const auto good = file_bytes(testing::shared_file("models/sgpr/sgpr_kitti.sgw"));
  ASSERT_EQ(error_of(good), "");

  auto bad_magic = good;
  bad_magic[0] = std::byte{'X'};
  EXPECT_NE(error_of(bad_magic).find("magic"), std::string::npos);

  auto truncated = good;
  truncated.resize(good.size() - 10);
  EXPECT_NE(error_of(truncated).find("truncated"), std::string::npos);

  auto trailing = good;
  trailing.push_back(std::byte{0});
  EXPECT_NE(error_of(trailing).find("unexpected bytes"), std::string::npos);

  EXPECT_NE(error_of({}).find("truncated"), std::string::npos);

  // A tensor with the right name but the wrong shape.
  auto weights = parse_sgpr_weights(good, "bad.sgw");
  weights.tensors["attention.weight_matrix"] = SgprTensor{{16, 64}, std::vector<float>(16 * 64, 0.0F)};
  EXPECT_NE(error_of(serialize_sgpr_weights(weights)).find("attention.weight_matrix"), std::string::npos);

  // A missing tensor.
  weights = parse_sgpr_weights(good, "bad.sgw");
  weights.tensors.erase("scoring_layer.bias");
  EXPECT_NE(error_of(serialize_sgpr_weights(weights)).find("lack tensor 'scoring_layer.bias'"), std::string::npos);

  // A NaN value.
  weights = parse_sgpr_weights(good, "bad.sgw");
  weights.tensors["scoring_layer.bias"].values[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(error_of(serialize_sgpr_weights(weights)).find("non-finite"), std::string::npos);

  // A finite but absurd value (3e38 makes every score NaN): not trained weights.
  weights = parse_sgpr_weights(good, "bad.sgw");
  weights.tensors["dgcnn_s_conv1.0.weight"].values[5] = 3e38F;
  EXPECT_NE(error_of(serialize_sgpr_weights(weights)).find("tensor 'dgcnn_s_conv1.0.weight' holds 3e+38 at element 5"),
            std::string::npos);

  // An absurd dimension (larger than the file).
  auto huge = good;
  // First record: magic(8) + count(4) + name length(4) + name + ndim(4) + dims.
  std::uint32_t name_length = 0;
  std::memcpy(&name_length, huge.data() + 12, 4);
  const std::size_t dim0 = 16 + name_length + 4;
  const std::uint32_t big = 0x7fffffff;
  std::memcpy(huge.data() + dim0, &big, 4);
  EXPECT_NE(error_of(huge).find("larger than the rest of the file"), std::string::npos);
}

}  // namespace
}  // namespace saloam
