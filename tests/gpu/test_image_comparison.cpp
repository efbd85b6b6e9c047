// The shared image comparisons (gpu_test_env.h) refuse to call two empty images a match: a
// renderer that draws nothing must not pass a comparison with another that draws nothing.
#include "gpu_test_env.h"

#include <gtest/gtest-spi.h>

using namespace shadel::test;

namespace {

// 4 x 4 RGBA8 images (EXPECT_NONFATAL_FAILURE needs what it runs to be static).
std::vector<uint8_t> flat(uint8_t level, uint8_t alpha) {
    std::vector<uint8_t> rgba(4 * 4 * 4, level);
    for (size_t i = 3; i < rgba.size(); i += 4) rgba[i] = alpha;
    return rgba;
}
const std::vector<uint8_t> kNothing = flat(0, 0); // cleared to black, nothing covered
const std::vector<uint8_t> kSkyOnly = [] {        // a gradient, nothing covered
    std::vector<uint8_t> rgba = flat(0, 0);
    for (size_t i = 0; i < rgba.size(); i += 4) rgba[i + 2] = uint8_t(i);
    return rgba;
}();
const std::vector<uint8_t> kFlatCovered = flat(128, 255); // covered, one flat colour
const std::vector<uint8_t> kDrawn = [] {                  // covered and not flat
    std::vector<uint8_t> rgba = flat(0, 255);
    for (size_t i = 0; i < rgba.size(); i += 4) rgba[i] = uint8_t(i * 3);
    return rgba;
}();
const std::vector<uint8_t> kNoPixels;

} // namespace

TEST(ImageComparison, ContentNeedsCoverageAndVariation) {
    EXPECT_FALSE(imageContent(kNothing).any());
    EXPECT_FALSE(imageContent(kSkyOnly).any()) << "coverage " << imageContent(kSkyOnly).coverage;
    EXPECT_FALSE(imageContent(kFlatCovered).any())
        << "deviation " << imageContent(kFlatCovered).deviation;
    EXPECT_FALSE(imageContent(kNoPixels).any());
    ImageContent drawn = imageContent(kDrawn);
    EXPECT_TRUE(drawn.any());
    EXPECT_DOUBLE_EQ(drawn.coverage, 1.0);
    EXPECT_GT(drawn.deviation, 50.0); // red 0..180 in steps of 12, green and blue 0
}

TEST(ImageComparison, TwoEmptyImagesDoNotMatch) {
    EXPECT_NONFATAL_FAILURE(psnr(kNothing, kNothing), "comparing two images without content");
    EXPECT_NONFATAL_FAILURE(psnr(kSkyOnly, kSkyOnly), "comparing two images without content");
    EXPECT_NONFATAL_FAILURE(psnr(kFlatCovered, kNothing), "comparing two images without content");
    EXPECT_NONFATAL_FAILURE(psnr(kNoPixels, kNoPixels), "comparing two images without content");
}

TEST(ImageComparison, AnImageWithContentComparesAsBefore) {
    EXPECT_EQ(psnr(kDrawn, kDrawn), 99.0);
    EXPECT_LT(psnr(kDrawn, kNothing), 20.0); // an empty render against a drawn one fails a floor
}
