// The rows a tile writes into its image (render/stream_row.h): every store width this CPU
// runs writes in[x] / divisor bit for bit (the plain division), exactly n values whatever
// the destination's alignment, and nothing around them. A width the CPU lacks is skipped,
// and says so.

#include "render/stream_row.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/aligned.h"
#include "core/cpu_features.h"

namespace octray {
namespace {

#if defined(__x86_64__)
using RowFn = void (*)(float*, const float*, int, float);

struct Width {
    const char* name;
    RowFn fn;
    bool supported;
};

std::vector<Width> widths() {
    return {{"sse2", &stream_row_sse2, true},
            {"avx2", &stream_row_avx2, cpu_features().avx2},
            {"avx512", &stream_row_avx512, cpu_features().avx512}};
}

class StreamRowWidth : public testing::TestWithParam<int> {};

TEST_P(StreamRowWidth, WritesEachMeanBitForBitAndNothingElse) {
    const Width w = widths()[static_cast<std::size_t>(GetParam())];
    if (!w.supported) GTEST_SKIP() << w.name << " not on this CPU";
    constexpr int kMax = 100;
    // Sums with awkward quotients (thirds, sevenths), denormals and a signed zero.
    std::vector<float> in(kMax);
    for (int x = 0; x < kMax; ++x)
        in[static_cast<std::size_t>(x)] = 0.1f * float(x * x) + 1.0f / 3.0f;
    in[5] = 1e-40f, in[6] = -0.0f, in[7] = 3.4e38f;
    const float sentinel = -12345.0f;
    for (float divisor : {1.0f, 3.0f, 7.0f, 16.0f}) {
        for (int n : {0, 1, 3, 4, 7, 15, 16, 17, 31, 32, 33, 63, 64, 65, 99, 100}) {
            for (int offset = 0; offset < 16; ++offset) {  // floats past a 64-byte line
                AlignedVector<float> out(static_cast<std::size_t>(kMax + 32), sentinel);
                float* dst = out.data() + offset;
                w.fn(dst, in.data(), n, divisor);
                finish_streaming();
                for (int x = 0; x < n; ++x) {
                    const float want = divisor != 1.0f
                                           ? in[static_cast<std::size_t>(x)] / divisor
                                           : in[static_cast<std::size_t>(x)];
                    ASSERT_EQ(std::memcmp(&dst[x], &want, sizeof want), 0)
                        << w.name << ": n " << n << ", offset " << offset << ", divisor "
                        << divisor << ", sample " << x << ": " << dst[x] << " != " << want;
                }
                for (std::size_t i = 0; i < out.size(); ++i) {
                    const auto at = static_cast<std::ptrdiff_t>(i) - offset;
                    if (at >= 0 && at < n) continue;
                    ASSERT_EQ(out[i], sentinel)
                        << w.name << ": n " << n << ", offset " << offset
                        << ": wrote outside the row at " << at;
                }
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Widths, StreamRowWidth, testing::Values(0, 1, 2),
                         [](const testing::TestParamInfo<int>& info) {
                             return std::string(
                                 widths()[static_cast<std::size_t>(info.param)].name);
                         });
#endif

// Whatever width this CPU picks, the dispatching entry point writes the same bits.
TEST(StreamRow, TheChosenWidthWritesThePlainQuotients) {
    std::vector<float> in(77);
    for (std::size_t x = 0; x < in.size(); ++x) in[x] = 0.7f * float(x) + 0.01f;
    AlignedVector<float> out(in.size() + 3, 0.0f);
    stream_row(out.data() + 3, in.data(), static_cast<int>(in.size()), 9.0f);
    finish_streaming();
    for (std::size_t x = 0; x < in.size(); ++x) {
        const float want = in[x] / 9.0f;
        EXPECT_EQ(std::memcmp(&out[x + 3], &want, sizeof want), 0) << "sample " << x;
    }
}

}  // namespace
}  // namespace octray
