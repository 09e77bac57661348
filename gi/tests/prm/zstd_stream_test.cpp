// The one zstd stream reader of the bake files (io/zstd_stream.h; the PRM's panes, BRF
// coefficients and antiradiance links go through it). Here, in the PRM's tests because
// gi_prm is a target that links zstd: the caps it checks before allocating anything,
// on frames whose headers claim sizes their bytes do not hold.
#include "io/zstd_stream.h"

#include <zstd.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "io/blob_file.h"

namespace {

// A zstd frame whose header records `pledged` content bytes, followed by one block of
// `payload` (flushed, never ended): what a file claiming a huge stream can start with.
std::vector<std::uint8_t> frame_claiming(std::uint64_t pledged, const std::vector<std::uint8_t>& payload) {
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  EXPECT_NE(cctx, nullptr);
  EXPECT_EQ(ZSTD_isError(ZSTD_CCtx_setPledgedSrcSize(cctx, pledged)), 0u);
  std::vector<std::uint8_t> out(ZSTD_compressBound(payload.size()) + 64);
  ZSTD_inBuffer in{payload.data(), payload.size(), 0};
  ZSTD_outBuffer dst{out.data(), out.size(), 0};
  const std::size_t left = ZSTD_compressStream2(cctx, &dst, &in, ZSTD_e_flush);
  EXPECT_EQ(ZSTD_isError(left), 0u) << ZSTD_getErrorName(left);
  ZSTD_freeCCtx(cctx);
  out.resize(dst.pos);
  return out;
}

std::vector<std::uint8_t> ramp(std::size_t n) {
  std::vector<std::uint8_t> bytes(n);
  std::iota(bytes.begin(), bytes.end(), std::uint8_t{0});
  return bytes;
}

TEST(ZstdStream, AFrameClaimingMoreThanTheCapIsRefusedBeforeAnythingIsAllocated) {
  // One byte over the 4 GiB cap, and far over it; `expected` agrees with the claim, as it
  // would in a file whose counts were forged along with the frame, so only the cap stands
  // between the claim and a 4 GiB vector (under ASan that allocation itself would abort).
  for (const std::uint64_t claimed : {gi::kMaxDecompressedBytes + 1, std::uint64_t{1} << 40}) {
    const auto frame = frame_claiming(claimed, ramp(1000));
    ASSERT_EQ(ZSTD_getFrameContentSize(frame.data(), frame.size()), claimed);
    const auto result = gi::read_zstd_stream("forged.bin", "panes", frame, claimed);
    ASSERT_FALSE(result) << "a " << claimed << "-byte claim was accepted";
    const std::string message = result.error().to_string();
    EXPECT_NE(message.find("forged.bin"), std::string::npos) << message;
    EXPECT_NE(message.find("panes"), std::string::npos) << message;
    EXPECT_NE(message.find("above the " + std::to_string(gi::kMaxDecompressedBytes) + "-byte limit"), std::string::npos)
        << message;
  }
}

TEST(ZstdStream, AFrameAtTheCapPassesItAndIsThenJudgedByItsOwnBytes) {
  // Exactly 4 GiB claimed is within the cap; the frame's few bytes cannot hold it, which the
  // next checks catch (one block holds at most 128 KiB), still before allocating.
  const auto frame = frame_claiming(gi::kMaxDecompressedBytes, ramp(1000));
  const auto result = gi::read_zstd_stream("forged.bin", "links", frame, gi::kMaxDecompressedBytes);
  ASSERT_FALSE(result);
  const std::string message = result.error().to_string();
  EXPECT_EQ(message.find("limit"), std::string::npos) << message;
  EXPECT_NE(message.find("corrupt"), std::string::npos) << message;
}

TEST(ZstdStream, AnHonestFrameDecompressesAndAMismatchedCountIsNamed) {
  const auto payload = ramp(70000);
  std::vector<std::uint8_t> frame(ZSTD_compressBound(payload.size()));
  frame.resize(ZSTD_compress(frame.data(), frame.size(), payload.data(), payload.size(), 3));
  const auto ok = gi::read_zstd_stream("honest.bin", "coefficients", frame, payload.size());
  ASSERT_TRUE(ok) << ok.error().to_string();
  EXPECT_EQ(*ok, payload);
  const auto off = gi::read_zstd_stream("honest.bin", "coefficients", frame, payload.size() + 1);
  ASSERT_FALSE(off);
  EXPECT_NE(off.error().to_string().find("the file's counts need " + std::to_string(payload.size() + 1)),
            std::string::npos)
      << off.error().to_string();
}

}  // namespace
